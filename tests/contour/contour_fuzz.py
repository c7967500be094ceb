"""Hypothesis strategies for the contour fuzz tests: polygons of absurd scales, bad values and bad types."""

import numpy as np
from hypothesis import strategies as st


@st.composite
def polygons(draw):
    """Mostly star-shaped polygons (often valid) at scales 1e-300..1e300, with NaN, inf, duplicates and odd dtypes."""
    n = draw(st.integers(0, 60))
    rng = np.random.default_rng(draw(st.integers(0, 2**32 - 1)))
    shape = draw(st.sampled_from(["star", "star", "random", "line", "twice"]))
    theta = np.sort(rng.uniform(0, 2 * np.pi, n))
    if shape == "random":
        points = rng.uniform(-1, 1, (n, 2))
    elif shape == "line":
        points = np.c_[theta, 2 * theta]
    else:
        points = np.c_[np.cos(theta), np.sin(theta)] * rng.uniform(0.3, 1.0, (n, 1))
        if shape == "twice":
            points = np.vstack([points, points])
    exponent = draw(st.one_of(st.sampled_from([-7, -4, -3, -2, -1, -1, -1, 0, 1, 3, 4, 155, 200, 307]),
                              st.floats(-300, 300)))
    with np.errstate(over="ignore"):
        points = points * 10.0**exponent + draw(st.sampled_from([0.0, 0.0, 1.0, -1e6, 1e300]))
    if n and draw(st.booleans()):
        points[rng.integers(n)] = points[rng.integers(n)]  # a duplicate, adjacent or not
    if n and draw(st.integers(0, 5)) == 0:
        points[rng.integers(n), rng.integers(2)] = draw(st.sampled_from([np.nan, np.inf, -np.inf]))
    kind = draw(st.sampled_from(["float"] * 6 + ["complex", "object", "list", "float32", "int"]))
    if kind == "complex":
        return points + 1j
    if kind == "object":
        return points.astype(object)
    if kind == "list":
        return points.tolist()
    with np.errstate(all="ignore"):
        return points.astype(np.float32 if kind == "float32" else np.int64 if kind == "int" and np.isfinite(
            points).all() and np.abs(points).max(initial=0) < 2**62 else float)


def wrong_types():
    """Things that are no polygon at all."""
    return st.one_of(st.none(), st.text(max_size=5), st.integers(), st.floats(),
                     st.dictionaries(st.text(max_size=2), st.integers(), max_size=2),
                     st.lists(st.text(max_size=2), max_size=4),
                     st.lists(st.lists(st.floats(), max_size=3), max_size=4))
