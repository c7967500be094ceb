"""Camera files: colour, depth, masks, intrinsics, extrinsics."""

from __future__ import annotations

import json
import math
import os
import re
from pathlib import Path

import cv2
import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from contourgrasp.errors import DepthUnitWarning, InputError, UnitWarning
from contourgrasp.io.camera_file import (
    Intrinsics,
    read_depth,
    read_extrinsics,
    read_intrinsics,
    read_mask,
    read_rgb,
    read_rgbd,
)

PLAIN = {"fx": 525.0, "fy": 520.0, "cx": 319.5, "cy": 239.5, "width": 640, "height": 480}
EXPECTED = Intrinsics(fx=525.0, fy=520.0, cx=319.5, cy=239.5, width=640, height=480)


def rotation_z(angle):
    c, s = math.cos(angle), math.sin(angle)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def transform(angle=0.3, translation=(0.1, -0.2, 0.9)):
    matrix = np.eye(4)
    matrix[:3, :3] = rotation_z(angle) @ np.array([[1.0, 0, 0], [0, -1, 0], [0, 0, -1]])
    matrix[:3, 3] = translation
    return matrix


def write(path: Path, text: str) -> Path:
    path.write_text(text, encoding="utf-8")
    return path


# ---------------------------------------------------------------------------
# Images
# ---------------------------------------------------------------------------


@pytest.mark.parametrize("suffix", [".png", ".jpg"])
def test_rgb_is_returned_in_rgb_order(tmp_path, suffix):
    bgr = np.zeros((20, 30, 3), np.uint8)
    bgr[..., 0] = 200  # blue in OpenCV's order
    cv2.imwrite(str(tmp_path / f"c{suffix}"), bgr)
    rgb = read_rgb(tmp_path / f"c{suffix}")
    assert rgb.shape == (20, 30, 3) and rgb.dtype == np.uint8
    assert rgb[..., 2].mean() > 190 and rgb[..., 0].mean() < 10


def test_unreadable_images(tmp_path):
    with pytest.raises(InputError, match=r"nothing\.png: file not found"):
        read_rgb(tmp_path / "nothing.png")
    with pytest.raises(InputError, match="not a readable image"):
        read_rgb(write(tmp_path / "text.png", "not an image"))


def test_float_depth_in_meters_is_squeezed(tmp_path):
    depth = np.full((4, 5, 1), 0.7, np.float32)
    depth[0, 0] = 0.0
    np.save(tmp_path / "d.npy", depth)
    out = read_depth(tmp_path / "d.npy")
    assert out.shape == (4, 5) and out.dtype == float
    assert out[0, 0] == 0.0 and out[1, 1] == pytest.approx(0.7)


def test_integer_depth_is_scaled(tmp_path):
    raw = np.full((4, 5), 700, np.uint16)
    cv2.imwrite(str(tmp_path / "d.png"), raw)
    np.save(tmp_path / "d.npy", raw.astype(np.int32) * 10)
    assert read_depth(tmp_path / "d.png") == pytest.approx(np.full((4, 5), 0.7))
    assert read_depth(tmp_path / "d.npy", depth_scale=1e-4) == pytest.approx(np.full((4, 5), 0.7))


def test_depth_in_the_wrong_unit_warns(tmp_path):
    np.save(tmp_path / "mm.npy", np.full((4, 4), 700.0))
    with pytest.warns(UnitWarning, match=r"median depth 700 m: probably millimetres \(scale 0.001\)"):
        read_depth(tmp_path / "mm.npy")
    cv2.imwrite(str(tmp_path / "d.png"), np.full((4, 4), 7, np.uint16))
    with pytest.warns(UnitWarning, match="closer than a depth camera measures"):
        read_depth(tmp_path / "d.png")
    np.save(tmp_path / "tenths.npy", np.full((4, 4), 70_000.0))
    with pytest.warns(UnitWarning, match=r"median depth 7e\+04 m: probably tenths of millimetres \(scale 0.0001\)"):
        read_depth(tmp_path / "tenths.npy")
    np.save(tmp_path / "absurd.npy", np.full((4, 4), 1e300))
    with pytest.warns(UnitWarning, match="median depth 1e\\+300 m: no depth camera's unit makes that a distance"):
        read_depth(tmp_path / "absurd.npy")


