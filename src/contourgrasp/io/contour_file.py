"""Contour files: CSV (x,y in meters, header optional) or .npy ((n, 2) float), and the built-in examples.

A file's points are checked as a contour (:func:`contourgrasp.contour.clean_polygon`)
as they are read, so that every error names the file.
"""

from __future__ import annotations

import csv
from importlib import resources
from pathlib import Path

import numpy as np

from ..errors import ContourError, InputError

_EXAMPLE_DIR = "data/contours"


def read_contour(path) -> np.ndarray:
    """Read a contour file.

    Parameters
    ----------
    path : str or Path
        ``.npy`` holding an (n, 2) array, or a text file of two comma (or
        whitespace) separated columns x, y in meters; a first line that is not
        numeric is taken as a header.

    Returns
    -------
    (n, 2) float
        Points as read, checked by :func:`contourgrasp.contour.clean_polygon`
        (which planning applies again: it drops duplicates and resamples
        contours of more than ``tolerances.MAX_CONTOUR_POINTS`` points).

    Raises
    ------
    InputError
        Missing or unreadable file, wrong shape, a non-numeric or complex
        value (named by line).
    ContourError
        Points that are no usable contour; the message starts with the file name.
    """
    path = Path(path)
    if not path.is_file():
        raise InputError(f"{path}: contour file not found")
    points = _read_npy(path) if path.suffix.lower() == ".npy" else _read_text(path)
    if points.ndim != 2 or points.shape[1] != 2:
        raise InputError(f"{path}: expected two columns x, y (an (n, 2) array), got shape {points.shape}")
    try:
        from ..contour import clean_polygon

        clean_polygon(points, check_units=False)
    except ContourError as err:
        raise ContourError(f"{path}: {err}") from None
    return points


def _read_npy(path: Path) -> np.ndarray:
    """The (n, 2) float array of a .npy file; memory-mapped first, so that a header promising more data
    than the file holds is refused without allocating it."""
    try:
        array = np.load(path, mmap_mode="r", allow_pickle=False)
    except (OSError, ValueError, EOFError, SyntaxError, TypeError, OverflowError, MemoryError) as err:
        raise InputError(f"{path}: not a readable .npy array ({err or type(err).__name__})") from None
    if not isinstance(array, np.ndarray):
        raise InputError(f"{path}: not a readable .npy array")
    if array.dtype.kind == "c":
        raise InputError(f"{path}: array of complex numbers, expected real x, y")
    if array.dtype.kind not in "iuf":
        raise InputError(f"{path}: array of {array.dtype}, expected numbers")
    return np.array(array, dtype=float)


def _read_text(path: Path) -> np.ndarray:
    try:
        text = path.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as err:
        raise InputError(f"{path}: cannot read contour file ({err})") from None
    lines = [ln for ln in text.splitlines() if ln.strip()]
    fast = _parse_plain(lines)
    if fast is not None:
        return fast
    rows = []
    for number, line in enumerate(lines, start=1):
        try:
            fields = next(csv.reader([line])) if "," in line else line.split()
        except csv.Error as err:
            raise InputError(f"{path}: line {number}: {err}") from None
        try:
            rows.append([float(v) for v in fields])
        except ValueError:
            if number == 1:
                continue  # header
            raise InputError(f"{path}: line {number}: not numbers: {line.strip()!r}") from None
        if len(fields) != 2:
            raise InputError(f"{path}: line {number}: expected 2 columns x, y, got {len(fields)}")
    if not rows:
        raise InputError(f"{path}: no contour points")
    return np.array(rows, dtype=float)


def _parse_plain(lines: list[str]) -> np.ndarray | None:
    """The common file (one delimiter throughout, plain numbers, two columns) parsed at C speed, the header
    line dropped; None when it is not that plain, for the line-by-line parser to read or to name the bad line."""
    commas = sum("," in line for line in lines)
    if not lines or 0 < commas < len(lines):
        return None
    delimiter = "," if commas else None
    for body in (lines, lines[1:]):
        if not body:
            return None
        try:
            points = np.loadtxt(body, delimiter=delimiter, comments=None, dtype=float, ndmin=2, encoding=None)
        except ValueError:
            continue
        return points if points.ndim == 2 and points.shape[1] == 2 and len(points) else None
    return None


def example_names() -> list[str]:
    """Names of the built-in example contours."""
    folder = resources.files("contourgrasp").joinpath(_EXAMPLE_DIR)
    return sorted(p.name.removesuffix(".csv") for p in folder.iterdir() if p.name.endswith(".csv"))


def example_contour(name: str) -> np.ndarray:
    """(n, 2) float: a built-in example contour in meters (see ``example_names()``).

    Examples
    --------
    >>> example_contour("can").shape
    (200, 2)
    """
    if name not in example_names():
        raise InputError(f"unknown example contour {name!r}; choose from {', '.join(example_names())}")
    with resources.as_file(resources.files("contourgrasp").joinpath(f"{_EXAMPLE_DIR}/{name}.csv")) as path:
        return read_contour(path)
