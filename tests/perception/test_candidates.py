"""Candidates standing on the table and the choice of target, on synthetic frames and the bundled one."""

from __future__ import annotations

import math
from pathlib import Path

import cv2
import numpy as np
import pytest

import contourgrasp as cg
from contourgrasp.cli import main
from contourgrasp.errors import PerceptionError, SegmentationError
from contourgrasp.io.camera_file import read_rgbd
from contourgrasp.io.plan_file import image_plan_to_dict
from contourgrasp.perception import (Candidate, choose_target, find_candidates, fit_table_plane, low_part_candidate,
                                    segment)
from contourgrasp.perception.table import heights

from perception_scenes import CAMERA, H, W

TABLE = 0.7
FAST = {"xy_step": 0.03, "yaw_step": math.radians(6)}
FRAME = Path(__file__).resolve().parents[2] / "examples" / "bar_clamp"
#: Boxes (x, y, w, h in pixels, height in m): A wholly visible, B smaller and taller, C the largest but cut by
#: the left border.
A, B, C = (300, 200, 100, 60, 0.05), (480, 300, 40, 40, 0.08), (0, 80, 80, 120, 0.03)


def scene(*boxes, dead_band=None):
    """Top-down depth of a table at TABLE m with boxes standing on it (each box's top at TABLE - height)."""
    depth = np.full((H, W), TABLE)
    for x, y, w, h, height in boxes:
        depth[y:y + h, x:x + w] = TABLE - height
    if dead_band is not None:
        depth[dead_band] = 0.0
    return depth


def candidates(depth):
    return find_candidates(depth, CAMERA, fit_table_plane(depth, CAMERA))


def test_every_region_on_the_table_is_a_candidate_largest_first():
    found = candidates(scene(A, B, C))
    assert [c.area_px for c in found] == [80 * 120, 100 * 60, 40 * 40]
    assert [c.label for c in found] == [1, 2, 3]
    assert [c.in_view for c in found] == [False, True, True]
    for c, box in zip(found, (C, A, B), strict=True):
        x, y, w, h, height = box
        assert isinstance(c, Candidate)
        # heights from the rays' points: the plane fit is exact on a flat synthetic table
        assert c.height == pytest.approx(height, abs=1e-6)
        assert c.bbox == (x, y, w, h)
        assert c.centroid_px == pytest.approx((x + (w - 1) / 2, y + (h - 1) / 2))
        assert c.mask.sum() == w * h and c.contour_px.shape[1] == 2


def test_a_region_touching_the_dead_band_is_not_in_view_and_holes_are_filled():
    band = np.zeros((H, W), dtype=bool)
    band[:, 620:] = True  # missing readings along the right border
    ring = scene((560, 100, 60, 60, 0.04), (100, 300, 50, 50, 0.04))
    ring[310:340, 115:135] = TABLE  # a hole through the second box
    ring[band] = 0.0
    found = candidates(ring)
    assert [c.in_view for c in found] == [False, True]
    holed = next(c for c in found if c.bbox[0] == 100)
    assert holed.area_px == 2500 - 600 and holed.mask.sum() == 2500


def test_nothing_on_the_table_gives_no_candidates():
    assert candidates(scene()) == ()
    with pytest.raises(SegmentationError, match="nothing stands on the support surface") as err:
        choose_target(())
    assert err.value.kind == "no-object"


def test_default_target_is_the_largest_wholly_visible_candidate_when_it_alone_is_of_its_size():
    found = candidates(scene(A, B, C))
    target, reason = choose_target(found)
    assert target.bbox[:2] == A[:2] and "fit the hand" in reason  # B (1600 px) is under half of A (6000 px)
    largest, why = choose_target(found, rule="largest")
    assert largest is target and "largest wholly visible" in why
    centre, why = choose_target(found, rule="centre")
    assert centre.bbox[:2] == A[:2] and "centre" in why  # A's centroid (349.5, 229.5) is nearer (319.5, 239.5)
    with pytest.raises(PerceptionError, match="rule"):
        choose_target(found, rule="nearest")