def test_a_depth_unit_warning_names_the_scale_option_as_its_caller_spells_it(tmp_path):
    np.save(tmp_path / "mm.npy", np.full((4, 4), 700.0))
    cv2.imwrite(str(tmp_path / "mm.png"), np.full((4, 4), 700, np.uint16))
    with pytest.warns(DepthUnitWarning) as floats:
        read_depth(tmp_path / "mm.npy")
    with pytest.warns(DepthUnitWarning) as integers:
        read_depth(tmp_path / "mm.png", depth_scale=1.0)
    floats, integers = floats[0].message, integers[0].message
    assert str(floats).endswith("; pass integer millimetres with depth_scale=0.001, or convert to meters")
    assert floats.advice("--depth-scale", " ").endswith("with --depth-scale 0.001, or convert to meters")
    assert str(integers).endswith("probably millimetres (scale 0.001); check depth_scale")
    assert integers.advice("--depth-scale", " ").endswith("; check --depth-scale")
    assert str(integers).startswith(f"{tmp_path / 'mm.png'}: median depth 700 m") and isinstance(integers, UnitWarning)


@pytest.mark.parametrize(
    "array, message",
    [
        (np.zeros((4, 4)), "no valid pixel"),
        (np.full((4, 4), np.nan), "no valid pixel"),
        (np.ones((4, 4, 3)), r"one channel .* got shape \(4, 4, 3\)"),
        (np.ones((4, 4), bool), "depth of type bool"),
    ],
)
def test_bad_depth_is_refused(tmp_path, array, message):
    np.save(tmp_path / "d.npy", array)
    with pytest.raises(InputError, match=message):
        read_depth(tmp_path / "d.npy")


def test_eight_bit_depth_and_bad_scale_are_refused(tmp_path):
    cv2.imwrite(str(tmp_path / "d.png"), np.full((4, 4), 100, np.uint8))
    with pytest.raises(InputError, match="16-bit"):
        read_depth(tmp_path / "d.png")
    with pytest.raises(InputError, match="depth_scale must be a positive number"):
        read_depth(tmp_path / "d.png", depth_scale=0)


def test_masks(tmp_path):
    mask = np.zeros((6, 8), np.uint8)
    mask[2:4, 3:6] = 255
    cv2.imwrite(str(tmp_path / "m.png"), mask)
    cv2.imwrite(str(tmp_path / "rgb.png"), np.dstack([np.zeros_like(mask), mask, np.zeros_like(mask)]))
    np.save(tmp_path / "m.npy", mask > 0)
    for name in ("m.png", "rgb.png", "m.npy"):
        out = read_mask(tmp_path / name)
        assert out.dtype == bool
        np.testing.assert_array_equal(out, mask > 0)


def test_an_empty_mask_is_refused_naming_the_file(tmp_path):
    cv2.imwrite(str(tmp_path / "empty.png"), np.zeros((6, 8), np.uint8))
    with pytest.raises(InputError, match=r"empty\.png: the mask is empty"):
        read_mask(tmp_path / "empty.png")


# ---------------------------------------------------------------------------
# Intrinsics
# ---------------------------------------------------------------------------


def test_plain_intrinsics_json(tmp_path):
    assert read_intrinsics(write(tmp_path / "camera.json", json.dumps(PLAIN))) == EXPECTED


def test_autolab_intr(tmp_path):
    fields = {f"_{key}": value for key, value in PLAIN.items()} | {"_skew": 0.0, "_frame": "cam"}
    assert read_intrinsics(write(tmp_path / "camera.intr", json.dumps(fields))) == EXPECTED


def test_ros_camera_info_k(tmp_path):
    info = {"width": 640, "height": 480, "K": [525.0, 0, 319.5, 0, 520.0, 239.5, 0, 0, 1]}
    assert read_intrinsics(write(tmp_path / "info.json", json.dumps(info))) == EXPECTED


