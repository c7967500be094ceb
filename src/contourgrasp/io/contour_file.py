"""Contour files: CSV (x,y in meters, header optional) or .npy ((n, 2) float), and the built-in examples."""

from __future__ import annotations

import csv
from importlib import resources
from pathlib import Path

import numpy as np

from ..errors import InputError

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
        Points as read; :func:`contourgrasp.efd.clean_polygon` checks them.

    Raises
    ------
    InputError
        Missing or unreadable file, wrong shape, or a non-numeric value (named by line).
    """
    path = Path(path)
    if not path.is_file():
        raise InputError(f"{path}: contour file not found")
    if path.suffix.lower() == ".npy":
        try:
            points = np.load(path, allow_pickle=False)
        except (OSError, ValueError) as err:
            raise InputError(f"{path}: not a readable .npy array ({err})") from None
        if not np.issubdtype(points.dtype, np.number):
            raise InputError(f"{path}: array of {points.dtype}, expected numbers")
    else:
        points = _read_text(path)
    points = np.asarray(points, dtype=float)
    if points.ndim != 2 or points.shape[1] != 2:
        raise InputError(f"{path}: expected two columns x, y (an (n, 2) array), got shape {points.shape}")
    return points


def _read_text(path: Path) -> np.ndarray:
    try:
        text = path.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as err:
        raise InputError(f"{path}: cannot read contour file ({err})") from None
    rows = []
    lines = [ln for ln in text.splitlines() if ln.strip()]
    for number, line in enumerate(lines, start=1):
        fields = next(csv.reader([line])) if "," in line else line.split()
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
    return np.array(rows)


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
