"""The input polygon: checks that make it safe to model, self-intersections and their repair, growth.

:func:`clean_polygon` is the one gate every contour passes before it is
fitted (:func:`contourgrasp.contour.fit`), so that nothing after it meets a
NaN, an overflow, a crossing or a degenerate polygon. Its limits are in
:mod:`contourgrasp.tolerances` (``MIN_CONTOUR_SIZE``, ``MAX_CONTOUR_SIZE``,
``MAX_CONTOUR_POINTS``, ``POINT_MERGE``, ``MIN_AREA``).
"""

from __future__ import annotations

import math
import warnings

import numpy as np
import shapely

from .. import tolerances as tol
from .. import validation
from ..errors import ContourError, UnitWarning


def signed_area(points: np.ndarray) -> float:
    """Shoelace signed area of a closed polygon; positive for counter-clockwise with y up.

    Parameters
    ----------
    points : (n, 2) float
        Polygon vertices, not repeating the first point.

    Returns
    -------
    float
        In the square of the points' unit.

    Examples
    --------
    >>> signed_area(np.array([[0.0, 0.0], [1.0, 0.0], [0.0, 1.0]]))
    0.5
    """
    x, y = np.asarray(points, dtype=float).T
    return 0.5 * float(np.dot(x, np.roll(y, -1)) - np.dot(np.roll(x, -1), y))


def clean_polygon(points, *, check_units: bool = True) -> np.ndarray:
    """Check a closed polygon and return it ready for fitting.

    In order: the points must be an (n, 2) array of real, finite numbers; the
    polygon at most ``tolerances.MAX_CONTOUR_SIZE`` across. A repeated closing
    point and consecutive duplicates are dropped, and a polygon that is one
    loop traced several times (the same points again, from the same start)
    keeps one loop, so that its period is the loop's perimeter. At least three
    distinct points must remain, at least ``tolerances.MIN_CONTOUR_SIZE``
    across. A polygon of more than ``tolerances.MAX_CONTOUR_POINTS`` points is
    resampled uniformly by arc length to that many (finer detail than that is
    below any camera's resolution; it only slows the checks and the fit).
    Finally no edge may cross another (:func:`first_self_intersection`) and
    the polygon must enclose a non-zero area. With ``check_units``, a polygon
    larger than ``tolerances.MAX_PLAUSIBLE_SIZE`` gets a :class:`UnitWarning`
    (probably millimetres).

    Parameters
    ----------
    points : (n, 2) float
        Polygon vertices in meters, in either orientation.
    check_units : bool
        Warn about a polygon too large to be in meters.

    Returns
    -------
    (m, 2) float
        The cleaned vertices, orientation unchanged, ``m <= MAX_CONTOUR_POINTS``.

    Raises
    ------
    ContourError
        With a message that names what is wrong.

    Examples
    --------
    >>> clean_polygon([[0, 0], [0.1, 0], [0.1, 0], [0.1, 0.1], [0, 0]]).tolist()
    [[0.0, 0.0], [0.1, 0.0], [0.1, 0.1]]
    >>> clean_polygon([[0, 0], [1e-7, 0], [0, 1e-7]])
    Traceback (most recent call last):
    ...
    contourgrasp.errors.ContourError: the contour is 1e-07 m across: too small to model (at least 0.0001 m)
    """
    pts = _finite_points(points)
    size = _extent(pts)
    pts = _single_loop(_drop_duplicates(pts))
    if len(pts) < 3:
        raise ContourError(f"contour needs at least 3 distinct points, got {len(pts)}")
    if size < tol.MIN_CONTOUR_SIZE:
        raise ContourError(f"the contour is {size:.3g} m across: too small to model "
                           f"(at least {tol.MIN_CONTOUR_SIZE:g} m)")
    if len(pts) > tol.MAX_CONTOUR_POINTS:
        pts = _resample(pts, tol.MAX_CONTOUR_POINTS)
    crossing = first_self_intersection(pts)
    if crossing is not None:
        raise ContourError(f"contour is self-intersecting: edges {crossing[0]} and {crossing[1]} cross")
    area = signed_area(pts)
    if not math.isfinite(area):
        raise ContourError("contour area is not finite")
    if abs(area) < tol.MIN_AREA:
        raise ContourError("contour encloses no area (its points are collinear)")
    if check_units and size > tol.MAX_PLAUSIBLE_SIZE:
        warnings.warn(
            f"contour is {size:.3g} m across: an object that large is almost certainly "
            f"not in meters (millimetres? divide by 1000)",
            UnitWarning,
            stacklevel=2,
        )
    return pts