@pytest.mark.parametrize(
    "fields, message",
    [
        ({key: value for key, value in PLAIN.items() if key != "fy"}, "missing field fy"),
        (PLAIN | {"fx": -1.0}, r"fx must be a focal length in pixels in \[1, 1e\+06\], got -1"),
        (PLAIN | {"fx": 1e-300}, r"fx must be a focal length in pixels in \[1, 1e\+06\], got 1e-300"),
        (PLAIN | {"fy": 1e308}, r"fy must be a focal length in pixels in \[1, 1e\+06\], got 1e\+308"),
        (PLAIN | {"cx": 1e6}, r"cx must lie within the image or one image size beside it"),
        (PLAIN | {"width": 10_000, "height": 10_000}, r"a 10000x10000 image has more than 25,000,000 pixels"),
        (PLAIN | {"cx": "middle"}, "cx must be a finite number"),
        (PLAIN | {"height": 0}, "height must be a positive whole number"),
        ({"camera_matrix": {"rows": 3}, "image_width": 640, "image_height": 480}, "missing field camera_matrix.data"),
        ({"K": [1, 2, 3], "width": 640, "height": 480}, r"field K must have shape \(9,\)"),
        ({"_fx": 1.0}, "missing field _fy"),
    ],
)
def test_bad_intrinsics_name_the_file_and_field(tmp_path, fields, message):
    path = write(tmp_path / "camera.json", json.dumps(fields))
    with pytest.raises(InputError, match=f"camera.json: .*{message}"):
        read_intrinsics(path)


@pytest.mark.parametrize("name, text, message", [
    ("camera.json", '{"fx": ' + "9" * 5000 + "}", "a number too long to be camera data"),
    ("camera.yaml", "fx: " + "9" * 5000 + "\n", "a number too long to be camera data"),
    ("camera.yaml", "a: &a [1, 1, 1, 1, 1, 1, 1, 1, 1]\n" + "".join(
        f"{c}: &{c} [*{p}, *{p}, *{p}, *{p}, *{p}, *{p}, *{p}, *{p}, *{p}]\n" for p, c in zip("abcdefgh", "bcdefghi")),
     "YAML aliases"),
])
def test_camera_files_that_would_take_unbounded_work_are_refused_by_name(tmp_path, name, text, message):
    """A 5,000-digit integer, or a 500-byte YAML alias bomb (an array of gigabytes): one line naming the file."""
    path = write(tmp_path / name, text)
    for reader in (read_intrinsics, read_extrinsics):
        with pytest.raises(InputError, match=f"^{re.escape(str(path))}: {message}"):
            reader(path)


def test_an_image_of_too_many_pixels_is_refused_before_it_is_decoded(tmp_path):
    import cv2

    cv2.imwrite(str(tmp_path / "big.png"), np.zeros((6000, 5000), np.uint8))  # 30 MP, a few kB of PNG
    with pytest.raises(InputError, match=r"big.png: a 5000x6000 image has more than 25,000,000 pixels"):
        read_rgb(tmp_path / "big.png")
    np.lib.format.open_memmap(tmp_path / "big.npy", mode="w+", dtype=np.float32, shape=(6000, 5000)).flush()
    with pytest.raises(InputError, match=r"big.npy: a 5000x6000 image has more than 25,000,000 pixels"):
        read_depth(tmp_path / "big.npy")


def test_unreadable_intrinsics(tmp_path):
    with pytest.raises(InputError, match="not valid JSON"):
        read_intrinsics(write(tmp_path / "camera.json", "{fx: 1"))
    with pytest.raises(InputError, match="must be a mapping"):
        read_intrinsics(write(tmp_path / "camera.json", "[1, 2]"))
    with pytest.raises(InputError, match="file not found"):
        read_intrinsics(tmp_path / "absent.json")


def test_intrinsics_yaml_plain_and_ros(tmp_path):
    pytest.importorskip("yaml", reason="PyYAML not installed")
    plain = "\n".join(f"{key}: {value}" for key, value in PLAIN.items())
    assert read_intrinsics(write(tmp_path / "camera.yaml", plain)) == EXPECTED
    ros = (
        "image_width: 640\nimage_height: 480\ncamera_name: primesense\n"
        "camera_matrix:\n  rows: 3\n  cols: 3\n  data: [525.0, 0.0, 319.5, 0.0, 520.0, 239.5, 0.0, 0.0, 1.0]\n"
        "distortion_model: plumb_bob\n"
    )
    assert read_intrinsics(write(tmp_path / "ost.yml", ros)) == EXPECTED
    with pytest.raises(InputError, match="not valid YAML"):
        read_intrinsics(write(tmp_path / "bad.yaml", "fx: [1, 2"))


