import math
import warnings
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

import contourgrasp as cg
from contourgrasp import visualize
from contourgrasp.io.camera_file import read_rgbd


def test_plan_figure_draws_every_finger_and_the_cost():
    plan = cg.synthesize(cg.example_contour("can"), "five-finger-linear", yaw_step=math.radians(6))
    fig = visualize.plan_figure(plan)
    ax = fig.axes[0]
    labels = [t.get_text() for t in ax.texts]
    for finger in plan.hand.fingers:
        assert any(label.startswith(finger.name) for label in labels)
    assert f"{plan.cost.total:.1f}" in ax.get_title()
    assert ax.yaxis_inverted()
    grasp_markers = [line for line in ax.lines if line.get_marker() in ("*", "X") and len(line.get_xdata()) == 1]
    assert len(grasp_markers) == len(plan.fingers)
    for line, contact in zip(grasp_markers, plan.fingers):
        np.testing.assert_allclose([line.get_xdata()[0], line.get_ydata()[0]], contact.grasp_point)


def test_harmonics_figure_has_one_panel_per_count(tmp_path):
    fig = visualize.harmonics_figure(cg.example_contour("stone2"), (1, 4, 8))
    assert [ax.get_title() for ax in fig.axes] == ["1 harmonic", "4 harmonics", "8 harmonics"]
    fig.savefig(tmp_path / "h.png")
    assert (tmp_path / "h.png").stat().st_size > 1000


def test_image_plan_is_drawn_where_the_colour_image_shows_the_object():
    # Segmentation works in depth pixels; over the colour image everything is drawn less the colour offset.
    folder = Path(__file__).resolve().parents[1] / "examples" / "bar_clamp"
    frame = read_rgbd(folder / "color_0.png", folder / "depth_0.npy", folder / "primesense_overhead_color.intr")
    result = cg.plan_grasp(frame.rgb, frame.depth, frame.intrinsics, "three-finger", xy_step=0.03,
                           yaw_step=math.radians(6))
    result = replace(result, segmentation=replace(result.segmentation, colour_offset_px=(3, -2)))
    contour = result.segmentation.contour_px
    for rgb, shift in ((frame.rgb, (3, -2)), (None, (0, 0))):
        ax = visualize.image_plan_figure(result, rgb).axes[0]
        outline = ax.lines[0].get_xydata()
        np.testing.assert_allclose(outline[:-1], contour - shift)
        starts = [line.get_xydata()[0] for line in ax.lines if line.get_marker() == "o"]
        expected = visualize._to_pixels(result, [f.start for f in result.plan.fingers]) - shift
        np.testing.assert_allclose(starts, expected)


@pytest.mark.parametrize("size, label", [(2e-4, "50 µm"), (0.12, "2 cm"), (9000.0, "2000 m")])
def test_harmonics_figure_draws_any_contour_the_model_accepts(tmp_path, size, label):
    # a contour x 1e307 would crash matplotlib; the bounds of clean_polygon refuse it, and the scale
    # bar follows the contour's size, so every accepted contour draws.
    can = cg.example_contour("can")
    fig = visualize.harmonics_figure(can / np.ptp(can, axis=0).max() * size, (1, 4))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        fig.savefig(tmp_path / "h.png")
    bars = [a for ax in fig.axes for a in ax.artists if hasattr(a, "txt_label")]
    assert {bar.txt_label.get_text() for bar in bars} == {label}
    with pytest.raises(cg.ContourError, match="too large"):
        visualize.harmonics_figure(can * 1e307)


def test_image_plan_figure_has_a_height_panel(tmp_path):
    folder = Path(__file__).resolve().parents[1] / "examples" / "bar_clamp"
    frame = read_rgbd(folder / "color_0.png", folder / "depth_0.npy", folder / "primesense_overhead_color.intr")
    result = cg.plan_grasp(frame.rgb, frame.depth, frame.intrinsics, "three-finger", xy_step=0.03,
                           yaw_step=math.radians(6))
    fig = visualize.image_plan_figure(result, frame.rgb)
    height_ax = fig.axes[2]
    assert height_ax.get_title().startswith("height map (2 mm cells)")
    assert height_ax.images[0].get_array().shape == result.height_map.shape
    fig.savefig(tmp_path / "p.png")
    # Without a height map (no table plane), the two panels of before.
    assert len(visualize.image_plan_figure(replace(result, height_map=None)).axes) == 2


def test_the_side_view_draws_a_hand_of_measured_chains_in_each_fingers_plane(tmp_path):
    # a hand of SampledChains (as hand-from-model writes for a model's curling fingers) has no knuckle or
    # direction of its own: its side view takes the plane from its open pose (hand.chain_plane)
    from contourgrasp.hand import SampledChain, chain_joints, chain_plane

    three = cg.load_hand("three-finger")
    sampled = replace(three, chains=tuple(SampledChain(joints=chain_joints(c, np.linspace(0, 1, 11)), radius=c.radius)
                                          for c in three.chains))
    for planar, measured in zip(three.chains, sampled.chains, strict=True):
        knuckle, direction = chain_plane(measured)
        np.testing.assert_allclose(knuckle, planar.knuckle, atol=1e-12)
        assert direction @ np.asarray(planar.direction) == pytest.approx(1.0)  # the open tip leans along it
    folder = Path(__file__).resolve().parents[1] / "examples" / "bar_clamp"
    frame = read_rgbd(folder / "color_0.png", folder / "depth_0.npy", folder / "primesense_overhead_color.intr")
    result = cg.plan_grasp(frame.rgb, frame.depth, frame.intrinsics, sampled, planner="default", xy_step=0.03,
                           yaw_step=math.radians(6))
    assert result.grasp_height is not None
    fig = visualize.image_plan_figure(result, frame.rgb)
    side = [ax for ax in fig.axes if ax.get_title().startswith("each finger's plane at the grasp")]
    assert len(side) == 1 and len(side[0].lines) >= 3 * 3  # every finger's post and two links
    fig.savefig(tmp_path / "side.png")