def grow_polygon(points, distance: float) -> np.ndarray:
    """The polygon grown by ``distance``: the outline of every point within ``distance`` of it.

    The Minkowski sum with a disc (shapely's round buffer, ``tolerances.GROWTH_ARC_SEGMENTS`` chords per
    quarter circle): convex corners become arcs of radius ``distance``, concave notches narrower than
    twice ``distance`` close. Where a ball of radius ``distance`` first touches the polygon, its centre
    lies on the grown outline, so a fingertip ball's centre path meets the grown outline where the ball
    meets the object (the small-object rule of :func:`contourgrasp.synthesis.search`).

    The buffer's cost grows much faster than the vertex count on a jagged outline (a 2,000-point star
    took 11 s, 10,000 points minutes), so a polygon of more than ``tolerances.MAX_GROWTH_POINTS`` is first
    resampled uniformly by arc length to that many: every point of it then lies within half a spacing of
    the resampled one (0.2 mm for a 20 cm outline), and a polygon within the bound is grown exactly.

    Parameters
    ----------
    points : (n, 2) float
        A simple polygon (as :func:`clean_polygon` returns it), in either orientation, meters.
    distance : float
        How far to grow it, m: at least 0, at most ``tolerances.MAX_SEARCH_LENGTH``.

    Returns
    -------
    (m, 2) float
        The grown polygon's vertices, its first not repeated, in the input's orientation.

    Raises
    ------
    ContourError
        Bad points or a distance that is not a number in range, naming it.

    Examples
    --------
    >>> square = np.array([[0.0, 0.0], [0.1, 0.0], [0.1, 0.1], [0.0, 0.1]])
    >>> grown = grow_polygon(square, 0.01)
    >>> round(float(np.ptp(grown[:, 0])), 6), signed_area(grown) > 0
    (0.12, True)
    """
    pts = _finite_points(points)
    distance = validation.bounded("distance", distance, tol.MAX_SEARCH_LENGTH, " m", error=ContourError)
    if distance == 0:
        return pts.copy()
    if len(pts) > tol.MAX_GROWTH_POINTS:
        pts = _resample(pts, tol.MAX_GROWTH_POINTS)
    grown = shapely.Polygon(pts).buffer(distance, quad_segs=tol.GROWTH_ARC_SEGMENTS)
    out = np.asarray(grown.exterior.coords, dtype=float)[:-1]
    return out if (signed_area(out) > 0) == (signed_area(pts) > 0) else out[::-1]


def first_self_intersection(points: np.ndarray) -> tuple[int, int] | None:
    """The first pair of non-adjacent edges of a closed polygon that cross, or None.

    Two edges cross when each one's end points lie strictly on opposite sides
    of the other, or when the polygon passes twice through one vertex and the
    second pass goes from one side of the first to the other (a figure-8 drawn
    through a sample point). Touching without crossing (an outline out and
    back along a one-pixel neck) is not a crossing.

    Parameters
    ----------
    points : (n, 2) float
        Polygon vertices, no consecutive duplicates; edge i runs from point i
        to point i+1 (mod n).

    Returns
    -------
    (int, int) or None
        Edges i < j, the first in order of i, then j. For a crossing at a
        vertex, edges i and j are the ones that start there.

    Examples
    --------
    >>> first_self_intersection(np.array([[0, 0], [1, 1], [1, 0], [0, 1]]))
    (0, 2)
    """
    p = np.ascontiguousarray(points, dtype=float)
    if len(p) < 4:
        return None
    unit, _ = _unit_size(p)
    eps = tol.COLLINEAR * float(np.max(np.ptp(unit, axis=0))) ** 2
    from ._kernels import first_crossing  # numba loads here, not when the package is imported

    i, j = first_crossing(unit, eps)
    found = [(int(i), int(j))] if i >= 0 else []
    found += [pair for pair in _shared_vertices(p) if _passes_cross(unit, *pair)]
    return min(found, default=None)


