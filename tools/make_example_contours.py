"""Regenerate the built-in example contours in src/contourgrasp/data/contours/.

The contours are data (CSV, meters, image-plane x right / y down, centred near
the origin); this script documents how they were made. Run it from the
repository root: ``python tools/make_example_contours.py``.
"""

import argparse
from pathlib import Path

import numpy as np

OUT = Path(__file__).resolve().parents[1] / "src" / "contourgrasp" / "data" / "contours"
POINTS = 200


def resample(poly: np.ndarray, n: int = POINTS) -> np.ndarray:
    """n points evenly spaced by arc length along a closed polygon."""
    closed = np.vstack([poly, poly[:1]])
    s = np.concatenate([[0], np.cumsum(np.linalg.norm(np.diff(closed, axis=0), axis=1))])
    u = np.linspace(0, s[-1], n, endpoint=False)
    return np.c_[np.interp(u, s, closed[:, 0]), np.interp(u, s, closed[:, 1])]


def rounded_rectangle(width: float, height: float, radius: float) -> np.ndarray:
    arc = np.linspace(0, np.pi / 2, 50)
    corners = [(width / 2 - radius, height / 2 - radius, 0.0), (-width / 2 + radius, height / 2 - radius, np.pi / 2),
               (-width / 2 + radius, -height / 2 + radius, np.pi), (width / 2 - radius, -height / 2 + radius, 1.5 * np.pi)]
    pts = [np.c_[cx + radius * np.cos(a0 + arc), cy + radius * np.sin(a0 + arc)] for cx, cy, a0 in corners]
    return np.vstack(pts)


def profile(xs: np.ndarray, half_width: np.ndarray) -> np.ndarray:
    """A mirror-symmetric outline from its half width along x."""
    top = np.c_[xs, half_width]
    bottom = np.c_[xs[::-1], -half_width[::-1]]
    return np.vstack([top, bottom])


def bottle() -> np.ndarray:
    """A 0.5 l water bottle lying down, seen from above: body 0.065 wide, 0.205 long with the cap."""
    xs = np.linspace(0, 0.205, 400)
    body, shoulder_end, neck_end = 0.145, 0.180, 0.190
    half = np.where(xs < body, 0.0325, 0.0)
    taper = (xs >= body) & (xs < shoulder_end)
    u = (xs[taper] - body) / (shoulder_end - body)
    half[taper] = 0.014 + (0.0325 - 0.014) * 0.5 * (1 + np.cos(np.pi * u))
    half[(xs >= shoulder_end) & (xs < neck_end)] = 0.014
    half[xs >= neck_end] = 0.016
    half[0], half[-1] = 0.03, 0.0155  # rounded base edge and cap edge
    outline = profile(xs, half)
    return outline - [0.1025, 0.0]


def polar(radius_of_angle, n: int = 720) -> np.ndarray:
    theta = np.linspace(0, 2 * np.pi, n, endpoint=False)
    r = radius_of_angle(theta)
    return np.c_[r * np.cos(theta), r * np.sin(theta)]


def stone1() -> np.ndarray:
    """Large simple stone (~0.12 m): a lumpy oval with one long, slightly hollow flank."""
    def r(th):
        return 0.052 * (1 + 0.16 * np.cos(2 * th) + 0.05 * np.cos(3 * th + 0.7) + 0.03 * np.sin(th)
                        - 0.10 * np.exp(-((np.angle(np.exp(1j * (th - 1.5 * np.pi)))) / 0.45) ** 2))
    return polar(r)


def stone2() -> np.ndarray:
    """Smaller stone (~0.08 m) with a more complex outline: several small concavities."""
    def r(th):
        return 0.036 * (1 + 0.12 * np.cos(2 * th + 0.3) + 0.08 * np.sin(3 * th) + 0.06 * np.cos(5 * th + 1.0)
                        + 0.04 * np.sin(7 * th + 0.4))
    return polar(r)


SHAPES = {
    "can": lambda: rounded_rectangle(0.12, 0.066, 0.006),
    "case": lambda: rounded_rectangle(0.16, 0.06, 0.02),
    "bottle": bottle,
    "ellipse": lambda: polar(lambda th: 1 / np.sqrt((np.cos(th) / 0.05) ** 2 + (np.sin(th) / 0.03) ** 2)),
    "peanut": lambda: polar(lambda th: 0.045 * (1 + 0.35 * np.cos(2 * th))),
    "stone1": stone1,
    "stone2": stone2,
}


def main() -> None:
    argparse.ArgumentParser(description=__doc__.splitlines()[0]).parse_args()
    OUT.mkdir(parents=True, exist_ok=True)
    for name, make in SHAPES.items():
        pts = resample(make())
        header = "x,y"
        np.savetxt(OUT / f"{name}.csv", pts, delimiter=",", fmt="%.6f", header=header, comments="")
        size = np.ptp(pts, axis=0)
        print(f"{name:8s} {len(pts)} points, {size[0]:.3f} x {size[1]:.3f} m")


if __name__ == "__main__":
    main()
