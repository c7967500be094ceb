import io
import re
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from contourgrasp import ContourError, InputError, contour, example_contour, example_names, read_contour


def test_examples_are_bundled():
    assert example_names() == ["bottle", "can", "case", "ellipse", "peanut", "stone1", "stone2"]
    can = example_contour("can")
    np.testing.assert_allclose(np.ptp(can, axis=0), [0.12, 0.066], atol=1e-3)


def test_csv_with_and_without_header_and_npy(tmp_path):
    points = example_contour("stone1")
    np.savetxt(tmp_path / "a.csv", points, delimiter=",", header="x,y", comments="")
    np.savetxt(tmp_path / "b.csv", points, delimiter=",")
    np.savetxt(tmp_path / "c.txt", points)
    np.save(tmp_path / "d.npy", points)
    for name in ["a.csv", "b.csv", "c.txt", "d.npy"]:
        np.testing.assert_allclose(read_contour(tmp_path / name), points, atol=1e-12)


@pytest.mark.parametrize(
    "content, message",
    [
        ("x,y\n0,0\n1,oops\n", "line 3: not numbers"),
        ("0,0,0\n1,1,1\n", "line 1: expected 2 columns"),
        ("x,y\n", "no contour points"),
    ],
)
def test_bad_csv(tmp_path, content, message):
    path = tmp_path / "bad.csv"
    path.write_text(content)
    with pytest.raises(InputError, match=message):
        read_contour(path)


def test_bad_npy_and_missing(tmp_path):
    np.save(tmp_path / "bad.npy", np.zeros((4, 3)))
    with pytest.raises(InputError, match=r"shape \(4, 3\)"):
        read_contour(tmp_path / "bad.npy")
    (tmp_path / "junk.npy").write_bytes(b"not numpy")
    with pytest.raises(InputError, match="not a readable .npy"):
        read_contour(tmp_path / "junk.npy")
    with pytest.raises(InputError, match="not found"):
        read_contour(tmp_path / "missing.csv")
    with pytest.raises(InputError, match="unknown example"):
        example_contour("banana")


# --- malformed files ------------------------------------------------------------------------

def test_an_empty_npy_is_an_input_error(tmp_path):
    (tmp_path / "empty.npy").write_bytes(b"")
    with pytest.raises(InputError, match="empty.npy: not a readable .npy array"):
        read_contour(tmp_path / "empty.npy")


def test_a_complex_npy_is_refused_not_cut_to_its_real_part(tmp_path):
    np.save(tmp_path / "c.npy", example_contour("can") + 0.01j)
    with pytest.raises(InputError, match="c.npy: array of complex numbers"):
        read_contour(tmp_path / "c.npy")


def test_an_npy_header_promising_more_than_the_file_holds_is_refused(tmp_path):
    path = tmp_path / "short.npy"
    header = io.BytesIO()
    np.lib.format.write_array_header_1_0(header, {"descr": "<f8", "fortran_order": False, "shape": (10**11, 2)})
    path.write_bytes(header.getvalue() + bytes(160))  # 1.6 TB promised, 160 bytes held: not allocated
    with pytest.raises(InputError, match="short.npy: not a readable .npy array"):
        read_contour(path)


@pytest.mark.parametrize("content", ["x,y\n0,0\n0.1,0\n\0,1\n", "0,0\n0.1,0\n0.1,\0\n"])
def test_nul_bytes_in_a_csv_are_an_input_error(tmp_path, content):
    path = tmp_path / "nul.csv"
    path.write_text(content)
    with pytest.raises(InputError, match="nul.csv"):
        read_contour(path)


@pytest.mark.parametrize("rows, message", [
    (["0,0", "0.1,0", "0.1,0.1", "nan,0.1"], "outline.csv: contour point 3 is not finite"),
    (["0,0", "0.1,0.1", "0.1,0", "0,0.1"], "outline.csv: contour is self-intersecting: edges 0 and 2 cross"),
    (["0,0", "1e-8,0", "0,1e-8"], "outline.csv: the contour is 1e-08 m across: too small"),
    (["0,0", "1e200,0", "0,1e200"], "outline.csv: the contour is 1e+200 m across: too large"),
    (["0,0", "0.1,0"], "outline.csv: contour needs at least 3 distinct points"),
])
def test_geometry_errors_name_the_file(tmp_path, monkeypatch, rows, message):
    monkeypatch.chdir(tmp_path)
    Path("outline.csv").write_text("x,y\n" + "\n".join(rows) + "\n")
    with pytest.raises(ContourError, match="^" + re.escape(message)):
        read_contour("outline.csv")


def test_a_contour_traced_twice_reads_and_fits_as_once(tmp_path):
    once = example_contour("stone1")
    np.savetxt(tmp_path / "twice.csv", np.vstack([once, once[:1], once]), delimiter=",")
    twice = read_contour(tmp_path / "twice.csv")
    np.testing.assert_array_equal(contour.fit(twice).coefficients, contour.fit(once).coefficients)


# --- fuzz ---------------------------------------------------------------------------------------------

NPY_MAGIC = b"\x93NUMPY\x01\x00"


@settings(max_examples=100, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(st.one_of(st.binary(max_size=300),
                 st.binary(max_size=200).map(lambda b: NPY_MAGIC + b),
                 st.text(alphabet="0123456789.,-+einfa x\n\r\t#", max_size=300).map(str.encode),
                 st.text(max_size=100).map(lambda s: s.encode("utf-16"))),
       st.sampled_from([".csv", ".npy", ".txt"]))
def test_random_bytes_are_a_contour_or_an_input_error(tmp_path, data, suffix):
    path = tmp_path / f"fuzz{suffix}"
    path.write_bytes(data)
    try:
        points = read_contour(path)
    except InputError as err:
        assert str(err).startswith(str(path))
        return
    assert points.ndim == 2 and points.shape[1] == 2 and np.isfinite(points).all()


@settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.function_scoped_fixture])
@given(st.sampled_from(["<f8", ">f4", "<i2", "|u1", "|b1", "<c16", "<M8[s]", "<m8[s]", "<U3", "|V8"]),
       st.sampled_from([(5, 2), (0, 2), (3,), (2, 2, 2), ()]), st.booleans())
def test_any_npy_array_is_a_contour_or_an_input_error(tmp_path, dtype, shape, fortran):
    array = np.ones(shape, dtype=dtype)
    np.save(tmp_path / "a.npy", np.asfortranarray(array) if fortran else array)
    try:
        read_contour(tmp_path / "a.npy")
    except InputError as err:
        assert "a.npy" in str(err)
