import numpy as np
import pytest

from contourgrasp import InputError, example_contour, example_names, read_contour


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
