"""contourgrasp.doctor and ``contourgrasp doctor``: a first look at a user's frame, on the bundled frame and on
frames made wrong in the ways users' are (intrinsics of another resolution, colour off by pixels, depth in
millimetres)."""

import json
import os
import shutil
from dataclasses import replace
from pathlib import Path

import cv2
import numpy as np
import pytest

import contourgrasp as cg
from contourgrasp.cli import main
from contourgrasp.doctor import diagnose

REPO = Path(__file__).resolve().parents[1]
FRAME = REPO / "examples" / "bar_clamp"
SHARED = Path(os.environ.get("CONTOURGRASP_SHARED_DATA", REPO.parent / "shared" / "data"))


@pytest.fixture(scope="module")
def bundled():
    return cg.read_rgbd(FRAME / "color_0.png", FRAME / "depth_0.npy", FRAME / "primesense_overhead_color.intr")


def verdicts(diagnosis) -> dict:
    return {f.topic: f.verdict for f in diagnosis.findings}


def test_the_bundled_frame_looks_right_and_plans(bundled):
    diagnosis = diagnose(bundled.rgb, bundled.depth, bundled.intrinsics, cg.load_hand("five-finger-linear"))
    assert not diagnosis.warnings, diagnosis.lines()
    topics = [f.topic for f in diagnosis.findings]
    assert topics == ["depth", "missing", "intrinsics", "colour", "support", "objects", "target", "plan",
                      "registration"]
    assert "field of view of 63 x 49 deg" in dict((f.topic, f.text) for f in diagnosis.findings)["intrinsics"]
    assert diagnosis.result is not None and diagnosis.support.plane.tilt < np.radians(5)


def test_intrinsics_of_another_resolution_are_flagged(bundled):
    """The same frame with the focal lengths and principal point of a 1280 x 960 stream, the size fields corrected:
    the principal point lands at the image's edge."""
    k = bundled.intrinsics
    wrong = replace(k, fx=2 * k.fx, fy=2 * k.fy, cx=2 * k.cx, cy=2 * k.cy)
    diagnosis = diagnose(None, bundled.depth, wrong, cg.load_hand("three-finger"))
    assert verdicts(diagnosis)["intrinsics"] == "warning"
    assert any("another resolution" in line for line in diagnosis.lines())


def test_colour_off_by_pixels_is_flagged(bundled):
    shifted = np.roll(bundled.rgb, (8, 0), axis=(0, 1))  # the colour 8 px lower than the depth
    diagnosis = diagnose(shifted, bundled.depth, bundled.intrinsics, cg.load_hand("five-finger-linear"))
    registration = next(f for f in diagnosis.findings if f.topic == "registration")
    assert registration.verdict == "warning" and "--colour-offset" in registration.text


def test_missing_readings_beside_edges_are_told_from_the_rest():
    """A box on a table with a 4 px shadow on one side and a blob of missing readings far from it."""
    depth = np.full((120, 160), 0.7)
    depth[40:80, 50:90] = 0.6
    depth[40:80, 90:94] = 0.0       # the projector's shadow beside the box's edge
    depth[5:15, 5:15] = 0.0         # a dark patch on the table
    k = cg.perception.Intrinsics(fx=200.0, fy=200.0, cx=79.5, cy=59.5, width=160, height=120)
    diagnosis = diagnose(None, depth, k, cg.load_hand("three-finger"))
    assert diagnosis.edge_missing[40:80, 90:94].all() and not diagnosis.edge_missing[5:15, 5:15].any()


def test_the_command_reads_folders_and_draws(tmp_path, capsys):
    folder = tmp_path / "frame"
    folder.mkdir()
    for name in ("color_0.png", "depth_0.npy", "primesense_overhead_color.intr"):
        shutil.copy(FRAME / name, folder / name)
    assert main(["doctor", str(folder), "--plot", str(tmp_path / "doctor.png")]) == 0
    out = capsys.readouterr().out
    assert out.startswith(f"frame: {folder / 'color_0.png'}, {folder / 'depth_0.npy'}") and "planned:" in out
    assert (tmp_path / "doctor.png").stat().st_size > 10_000


@pytest.mark.parametrize("make, message", [
    (lambda d: None, "no colour file"),
    (lambda d: cv2.imwrite(str(d / "color.png"), np.zeros((48, 64, 3), np.uint8)), "no depth file"),
])
def test_a_folder_without_a_frame_is_one_line_and_exit_2(tmp_path, capsys, make, message):
    make(tmp_path)
    assert main(["doctor", str(tmp_path)]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and message in err


def test_a_depth_in_millimetres_read_as_metres_is_refused_naming_the_file(tmp_path, capsys):
    depth = np.load(FRAME / "depth_0.npy")
    cv2.imwrite(str(tmp_path / "depth.png"), (depth * 1000).astype(np.uint16))
    (tmp_path / "camera.json").write_text(json.dumps({"fx": 525.0, "fy": 525.0, "cx": 319.5, "cy": 239.5,
                                                      "width": 640, "height": 480}))
    args = ["doctor", "--depth", str(tmp_path / "depth.png"), "--intrinsics", str(tmp_path / "camera.json")]
    assert main([*args, "--depth-scale", "1"]) == 2
    assert "depth.png" in capsys.readouterr().err
    assert main(args) == 0  # millimetres, the default scale
    assert "median reading 0.66" in capsys.readouterr().out


@pytest.mark.skipif(not (SHARED / "rgbd").is_dir(), reason=f"the shared real frames are not at {SHARED}")
def test_every_shared_real_frame_is_read_and_told():
    for folder in sorted((SHARED / "rgbd").glob("real_*")):
        frame = cg.read_rgbd(folder / "color.png", folder / "depth.npy", folder / "camera.yaml")
        diagnosis = diagnose(frame.rgb, frame.depth, frame.intrinsics, cg.load_hand("five-finger-linear"),
                             colour_intrinsics=frame.colour_intrinsics)
        assert diagnosis.support is not None, folder.name
        assert {"depth", "missing", "intrinsics", "colour", "support", "objects", "plan"} <= set(verdicts(diagnosis))