# ---------------------------------------------------------------------------
# Extrinsics
# ---------------------------------------------------------------------------


def test_extrinsics_formats_agree(tmp_path):
    matrix = transform()
    np.save(tmp_path / "T.npy", matrix)
    np.savetxt(tmp_path / "T.txt", matrix)
    write(tmp_path / "list.json", json.dumps(matrix.tolist()))
    write(tmp_path / "matrix.json", json.dumps({"matrix": matrix.tolist()}))
    write(tmp_path / "parts.json", json.dumps({"rotation": matrix[:3, :3].tolist(), "translation": matrix[:3, 3].tolist()}))
    rows = "\n".join(" ".join(f"{x:.6f}" for x in row) for row in matrix[:3, :3])
    write(tmp_path / "cam.tf", f"camera\nworld\n{' '.join(map(str, matrix[:3, 3]))}\n{rows}\n")
    for name in ("T.npy", "T.txt", "list.json", "matrix.json", "parts.json", "cam.tf"):
        np.testing.assert_allclose(read_extrinsics(tmp_path / name), matrix, atol=2e-6, err_msg=name)


def test_rounded_rotation_is_made_exact(tmp_path):
    rows = "\n".join(" ".join(f"{x:.6f}" for x in row) for row in transform()[:3, :3])
    out = read_extrinsics(write(tmp_path / "cam.tf", f"a\nb\n0 0 0\n{rows}\n"))
    np.testing.assert_allclose(out[:3, :3].T @ out[:3, :3], np.eye(3), atol=1e-12)
    assert np.linalg.det(out[:3, :3]) == pytest.approx(1.0, abs=1e-12)


@pytest.mark.parametrize(
    "change, message",
    [
        (lambda m: m[:3, :3].__imul__(1.01), "not orthonormal"),
        (lambda m: m[:, 0].__imul__(-1), r"det = -1"),
        (lambda m: m[3].__setitem__(0, 0.5), "last row .* must be 0 0 0 1"),
    ],
)
def test_non_rigid_extrinsics_are_refused(tmp_path, change, message):
    matrix = transform()
    change(matrix)
    np.save(tmp_path / "T.npy", matrix)
    with pytest.raises(InputError, match=f"T.npy: .*{message}"):
        read_extrinsics(tmp_path / "T.npy")


def test_malformed_extrinsics(tmp_path):
    np.save(tmp_path / "T.npy", np.eye(3))
    with pytest.raises(InputError, match=r"matrix must have shape \(4, 4\)"):
        read_extrinsics(tmp_path / "T.npy")
    with pytest.raises(InputError, match="a .tf file has 6 lines"):
        read_extrinsics(write(tmp_path / "cam.tf", "a\nb\n0 0 0\n"))
    with pytest.raises(InputError, match="translation .* must hold numbers"):
        read_extrinsics(write(tmp_path / "cam.tf", "a\nb\nx y z\n1 0 0\n0 1 0\n0 0 1\n"))
    with pytest.raises(InputError, match="missing field matrix"):
        read_extrinsics(write(tmp_path / "T.json", json.dumps({"T": 1})))


def test_extrinsics_yaml(tmp_path):
    pytest.importorskip("yaml", reason="PyYAML not installed")
    matrix = transform()
    text = "matrix:\n" + "".join(f"  - [{', '.join(map(repr, row))}]\n" for row in matrix.tolist())
    np.testing.assert_allclose(read_extrinsics(write(tmp_path / "T.yaml", text)), matrix, atol=1e-12)


# ---------------------------------------------------------------------------
# Frames
# ---------------------------------------------------------------------------