def repair_self_intersections(points) -> np.ndarray:
    """Remove the loops a polygon makes where it crosses itself, keeping the larger side each time.

    An outline traced along a pixel staircase (a segmentation mask's) can
    cross itself where it doubles back, making tiny loops. Repeatedly: take
    the first crossing edges i < j (:func:`first_self_intersection`), split the
    polygon at the crossing point into its two loops (points i+1..j and
    j+1..i), and keep the one enclosing the larger absolute area, the
    crossing point inserted as its first vertex. Each step removes at least
    one vertex, so it ends; the result has no crossing. A figure-8 keeps its
    larger lobe.

    This is for outlines the library traces itself; :func:`clean_polygon` does
    not call it: a contour the user gives that crosses itself is refused.

    Parameters
    ----------
    points : (n, 2) float
        Polygon vertices, either orientation, closed or not.

    Returns
    -------
    (m, 2) float
        ``m <= n`` vertices without self-intersection (fewer than 3 when nothing
        with an area is left, which :func:`clean_polygon` then refuses).

    Raises
    ------
    ContourError
        When ``points`` is not an (n, 2) array of finite numbers.

    Examples
    --------
    >>> eight = [[0, 0], [3, 3], [3, 0], [0, 1.5]]  # two triangles crossing at (1, 1)
    >>> repair_self_intersections(eight).tolist()
    [[1.0, 1.0], [3.0, 3.0], [3.0, 0.0]]
    """
    pts, factor = _unit_size(_finite_points(points))  # in units of its size: any magnitude works
    pts = _drop_duplicates(pts)
    crossing = first_self_intersection(pts)
    while crossing is not None:
        i, j = crossing
        x = _crossing_point(pts, i, j)
        inner = np.vstack([x, pts[i + 1:j + 1]])
        outer = np.vstack([x, pts[j + 1:], pts[:i + 1]])
        kept = inner if abs(signed_area(inner)) > abs(signed_area(outer)) else outer
        pts = _drop_duplicates(kept)
        crossing = first_self_intersection(pts)
    return pts / factor


def _finite_points(points) -> np.ndarray:
    """(n, 2) float of real, finite numbers, or a ContourError naming the first bad point."""
    pts = validation.float_array("contour", points, error=ContourError)
    if pts.ndim != 2 or pts.shape[1] != 2:
        raise ContourError(f"contour must be an (n, 2) array of x, y points, got shape {pts.shape}")
    if not np.all(np.isfinite(pts)):
        bad = int(np.flatnonzero(~np.all(np.isfinite(pts), axis=1))[0])
        raise ContourError(f"contour point {bad} is not finite (NaN or inf)")
    return pts


def _extent(pts: np.ndarray) -> float:
    """The larger side of the bounding box; refused above MAX_CONTOUR_SIZE before anything can overflow."""
    with np.errstate(over="ignore", invalid="ignore"):
        size = float(np.max(np.ptp(pts, axis=0))) if len(pts) else 0.0
    if not size <= tol.MAX_CONTOUR_SIZE:
        across = f"{size:.3g} m" if math.isfinite(size) else "more than 1e308 m"
        raise ContourError(f"the contour is {across} across: too large to model "
                           f"(at most {tol.MAX_CONTOUR_SIZE:g} m; is it in meters?)")
    return size


def _drop_duplicates(pts: np.ndarray) -> np.ndarray:
    """The vertices farther than POINT_MERGE from the next (the last compared with the first)."""
    step = np.linalg.norm(np.diff(pts, axis=0, append=pts[:1]), axis=1)
    return pts[step > tol.POINT_MERGE]