def test_default_rule_takes_the_candidate_nearest_the_centre_among_those_of_similar_size_that_fit_the_hand():
    near = (330, 250, 60, 50, 0.04)  # 3000 px, centroid (359.5, 274.5)
    far = (40, 40, 80, 50, 0.04)  # 4000 px, the largest, far from the centre
    wide = (150, 380, 400, 60, 0.02)  # 24000 px, 0.52 m long and 0.076 m wide at 0.68 m
    found = candidates(scene(near, far))
    target, reason = choose_target(found, max_width=0.2)
    assert target.bbox[:2] == near[:2] and "nearest the image centre among the 2" in reason
    assert choose_target(found, rule="largest")[0].bbox[:2] == far[:2]
    small = candidates(scene(far, (330, 250, 20, 20, 0.04)))  # 400 px: under half the largest, not a contender
    assert choose_target(small, max_width=0.2)[0].bbox[:2] == far[:2]
    with_wide = candidates(scene(near, wide))
    assert with_wide[0].extent == pytest.approx((399 * 0.68 / 525, 59 * 0.68 / 525), rel=1e-6)
    assert choose_target(with_wide, max_width=0.2)[0].bbox[:2] == wide[:2]  # 7.6 cm wide: fits, the near one is small
    assert choose_target(with_wide, max_width=0.07)[0].bbox[:2] == near[:2]  # 6.2 cm wide; the wide one 7.6
    none_fit, why = choose_target(with_wide, max_width=0.01)
    assert none_fit.bbox[:2] == wide[:2] and "none is narrower than the hand's opening (10 mm)" in why
    with pytest.raises(PerceptionError, match="max_width"):
        choose_target(found, max_width=-1.0)


def test_hand_opening_is_the_widest_distance_between_finger_starts():
    hand = cg.load_hand("three-finger")
    starts = hand.starts
    assert cg.perception.hand_opening(hand) == pytest.approx(
        max(np.linalg.norm(a - b) for a in starts for b in starts))


def test_default_target_equals_todays_depth_segmentation():
    depth = scene(A, B, C)
    target, _ = choose_target(candidates(depth))
    seg = segment(None, depth, CAMERA, method="depth")
    np.testing.assert_array_equal(seg.mask, target.mask)


def test_every_candidate_touching_the_border_is_refused_as_not_visible():
    with pytest.raises(SegmentationError, match="not completely visible") as err:
        choose_target(candidates(scene(C, (600, 0, 40, 40, 0.05))))
    assert err.value.kind == "not-visible" and "\n" not in str(err.value)


def test_target_by_pixel():
    found = candidates(scene(A, B, C))
    target, reason = choose_target(found, target_px=(490, 310))
    assert target.bbox[:2] == B[:2] and reason == "the candidate under pixel (490, 310)"
    with pytest.raises(SegmentationError, match=r"^no object at pixel \(450, 100\); the nearest candidate is at "
                                                r"\(399, 200\)$"):
        choose_target(found, target_px=(450, 100))
    with pytest.raises(SegmentationError, match=r"the object at pixel \(10, 100\) is not completely visible") as err:
        choose_target(found, target_px=(10, 100))
    assert err.value.kind == "not-visible"
    with pytest.raises(SegmentationError, match=r"pixel \(640, 10\) is outside the 640x480 image"):
        choose_target(found, target_px=(640, 10))
    with pytest.raises(PerceptionError, match="two integers"):
        choose_target(found, target_px=(1.5, 2))
    with pytest.raises(PerceptionError, match="not both"):
        choose_target(found, target_px=(1, 2), roi=(0, 0, 5, 5))