def test_frame_sizes_must_agree(tmp_path):
    cv2.imwrite(str(tmp_path / "c.png"), np.zeros((480, 640, 3), np.uint8))
    np.save(tmp_path / "d.npy", np.full((240, 320), 0.7))
    intr = write(tmp_path / "camera.json", json.dumps(PLAIN))
    with pytest.raises(InputError, match=r"d.npy is 320x240 but .*camera.json is 640x480"):
        read_rgbd(tmp_path / "c.png", tmp_path / "d.npy", intr)
    cv2.imwrite(str(tmp_path / "wide.png"), np.zeros((480, 800, 3), np.uint8))
    np.save(tmp_path / "d640.npy", np.full((480, 640), 0.7))
    with pytest.raises(InputError, match=r"wide.png: rgb image is 800x480 but the depth image is 640x480: not the same "
                                         r"view at another resolution .*camera.json gives no color_fx"):
        read_rgbd(tmp_path / "wide.png", tmp_path / "d640.npy", intr)
    with pytest.raises(InputError, match="needs an intrinsics file"):
        read_rgbd(None, tmp_path / "d.npy")
    frame = read_rgbd(tmp_path / "c.png", None, intr)
    assert frame.depth is None and frame.rgb.shape == (480, 640, 3) and frame.intrinsics == EXPECTED


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(content=st.binary(max_size=300), suffix=st.sampled_from([".png", ".npy", ".json", ".intr", ".tf", ".txt"]))
def test_garbage_files_raise_only_input_error(tmp_path, content, suffix):
    path = tmp_path / f"garbage{suffix}"
    path.write_bytes(content)
    readers = [read_rgb, read_depth, read_mask] if suffix in (".png", ".npy") else [read_intrinsics, read_extrinsics]
    for reader in readers:
        try:
            reader(path)
        except InputError:
            pass


def test_a_mask_of_another_size_names_both_files(tmp_path):
    cv2.imwrite(str(tmp_path / "color.png"), np.zeros((240, 320, 3), np.uint8))
    np.save(tmp_path / "depth.npy", np.full((480, 640), 0.7))
    cv2.imwrite(str(tmp_path / "mask.png"), np.full((240, 320), 255, np.uint8))
    intr = write(tmp_path / "camera.json", json.dumps(PLAIN))
    with pytest.raises(InputError, match=r"depth.npy is 640x480 but .*mask.png is 320x240"):
        read_rgbd(None, tmp_path / "depth.npy", intr, mask_path=tmp_path / "mask.png")
    with pytest.raises(InputError, match=r"depth.npy is 640x480 but .*mask.png is 320x240"):
        read_rgbd(tmp_path / "color.png", tmp_path / "depth.npy", intr, mask_path=tmp_path / "mask.png")
    half = read_rgbd(tmp_path / "color.png", tmp_path / "depth.npy", intr)  # colour at half the depth's resolution
    assert half.rgb.shape == (240, 320, 3) and half.depth.shape == (480, 640)
    assert read_rgbd(tmp_path / "color.png", mask_path=tmp_path / "mask.png").mask.shape == (240, 320)


def test_a_corrupt_png_is_one_error_and_nothing_on_stderr(tmp_path, capfd):
    good = tmp_path / "good.png"
    cv2.imwrite(str(good), np.full((40, 60, 3), 7, np.uint8))
    corrupt = tmp_path / "corrupt.png"
    corrupt.write_bytes(good.read_bytes()[:60] + b"\0" * 40 + good.read_bytes()[100:])
    for reader in (read_rgb, read_depth, read_mask):
        with pytest.raises(InputError, match=r"corrupt.png: not a readable image"):
            reader(corrupt)
    assert capfd.readouterr().err == ""
    assert read_rgb(good).shape == (40, 60, 3)


@pytest.mark.parametrize("suffix", [".json", ".yaml"])
def test_deeply_nested_camera_files_are_one_error(tmp_path, suffix):
    nested = "[" * 100_000 + "]" * 100_000
    path = write(tmp_path / f"deep{suffix}", nested)
    for reader in (read_intrinsics, read_extrinsics):
        with pytest.raises(InputError, match=rf"deep{suffix}: (nested too deeply|not valid)"):
            reader(path)


NUMBERS = st.one_of(st.floats(allow_nan=True, allow_infinity=True), st.integers(-10**30, 10**30),
                    st.sampled_from([1e-300, 1e300, -1e300, 0, True, "1", None]))