def _single_loop(pts: np.ndarray) -> np.ndarray:
    """One loop of a polygon that repeats the same loop (the same points from the same start) k times."""
    n = len(pts)
    if n < 2:
        return pts
    returns = np.flatnonzero(np.all(np.abs(pts[1:] - pts[0]) <= tol.POINT_MERGE, axis=1)) + 1
    for period in returns:
        if n % period == 0 and np.all(np.abs(pts.reshape(-1, period, 2) - pts[:period]) <= tol.POINT_MERGE):
            return pts[:period]
    return pts


def _resample(pts: np.ndarray, count: int) -> np.ndarray:
    """(count, 2) float: points evenly spaced by arc length along the closed polygon, from its first point."""
    closed = np.vstack([pts, pts[:1]])
    s = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(closed, axis=0), axis=1))])
    u = np.linspace(0.0, s[-1], count, endpoint=False)
    return np.c_[np.interp(u, s, closed[:, 0]), np.interp(u, s, closed[:, 1])]


def _unit_size(p: np.ndarray) -> tuple[np.ndarray, float]:
    """(p * factor, factor): p scaled by a power of two to a size in [0.5, 1).

    The scaling is exact, so every orientation test keeps its sign, and
    nothing overflows however large p is.
    """
    factor = 1.0
    with np.errstate(over="ignore", invalid="ignore"):
        if len(p) and not np.isfinite(np.ptp(p, axis=0)).all():
            factor = 2.0**-64
        size = float(np.max(np.ptp(p * factor, axis=0))) if len(p) else 0.0
    if 0 < size < math.inf:
        factor *= 2.0 ** min(max(-math.frexp(size)[1], -1000), 1000)
    return np.ascontiguousarray(p * factor), factor


def _shared_vertices(p: np.ndarray) -> list[tuple[int, int]]:
    """Pairs a < b of non-adjacent vertices in the same POINT_MERGE cell (one pair per next visit)."""
    with np.errstate(over="ignore", invalid="ignore"):
        key = np.round(p / tol.POINT_MERGE)
    key[~np.isfinite(key).all(axis=1)] = np.nan  # never equal: no cell for points beyond floats
    order = np.lexsort((key[:, 1], key[:, 0]))  # stable: a cell's vertices stay in index order
    same = np.flatnonzero(np.all(key[order[1:]] == key[order[:-1]], axis=1))
    n = len(p)
    pairs = [(int(order[k]), int(order[k + 1])) for k in same]
    return [(a, b) for a, b in pairs if b - a not in (1, n - 1)]


def _passes_cross(p: np.ndarray, a: int, b: int) -> bool:
    """The pass through vertex b goes from one side of the pass through vertex a (the same point) to the other.

    The first pass's two edges split the plane around the point into two
    wedges; the second crosses when its edges lie strictly in different ones.
    A second edge along a first one (touching, overlapping) is no crossing.
    """
    n, full = len(p), 2 * math.pi

    def direction(k: int) -> float:
        dx, dy = p[k % n] - p[a]
        return math.atan2(dy, dx)

    first_out = direction(a + 1)
    wedge, inward, outward = ((direction(k) - first_out) % full for k in (a - 1, b - 1, b + 1))
    if _near(wedge, 0.0, full) or _near(inward, 0.0, wedge, full) or _near(outward, 0.0, wedge, full):
        return False
    return (inward < wedge) != (outward < wedge)


def _near(angle: float, *others: float) -> bool:
    return any(abs(angle - other) < tol.SAME_DIRECTION for other in others)


def _crossing_point(p: np.ndarray, i: int, j: int) -> np.ndarray:
    """(2,) float: where edges i and j of the closed polygon p cross (at a vertex crossing, about their shared start)."""
    n = len(p)
    a, d1 = p[i], p[(i + 1) % n] - p[i]
    c, d2 = p[j], p[(j + 1) % n] - p[j]
    denominator = d1[0] * d2[1] - d1[1] * d2[0]
    if denominator == 0:  # parallel edges cross only at a shared vertex
        return a.copy()
    s = ((c[0] - a[0]) * d2[1] - (c[1] - a[1]) * d2[0]) / denominator
    return a + min(max(s, 0.0), 1.0) * d1