def test_a_click_into_a_cup_in_a_bin_whose_rim_read_nothing_in_places_means_the_cup():
    # Bin walls round the scene's middle; inside, a cup: a ring 8 cm tall whose rim has a 10 px gap (dropouts), so
    # its filled mask does not hold its inside. A click on the cup's bottom (on the support) means the cup, not the
    # bin whose filled ring holds the pixel; a click in an empty corner of the bin still means the bin.
    depth = scene((150, 100, 340, 10, 0.10), (150, 370, 340, 10, 0.10), (150, 100, 10, 280, 0.10),
                  (480, 100, 10, 280, 0.10))
    v, u = np.indices(depth.shape)
    r = np.hypot(u - 300, v - 240)
    depth[(r > 12) & (r < 22) & ~((u > 295) & (u < 305) & (v < 240))] = TABLE - 0.08
    found = candidates(depth)
    plane = fit_table_plane(depth, CAMERA)
    ph = heights(depth, CAMERA, plane)
    cup, reason = choose_target(found, target_px=(300, 240), pixel_heights=ph)
    assert cup.area_px < 3000 and "inside the container clicked in" in reason
    assert not cup.mask[240, 300]  # the cup's filled mask misses its inside: the rim is open
    corner, _ = choose_target(found, target_px=(200, 150), pixel_heights=ph)
    assert corner.area_px > 10000


def test_target_by_roi():
    found = candidates(scene(A, B, C))
    # covers all of C, a strip of A and a corner of B: the wholly visible one with most area in it is A
    target, reason = choose_target(found, roi=(0, 0, 310, 480))
    assert target.bbox[:2] == A[:2] and reason.endswith(": 600 px")  # A's columns 300-309
    target, _ = choose_target(found, roi=(380, 150, 200, 200))
    assert target.bbox[:2] == B[:2]  # B 1600 px inside, A 20 x 60 = 1200 px
    with pytest.raises(SegmentationError, match=r"^no candidate in the ROI \(0, 50, 60, 60\): 1 region\(s\) in it "
                                                r"touch the image border$") as err:
        choose_target(found, roi=(0, 50, 60, 60))
    with pytest.raises(SegmentationError, match="nothing stands on the support surface there"):
        choose_target(found, roi=(200, 400, 50, 50))
    with pytest.raises(PerceptionError, match="positive"):
        choose_target(found, roi=(0, 0, 0, 5))
    with pytest.raises(SegmentationError, match="outside the 640x480 image"):
        choose_target(found, roi=(700, 0, 5, 5))
    assert err.value.kind == "no-object"


def test_plan_frame_plans_on_the_chosen_target_and_lists_the_candidates():
    depth = scene(A, B, C)
    hand = cg.load_hand("three-finger")
    default = cg.plan_grasp(None, depth, CAMERA, hand, **FAST)
    chosen = cg.plan_grasp(None, depth, CAMERA, hand, target_px=(490, 310), **FAST)
    assert default.target.bbox[:2] == A[:2] and chosen.target.bbox[:2] == B[:2]
    np.testing.assert_array_equal(chosen.segmentation.mask, chosen.target.mask)
    data = image_plan_to_dict(chosen)
    assert [o["in_view"] for o in data["objects"]] == [False, True, True]
    assert data["objects"][2] == {"label": 3, "area_px": 1600, "height": pytest.approx(0.08, abs=1e-6),
                                  "extent": pytest.approx([39 * 0.62 / 525] * 2, rel=1e-6),
                                  "centroid_px": [499.5, 319.5], "in_view": True, "touching": False,
                                  "bbox": [480, 300, 40, 40]}
    assert data["target"] == {"label": 3, "reason": "the candidate under pixel (490, 310)"}
    by_roi = cg.plan_grasp(None, depth, CAMERA, hand, roi=(470, 290, 20, 20), **FAST)
    np.testing.assert_allclose(by_roi.T_camera_hand, chosen.T_camera_hand)
    with pytest.raises(SegmentationError, match="not completely visible"):
        cg.plan_grasp(None, depth, CAMERA, hand, target_px=(10, 100), **FAST)
    with pytest.raises(PerceptionError, match="not with a mask"):
        cg.plan_grasp(None, depth, CAMERA, hand, mask=default.segmentation.mask, target_px=(490, 310))


