import json
import math
import os
from pathlib import Path

import cv2
import numpy as np
import pytest

import contourgrasp as cg
from contourgrasp.cli import main
from contourgrasp.io.camera_file import read_extrinsics, read_intrinsics, read_mask, read_rgbd

REPO = Path(__file__).resolve().parents[1]
FRAME = REPO / "examples" / "bar_clamp"
SHARED = Path(os.environ.get("CONTOURGRASP_SHARED_DATA", REPO.parent / "shared" / "data"))
SINGLE = SHARED / "rgbd" / "gqcnn_primesense_single_object"
needs_data = pytest.mark.skipif(not SINGLE.is_dir(), reason=f"real RGB-D frames not found at {SINGLE}")
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
    assert T[2, 3] == pytest.approx(result.metric.approach_depth, abs=0.01)
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
    assert (tmp_path / "p.png").stat().st_size > 10000


def test_footprint_can_be_forced_either_way():
    # The bundled frame is tilted 3.3 deg, so by default the footprint is planned, on the table plane.
    frame = bundled()
    default = cg.plan_grasp(frame.rgb, frame.depth, frame.intrinsics, "three-finger", **FAST)
    seen = cg.plan_grasp(frame.rgb, frame.depth, frame.intrinsics, "three-finger", footprint=False, **FAST)
    assert default.segmentation.on_table and default.metric.on_table
    assert not seen.segmentation.on_table and not seen.metric.on_table
    assert seen.segmentation.area_px > default.segmentation.area_px  # the tall clamp's top and near side
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
    with pytest.raises(SystemExit) as exit_:
        main([*args, "--colour-offset", "1.5,0"])
    assert exit_.value.code == 2


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
])
def test_plan_bad_inputs(tmp_path, capsys, case, code, message):
    overrides = {}
    if case == "missing rgb":
        overrides["--rgb"] = tmp_path / "nope.png"
    elif case == "size mismatch":
        small = tmp_path / "small.png"
        cv2.imwrite(str(small), np.zeros((240, 320, 3), np.uint8))
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
    before = set(tmp_path.iterdir())
    result = main(plan_args(tmp_path, **overrides))
    err = capsys.readouterr().err
    lines = [line for line in err.strip().splitlines() if "warning" not in line]
    assert result == code
    assert len(lines) == 1 and message in lines[0] and "Traceback" not in err
    assert set(tmp_path.iterdir()) == before


def test_intrinsics_from_shared_format_match_the_bundled_file():
    k = read_intrinsics(FRAME / "primesense_overhead_color.intr")
    assert (k.fx, k.fy, k.cx, k.cy, k.width, k.height) == (525.0, 525.0, 319.5, 239.5, 640, 480)