JSON_VALUES = st.recursive(NUMBERS | st.text(max_size=3), lambda inner: st.lists(inner, max_size=5)
                           | st.dictionaries(st.sampled_from(["fx", "fy", "cx", "cy", "width", "height", "K", "matrix",
                                                              "rotation", "translation", "_fx"]), inner, max_size=6),
                           max_leaves=30)


@settings(max_examples=80, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(fields=st.fixed_dictionaries({k: NUMBERS for k in PLAIN}) | JSON_VALUES, suffix=st.sampled_from([".json", ".yaml"]))
def test_random_camera_files_read_or_raise_input_error(tmp_path, fields, suffix):
    path = write(tmp_path / f"camera{suffix}", json.dumps(fields, allow_nan=True))
    for reader in (read_intrinsics, read_extrinsics):
        try:
            reader(path)
        except InputError:
            pass


@settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(shape=st.sampled_from([(0,), (5,), (4, 4), (3, 4, 2), (6, 5, 1), (2, 2, 3)]),
       dtype=st.sampled_from(["float64", "float32", "uint16", "uint8", "int64", "bool", "complex128"]),
       fill=st.sampled_from([0.7, np.nan, np.inf, 1e300, -1.0, 0.0]))
def test_random_frames_read_or_raise_input_error(tmp_path, shape, dtype, fill):
    with np.errstate(invalid="ignore", over="ignore"):
        array = np.full(shape, fill).astype(dtype)
    np.save(tmp_path / "a.npy", array)
    intr = write(tmp_path / "camera.json", json.dumps(PLAIN))
    for call in (lambda: read_rgbd(None, tmp_path / "a.npy", intr), lambda: read_rgbd(None, None, intr, mask_path=tmp_path / "a.npy")):
        try:
            call()
        except InputError:
            pass


# ---------------------------------------------------------------------------
# Real files (shared/data, beside the repository)
# ---------------------------------------------------------------------------

SHARED = Path(os.environ.get("CONTOURGRASP_SHARED_DATA", Path(__file__).resolve().parents[3] / "shared" / "data"))
SINGLE = SHARED / "rgbd" / "gqcnn_primesense_single_object"
BAR_CLAMP = SHARED / "rgbd" / "gqcnn_primesense_overhead_bar_clamp"
needs_data = pytest.mark.skipif(
    not SINGLE.is_dir(), reason=f"real RGB-D frames not found at {SINGLE} (set CONTOURGRASP_SHARED_DATA)"
)


@needs_data
def test_shared_frame_files():
    frame = read_rgbd(SINGLE / "color_0.png", SINGLE / "depth_0.npy", SINGLE / "primesense.intr")
    assert frame.intrinsics == Intrinsics(525.0, 525.0, 319.5, 239.5, 640, 480)
    assert frame.depth.shape == (480, 640) and 0.5 < np.median(frame.depth) < 0.8
    assert frame.rgb[240, 100, 1] > frame.rgb[240, 100, 2]  # the green mat, in RGB order
    assert read_mask(SINGLE / "segmask_0.png").sum() == 3829


@needs_data
def test_shared_tf_files_give_the_documented_optical_axes():
    axis = read_extrinsics(SINGLE / "primesense.tf")[:3, 2]
    np.testing.assert_allclose(axis, [0.220, 0.000, -0.976], atol=1e-3)
    axis = read_extrinsics(BAR_CLAMP / "primesense_overhead_to_world.tf")[:3, 2]
    np.testing.assert_allclose(axis, [0.049, -0.017, -0.999], atol=1e-3)


@needs_data
def test_shared_raw_depth_keeps_its_holes():
    depth = read_depth(BAR_CLAMP / "depth_0.npy")
    assert (depth == 0).sum() == 42637


def test_a_complex_npy_mask_or_depth_is_refused_not_cast(tmp_path):
    path = tmp_path / "depth.npy"
    np.save(path, np.full((4, 4), 0.5 + 1j))
    with pytest.raises(InputError, match="depth.npy: expected an array of real numbers, got dtype complex128"):
        read_depth(path)
    with pytest.raises(InputError, match="real numbers"):
        read_mask(path)