def test_the_bundled_frame_lists_the_grippers_fingers_as_candidates_not_in_view():
    frame = read_rgbd(FRAME / "color_0.png", FRAME / "depth_0.npy", FRAME / "primesense_overhead_color.intr")
    result = cg.plan_grasp(frame.rgb, frame.depth, frame.intrinsics, "three-finger", **FAST)
    fingers = [c for c in result.candidates if not c.in_view]
    assert len(fingers) == 2 and all(c.bbox[1] + c.bbox[3] > 0.75 * frame.intrinsics.height for c in fingers)
    assert result.target.in_view and result.target.label == 3
    # the object planned on is the one today's segmentation finds
    d, _ = cg.perception.fill_depth_holes(frame.depth)
    today = segment(frame.rgb, d, frame.intrinsics)
    np.testing.assert_array_equal(result.segmentation.mask, today.mask)
    v, u = np.argwhere(result.target.mask)[len(np.argwhere(result.target.mask)) // 2]
    clicked = cg.plan_grasp(frame.rgb, frame.depth, frame.intrinsics, "three-finger", target_px=(int(u), int(v)),
                            **FAST)
    np.testing.assert_allclose(clicked.T_camera_hand, result.T_camera_hand)


#: ``contourgrasp plan`` on examples/bar_clamp with the default hand and planner, as the largest region's plan (the
#: squeeze's balance turned off to compare): listing the candidates must not move it.
MAIN_POSE = {"x": 0.12870781963601305, "y": -0.07405212705766118, "yaw": 1.3264502315156905}


def _plan(tmp_path, capsys, *extra):
    out = tmp_path / "plan.json"
    code = main(["plan", "--rgb", str(FRAME / "color_0.png"), "--depth", str(FRAME / "depth_0.npy"),
                 "--intrinsics", str(FRAME / "primesense_overhead_color.intr"), "--out", str(out), *extra])
    return code, out, capsys.readouterr()


def test_cli_plan_on_the_bundled_frame_is_unchanged_and_reports_objects(tmp_path, capsys):
    import json

    code, out, _ = _plan(tmp_path, capsys, "--max-imbalance", "1", "--centring-gain", "0")  # the plan of then
    assert code == 0
    data = json.loads(out.read_text())
    assert data["pose"] == pytest.approx(MAIN_POSE, abs=1e-9)
    assert [o["in_view"] for o in data["objects"]] == [False, False, True]
    assert data["target"]["label"] == 3 and "fit the hand" in data["target"]["reason"]
    assert data["support_surface"]["planes_considered"] == 1 and "dominant plane" in data["support_surface"]["reason"]


@pytest.mark.parametrize(("args", "message"), [
    (["--target", "1,2,3"], "--target: must be 2 integers U,V"),
    (["--target", "a,b"], "--target: must be 2 integers U,V"),
    (["--roi", "1,2,0,4"], "--roi: W and H must be positive"),
    (["--roi", "1,2,3"], "--roi: must be 4 integers X,Y,W,H"),
    (["--target", "1,2", "--roi", "0,0,5,5"], "not allowed with argument"),
    (["--target", "640,10"], "error: pixel (640, 10) is outside the 640x480 image"),
    (["--roi", "700,0,10,10"], "outside the 640x480 image"),
    (["--target", "320,50"], "error: no object at pixel (320, 50); the nearest candidate is at"),
    (["--target", "176,422"], "is not completely visible"),
    (["--roi", "0,0,100,100"], "error: no candidate in the ROI (0, 0, 100, 100)"),
])
def test_cli_plan_refuses_bad_targets_in_one_line_writing_nothing(tmp_path, capsys, args, message):
    code, out, (stdout, stderr) = _plan(tmp_path, capsys, *args)
    assert code == 2 and not out.exists()
    assert message in stderr and len(stderr.strip().splitlines()) == 1


def _scene_files(tmp_path, *boxes):
    depth, intrinsics = tmp_path / "depth.npy", tmp_path / "camera.yaml"
    np.save(depth, scene(*boxes))
    intrinsics.write_text(f"fx: {CAMERA.fx}\nfy: {CAMERA.fy}\ncx: {CAMERA.cx}\ncy: {CAMERA.cy}\nwidth: {W}\nheight: {H}\n")
    return ["plan", "--depth", str(depth), "--intrinsics", str(intrinsics), "--hand", "three-finger",
            "--xy-step", "0.03", "--yaw-step-deg", "6"]


def test_cli_plan_all_writes_a_plan_per_wholly_visible_object(tmp_path, capsys):
    import json

    args = _scene_files(tmp_path, A, B, C)
    code = main([*args, "--all", "--out", str(tmp_path / "plan.json"), "--plot", str(tmp_path / "plan.png")])
    stdout = capsys.readouterr().out
    assert code == 0
    written = sorted(p.name for p in tmp_path.glob("plan*"))
    # C (label 1) touches the border: an obstacle, not planned
    assert written == ["plan_2.json", "plan_2.png", "plan_3.json", "plan_3.png"]
    for label in (2, 3):
        data = json.loads((tmp_path / f"plan_{label}.json").read_text())
        assert data["target"]["label"] == label and len(data["objects"]) == 3
        assert f"object {label}: pose" in stdout
    single = main([*args, "--target", "490,310", "--out", str(tmp_path / "one.json")])
    assert single == 0
    assert json.loads((tmp_path / "one.json").read_text())["pose"] == json.loads(
        (tmp_path / "plan_3.json").read_text())["pose"]
    capsys.readouterr()
    assert main([*args, "--all"]) == 0
    printed = json.loads(capsys.readouterr().out)
    assert [p["target"]["label"] for p in printed] == [2, 3]


def test_cli_plan_all_skips_an_object_without_a_grasp_and_exits_3_when_none_has_one(tmp_path, capsys):
    huge = (60, 60, 360, 360, 0.05)  # 0.45 x 0.45 m: wider than any hand opens
    args = _scene_files(tmp_path, huge, B)
    assert main([*args, "--all", "--out", str(tmp_path / "plan.json")]) == 0
    err = capsys.readouterr().err
    assert sorted(p.name for p in tmp_path.glob("plan*.json")) == ["plan_2.json"]
    assert "contourgrasp: object 1: no feasible grasp" in err
    (tmp_path / "only").mkdir()
    only = _scene_files(tmp_path / "only", huge)
    assert main([*only, "--all", "--out", str(tmp_path / "only" / "plan.json")]) == 3
    assert not list((tmp_path / "only").glob("plan*.json"))
    assert "none of the 1 wholly visible objects was planned" in capsys.readouterr().err


def test_cli_plan_any_plans_the_next_object_when_the_chosen_one_has_none(tmp_path, capsys):
    import json

    middle, far = (300, 220, 40, 40, 0.06), (560, 40, 40, 40, 0.06)
    walls = [(150, 150, 148, 180, 0.25), (342, 150, 148, 180, 0.25)]  # 25 cm tall, 2 px from it
    args = _scene_files(tmp_path, middle, *walls, far)
    assert main([*args, "--out", str(tmp_path / "plan.json")]) == 3  # the one nearest the centre, between the walls
    assert not (tmp_path / "plan.json").exists()
    assert main([*args, "--any", "--out", str(tmp_path / "plan.json")]) == 0
    target = json.loads((tmp_path / "plan.json").read_text())["target"]
    assert target["reason"] == "the candidate under pixel (579, 59)"  # the far box's deepest pixel
    (tmp_path / "walled").mkdir()
    walled = _scene_files(tmp_path / "walled", middle, *walls)
    capsys.readouterr()
    assert main([*walled, "--any", "--out", str(tmp_path / "walled" / "plan.json")]) == 3
    assert "none of the 3 objects tried has a feasible grasp; the last:" in capsys.readouterr().err  # the walls too


@pytest.mark.parametrize(("boxes", "extra", "message"), [
    ((A,), ["--any", "--segment", "rgb"], "--any chooses among the depth candidates"),
    ((C, (600, 0, 40, 40, 0.05)), ["--all"], "not completely visible: every region on the support surface"),
    ((C, (600, 0, 40, 40, 0.05)), [], "not completely visible"),
    ((), ["--all"], "nothing stands on the support surface"),
    ((A,), ["--target", "100,400"], "no object at pixel (100, 400); the nearest candidate is at (300, 259)"),
    ((A,), ["--target=-1,5"], "pixel (-1, 5) is outside the 640x480 image"),
    ((A,), ["--roi", "0,0,50,50"], "no candidate in the ROI (0, 0, 50, 50): nothing stands on the support surface"),
    ((A,), ["--all", "--segment", "rgb"], "--all plans every depth candidate"),
    ((A,), ["--all", "--target", "1,1"], "not allowed with argument"),
])
def test_cli_plan_bad_targets_are_one_line_exit_2_nothing_written(tmp_path, capsys, boxes, extra, message):
    args = _scene_files(tmp_path, *boxes)
    code = main([*args, *extra, "--out", str(tmp_path / "plan.json")])
    err = capsys.readouterr().err
    assert code == 2 and not list(tmp_path.glob("plan*"))
    assert message in err and len(err.strip().splitlines()) == 1


def test_cli_plan_all_writes_all_or_nothing(tmp_path, capsys):
    args = _scene_files(tmp_path, A, B, C)
    (tmp_path / "plan_3.json").mkdir()  # the second object's plan cannot be written
    assert main([*args, "--all", "--out", str(tmp_path / "plan.json")]) == 2
    assert "plan_3.json: cannot write, it is a directory" in capsys.readouterr().err
    assert not (tmp_path / "plan_2.json").exists()


def test_a_pixel_on_an_object_inside_a_bins_walls_is_the_object_not_the_bin():
    """The walls' ring, its hole filled, covers the objects in the bin too: the innermost candidate wins."""
    walls = [(150, 100, 300, 10, 0.10), (150, 300, 300, 10, 0.10), (150, 100, 10, 210, 0.10), (440, 100, 10, 210, 0.10)]
    found = candidates(scene(*walls, (270, 180, 60, 40, 0.05)))
    target, _ = choose_target(found, target_px=(300, 200))
    assert target.bbox == (270, 180, 60, 40)
    ring, _ = choose_target(found, target_px=(155, 200))
    assert ring.bbox == (150, 100, 300, 210)


#: A low flat object (a fork's raised neck: 18 mm) with a thin handle leaving its right side.
NECK = (300, 200, 100, 60, 0.018)


def with_handle(depth, handle_height=0.005, noise=0.002, seed=0):
    """``depth`` with a thin handle (4 x 60 px, ``handle_height`` up) leaving NECK's right side, and table noise."""
    depth = depth.copy()
    depth[228:232, 400:460] = TABLE - handle_height
    return depth + np.random.default_rng(seed).normal(0.0, noise, depth.shape)


def up(depth):
    return heights(depth, CAMERA, fit_table_plane(depth, CAMERA))


def test_a_pixel_on_a_low_part_is_the_candidate_the_part_leads_to():
    """A fork's handle lies below MIN_HEIGHT: no candidate holds it, and clicking it names its object."""
    depth = with_handle(scene(NECK, B))
    found = candidates(depth)
    target, reason = choose_target(found, target_px=(450, 230), pixel_heights=up(depth))
    assert target.bbox[:2] == NECK[:2] and reason == "the candidate the low part under pixel (450, 230) belongs to"
    assert low_part_candidate(found, (330, 230), up(depth)) is None  # on the neck itself: the candidate under the pixel
    with pytest.raises(SegmentationError, match=r"^no object at pixel \(450, 230\)"):
        choose_target(found, target_px=(450, 230))  # without heights, as before
    with pytest.raises(SegmentationError, match=r"^no object at pixel \(450, 260\)"):
        choose_target(found, target_px=(450, 260), pixel_heights=up(depth))  # the bare table beside the handle


def test_a_low_part_does_not_lead_to_a_tall_neighbour_it_touches():
    """A 10 cm box against the handle's end stands up sharply beside it: the handle still leads to its neck, and a
    handle that touches only the tall box leads nowhere (refused as before, rather than the wrong object)."""
    tall = (460, 210, 40, 40, 0.10)
    depth = with_handle(scene(NECK, tall))
    assert choose_target(candidates(depth), target_px=(455, 230), pixel_heights=up(depth))[0].bbox[:2] == NECK[:2]
    alone = with_handle(scene(tall))
    assert low_part_candidate(candidates(alone), (455, 230), up(alone)) is None


@pytest.mark.parametrize("handle_height, found_by_part", [(0.004, True), (0.0015, False)])
def test_a_low_part_must_stand_above_the_tables_noise(handle_height, found_by_part):
    """With 2 mm of noise, 5 sigma of the 5 x 5 median (about 1 mm) separates a 4 mm handle from the table; 1.5 mm
    does not."""
    depth = with_handle(scene(NECK), handle_height=handle_height)
    assert (low_part_candidate(candidates(depth), (450, 230), up(depth)) is not None) == found_by_part


def test_a_low_part_inside_a_bins_walls_leads_to_its_object_not_the_bin():
    """The walls' filled ring holds the handle's pixel and the neck alike: the innermost candidate the part reaches."""
    walls = [(150, 100, 400, 10, 0.10), (150, 350, 400, 10, 0.10), (150, 100, 10, 260, 0.10), (540, 100, 10, 260, 0.10)]
    depth = with_handle(scene(*walls, NECK))
    found = candidates(depth)
    assert choose_target(found, target_px=(450, 230))[0].bbox == (150, 100, 400, 260)  # without heights: the bin
    assert choose_target(found, target_px=(450, 230), pixel_heights=up(depth))[0].bbox[:2] == NECK[:2]


def test_pixel_heights_of_another_size_are_refused():
    found = candidates(scene(A))
    with pytest.raises(PerceptionError, match=r"pixel_heights is 10x10 but the depth image is 640x480"):
        choose_target(found, target_px=(450, 230), pixel_heights=np.zeros((10, 10)))


def bin_with_box():
    """A bin's 10 cm walls (a 20 px ring around 160 x 120 px) and a 4 cm box touching the inner face of its left wall."""
    walls = (200, 150, 200, 160, 0.10)
    depth = scene(walls)
    depth[170:290, 220:380] = TABLE  # the bin's floor: the table itself here
    depth[200:260, 220:280] = TABLE - 0.04  # the box, against the left wall
    return depth


def test_an_object_touching_a_bin_wall_is_a_candidate_of_its_own():
    found = candidates(bin_with_box())
    assert len(found) == 2
    walls, box = found
    assert walls.area_px == 200 * 160 - 160 * 120 and box.area_px == 60 * 60
    assert box.height == pytest.approx(0.04, abs=1e-6) and walls.height == pytest.approx(0.10, abs=1e-6)
    target, _ = choose_target(found, target_px=(250, 230))
    assert target is box


def test_a_step_within_an_object_leaves_it_whole():
    """A block 4 cm higher on a box's body (a clamp's jaw): pieces side by side, not one inside another."""
    depth = scene((300, 200, 100, 60, 0.03))
    depth[200:230, 300:340] = TABLE - 0.07
    found = candidates(depth)
    assert len(found) == 1 and found[0].area_px == 6000


def test_planning_on_the_object_in_the_bin_takes_its_region_not_the_walls():
    result = cg.plan_grasp(None, bin_with_box(), CAMERA, cg.load_hand("five-finger-linear"), target_px=(250, 230),
                        segment="depth", **FAST)
    assert result.segmentation.mask.sum() == 60 * 60


def test_in_grey_the_wall_an_object_was_split_from_is_no_flat_part_of_it():
    """Grey images take flat-part evidence from the heights; the wall beside the box stands, but is another object."""
    grey = np.full((H, W, 3), 128, dtype=np.uint8)
    result = cg.plan_grasp(grey, bin_with_box(), CAMERA, cg.load_hand("five-finger-linear"), target_px=(250, 230),
                        **FAST)
    assert result.segmentation.mask.sum() == 60 * 60


def ring_with_a_post(side_px, post_depth):
    """(above, depth): a square ring of wall 5 px thick, ``side_px`` across at 0.6 m, and a 30 px post over its top
    side at ``post_depth``, reaching beyond it, as a tall object standing in front of a bin's far wall looks."""
    above, depth = np.zeros((220, 220), bool), np.full((220, 220), 0.6)
    lo, hi = 110 - side_px // 2, 110 + side_px // 2
    above[lo:hi, lo:hi] = True
    above[lo + 5:hi - 5, lo + 5:hi - 5] = False
    above[lo - 10:lo + 20, 95:125], depth[lo - 10:lo + 20, 95:125] = True, post_depth
    return above, depth


def test_a_post_that_closes_a_bins_ring_in_front_of_its_wall_is_split_from_it():
    from contourgrasp.perception.candidates import split_at_depth_steps

    focal = (500.0, 500.0)  # the 150 x 150 px floor at 0.6 m: 0.032 m^2, a bin's
    above, depth = ring_with_a_post(160, 0.55)
    assert split_at_depth_steps(above, depth, 100)[0] == 1  # the post is not inside the walls' outline
    assert split_at_depth_steps(above, depth, 100, focal=focal)[0] == 2  # but it closes the walls round a floor
    above, depth = ring_with_a_post(160, 0.6)
    assert split_at_depth_steps(above, depth, 100, focal=focal)[0] == 1  # no step between them: one surface
    above, depth = ring_with_a_post(60, 0.55)  # a 50 px hole, 0.0036 m^2: a handle's, not a floor
    assert split_at_depth_steps(above, depth, 100, focal=focal)[0] == 1


def test_regions_without_a_split_are_opencvs_on_the_whole_image():
    """Labelled on the raised pixels' box, the labels, boxes and centroids are OpenCV's on the whole image, to the bit."""
    from contourgrasp.perception.candidates import split_at_depth_steps

    rng = np.random.default_rng(4)
    for _ in range(100):
        above = np.zeros((97, 131), bool)
        for _ in range(rng.integers(1, 6)):
            r, c = rng.integers(1, 97), rng.integers(1, 131)
            block = above[r:r + rng.integers(1, 40), c:c + rng.integers(1, 40)]
            block[...] = rng.random(block.shape) < 0.8
        count, labels, stats, centroids = split_at_depth_steps(above, np.full(above.shape, 0.6), 10)
        n, whole, whole_stats, whole_centroids = cv2.connectedComponentsWithStats(above.astype(np.uint8),
                                                                                  connectivity=8)
        assert count == n - 1
        np.testing.assert_array_equal(labels, whole)
        np.testing.assert_array_equal(stats[1:], whole_stats[1:])
        np.testing.assert_array_equal(centroids[1:], whole_centroids[1:])


def test_a_split_region_moves_with_the_image():
    """The split of the post from a bin's ring, the picture shifted by (7, 5) px: the same regions, shifted."""
    from contourgrasp.perception.candidates import split_at_depth_steps

    above, depth = ring_with_a_post(160, 0.55)
    count, labels, stats, centroids = split_at_depth_steps(above, depth, 100, focal=(500.0, 500.0))
    moved = [np.pad(a, ((5, 0), (7, 0)), constant_values=fill) for a, fill in ((above, False), (depth, 0.6))]
    count_moved, labels_moved, stats_moved, centroids_moved = split_at_depth_steps(*moved, 100, focal=(500.0, 500.0))
    assert count == count_moved == 2
    np.testing.assert_array_equal(labels_moved[5:, 7:], labels)
    np.testing.assert_array_equal(stats_moved[1:], stats[1:] + [7, 5, 0, 0, 0])
    np.testing.assert_allclose(centroids_moved[1:], centroids[1:] + [7, 5], rtol=0, atol=1e-9)
