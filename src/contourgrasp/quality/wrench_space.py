"""Grasp quality: 2-D force closure and the Ferrari-Canny epsilon metric.

The thesis traces the failures on the glasses case to "all grasping points
laying on the same surface" (chapter 5, failure 2) and proposes a force-closure
test (section 6.1, item 2). This module provides it, together with the epsilon
metric of Ferrari & Canny (1992, "Planning optimal grasps", ICRA), which also
says how far a grasp is from losing closure, and the squeeze's imbalance
(:func:`imbalance`): the net force left when every contact pushes equally hard,
which an underactuated hand cannot correct. Everything here is a pure function
of numpy arrays; the planner decides how to use the numbers.

Conventions
-----------
Contacts
    Point contacts with Coulomb friction mu, in the plane. Contact i sits at
    p_i with unit normal n_i pointing *into* the object (normals of any
    positive length are normalised; zero ones are refused) and tangent t_i, n_i
    rotated by +90 deg. In 2-D a friction cone has exactly two edges, so it is
    represented exactly, not approximated::

        f_i+ = n_i + mu t_i,    f_i- = n_i - mu t_i

    Edges are scaled to a *unit normal component*, not to unit length: an edge
    is the largest friction force that goes with a unit normal force. Then the
    cone edges for a smaller mu are convex combinations of those for a larger
    one, so epsilon never decreases as mu grows (unit-length edges would
    shrink instead).
Wrenches
    w = (f_x, f_y, tau / rho) with tau = (p - c) x f, the z component of the
    torque about a reference point c, and rho a characteristic length that
    makes the torque commensurate with the force. Defaults: c = ``centre`` =
    the centroid of the contacts, rho = the largest distance of a contact from
    c (1 when all contacts are at c). Force closure does not depend on c or rho
    (changing them maps wrench space linearly and invertibly), epsilon does: to
    compare grasps on one object pass the same ``centre`` and ``rho`` to every
    call, e.g. the object's centroid and its largest radius about it.
Metrics
    ``"L1"``: the grasp wrench space is the convex hull of the 2n edge wrenches,
    the wrenches the grasp can exert with a *sum* of normal forces <= 1
    (Ferrari & Canny's Q_1). ``"Linf"``: the Minkowski sum over contacts of
    conv{0, w_i+, w_i-}, the wrenches with *each* normal force <= 1. Ferrari &
    Canny sum the edges alone; we include the zero force so that a contact may
    push less than another: without it two antipodal contacts would always
    cancel their normal forces and span a flat set. Both metrics agree on force
    closure and eps_L1 <= eps_Linf <= n eps_L1.
Friction
    mu is at most :data:`tolerances.MAX_FRICTION` (10): no real pair of materials comes near,
    and far beyond it the cone edges swamp the normals until the wrench hull cannot be built.

    epsilon is the radius of the largest origin-centred ball inside the grasp
    wrench space: the smallest distance of the origin to a facet's plane when
    the origin is strictly inside, else 0. The grasp is in force closure iff
    epsilon > 0. Values at or below :data:`tolerances.WRENCH_ZERO` are
    reported as 0, and so are degenerate wrench sets (fewer than four affinely
    independent wrenches: one contact, or frictionless contacts whose normal
    lines meet in one point, e.g. any frictionless grasp of a disc) -- never an
    exception.

With two contacts this reduces to Nguyen's test (1988): closure iff the
segment joining the contacts lies strictly inside both friction cones, i.e.
makes an angle below atan(mu) with both normals.
"""

from __future__ import annotations

import functools
import itertools
from dataclasses import dataclass

import numpy as np

from .. import tolerances as tol
from .. import validation as check
from ._kernels import ball_radii
from ..contour import EFD, evaluate
from ..errors import QualityError

METRICS: tuple[str, ...] = ("L1", "Linf")


@dataclass(frozen=True)
class GraspQuality:
    """Quality of one grasp (Ferrari & Canny 1992; thesis 6.1 item 2).

    Attributes
    ----------
    force_closure : bool
        The grasp can resist any wrench (origin strictly inside the grasp wrench space).
    epsilon : float
        Ferrari-Canny epsilon in units of unit normal force; 0 without closure.
    metric : {"L1", "Linf"}
    mu : float
        Friction coefficient used.
    imbalance : float
        :func:`imbalance` of the contacts: 0 when equal pushes cancel, 1 when all push one way.
    """

    force_closure: bool
    epsilon: float
    metric: str
    mu: float
    imbalance: float


# --------------------------------------------------------------------- public


def contact_wrenches(points, normals, *, mu: float = 0.5, centre=None, rho=None) -> np.ndarray:
    """Wrenches of the friction-cone edges of planar point contacts.

    Parameters
    ----------
    points : (n, 2) float
        Contact points, meters.
    normals : (n, 2) float
        Normals pointing into the object; normalised here.
    mu : float
        Coulomb friction coefficient, >= 0.
    centre : (2,) float, optional
        Point the torques are taken about; default the contacts' centroid.
    rho : float, optional
        Characteristic length dividing the torque; default the largest
        distance of a contact from ``centre``.

    Returns
    -------
    (2n, 3) float
        Rows (f_x, f_y, tau / rho) in the order f_0+, f_0-, f_1+, ..., each
        edge n_i +/- mu t_i scaled to a unit normal component (module docstring).

    Raises
    ------
    QualityError
        Naming the argument that is malformed, or when the contacts lie so far from ``centre``
        (or ``rho`` is so small) that their torques overflow.
    """
    p, n = _check_contacts(points, normals)
    mu = _check_mu(mu)
    c, r = _frame(p[None], np.ones((1, len(p)), bool), centre, rho)
    return _edge_wrenches(p[None], n[None], mu, c, r)[0]


def epsilon(points, normals, *, mu: float = 0.5, centre=None, rho=None, metric: str = "L1") -> float:
    """Ferrari-Canny epsilon of one grasp: the largest origin-centred ball in its wrench space.

    Parameters are those of :func:`contact_wrenches`, plus

    metric : {"L1", "Linf"}
        ``"L1"`` bounds the sum of the normal forces, ``"Linf"`` each of them
        (module docstring; Ferrari & Canny 1992). ``"Linf"`` takes at most
        :data:`tolerances.LINF_MAX_CONTACTS` contacts.

    Returns
    -------
    float
        >= 0; 0 exactly when the grasp is not in force closure (thesis 6.1
        item 2, chapter 5 failure 2: contacts all on one surface give 0).

    Examples
    --------
    Two antipodal contacts on a box, torques about their midpoint:

    >>> round(epsilon([[-0.03, 0], [0.03, 0]], [[1, 0], [-1, 0]], mu=0.5), 6)
    0.333333
    """
    metric = _check_metric(metric)
    w = contact_wrenches(points, normals, mu=mu, centre=centre, rho=rho)
    if metric == "Linf":
        _check_linf_size(len(w) // 2)
        w = _minkowski_sum(w.reshape(-1, 2, 3))
    return _ball_radius(w)


def force_closure(points, normals, *, mu: float = 0.5, centre=None, rho=None) -> bool:
    """Whether the grasp is in 2-D force closure: its L1 epsilon is positive.

    Parameters are those of :func:`contact_wrenches`; ``centre`` and ``rho``
    do not change the answer except within :data:`tolerances.WRENCH_ZERO` of
    the boundary.
    """
    return epsilon(points, normals, mu=mu, centre=centre, rho=rho) > 0.0


def grasp_quality(
    points, normals, *, mu: float = 0.5, centre=None, rho=None, metric: str = "L1"
) -> GraspQuality:
    """Force closure and epsilon of one grasp, as a :class:`GraspQuality`.

    Parameters are those of :func:`epsilon`.
    """
    eps = epsilon(points, normals, mu=mu, centre=centre, rho=rho, metric=metric)
    share = float(imbalance(np.asarray(normals, dtype=float)[None])[0])
    return GraspQuality(force_closure=eps > 0.0, epsilon=eps, metric=metric, mu=float(mu), imbalance=share)


def imbalance(normals, valid=None) -> np.ndarray:
    """The squeeze's net force when every contact pushes with the same force, as a share of their sum.

    An underactuated hand cannot choose its contact forces: one tendon drives every finger, and
    each finger that touches presses along the surface's normal. Our reading is that they press
    equally hard, which needs nothing the hand file does not give. The net force
    ``|sum_i n_i| / k`` over the k contacts must then be carried by friction, or the object
    squirts out of the closing hand. Force closure says the contacts *could* balance any force
    with well-chosen forces; this says whether the forces the hand applies balance.

    Parameters
    ----------
    normals : (p, n, 2) float
        Inward normals of p grasps with up to n contacts each (any positive length).
    valid : (p, n) bool, optional
        Which contacts exist; invalid entries may hold anything. Default all.

    Returns
    -------
    (p,) float
        In [0, 1]: 0 when the pushes cancel, 1 when every contact pushes the same way; 1 for a
        grasp without contacts.

    Examples
    --------
    Opposite contacts cancel; a thumb against four fingers spread over 120 deg does not:

    >>> import numpy as np
    >>> float(imbalance([[[1.0, 0.0], [-1.0, 0.0]]])[0])
    0.0
    >>> fingers = [[np.cos(a), np.sin(a)] for a in np.radians([-60, -20, 20, 60])]
    >>> round(float(imbalance([[[-1.0, 0.0], *fingers]])[0]), 3)
    0.376
    """
    n, ok = _check_normal_batch(normals, valid)
    count = ok.sum(axis=1)
    net = np.linalg.norm(np.where(ok[..., None], n, 0.0).sum(axis=1), axis=1)
    with np.errstate(invalid="ignore", divide="ignore"):
        return np.where(count > 0, net / np.maximum(count, 1), 1.0)


def epsilon_many(
    points, normals, valid=None, *, mu: float = 0.5, centre=None, rho=None, metric: str = "L1"
) -> np.ndarray:
    """Epsilon of many grasps at once, e.g. the candidate poses of one plan.

    Parameters
    ----------
    points : (p, n, 2) float
        Contact points of p grasps with up to n contacts each.
    normals : (p, n, 2) float
        Inward normals at those points.
    valid : (p, n) bool, optional
        Which contacts exist (a finger that misses the object has none);
        invalid entries may hold anything, NaN included. Default all.
    mu : float
    centre : (2,) or (p, 2) float, optional
        Torque reference per grasp; default each grasp's contact centroid.
    rho : float or (p,) float, optional
        Characteristic length per grasp; default each grasp's own (see
        :func:`contact_wrenches`). Pass one value to make the grasps comparable.
    metric : {"L1", "Linf"}

    Returns
    -------
    (p,) float
        ``epsilon_many(...)[k]`` equals :func:`epsilon` of grasp k's valid
        contacts to within rounding; empty for no grasps (p = 0). The L1 metric
        is vectorised over grasps (every plane through three wrenches is tested
        as a supporting plane); ``"Linf"`` loops over grasps with Qhull.

    Raises
    ------
    QualityError
        As :func:`contact_wrenches`.
    """
    metric = _check_metric(metric)
    mu = _check_mu(mu)
    p, n, ok = _check_contact_batch(points, normals, valid)
    c, r = _frame(p, ok, centre, rho)
    w = _edge_wrenches(p, n, mu, c, r)
    if metric == "L1":
        return _ball_radius_batch(w, np.repeat(ok, 2, axis=1))
    _check_linf_size(int(ok.sum(axis=1).max(initial=0)))
    pairs = w.reshape(len(w), w.shape[1] // 2, 2, 3)
    return np.array([_ball_radius(_minkowski_sum(pairs[k][ok[k]])) for k in range(len(w))])


def contour_normals(model: EFD, t) -> np.ndarray:
    """Inward unit normals of an EFD contour at parameters t.

    Parameters
    ----------
    model : EFD
        A model from :func:`contourgrasp.contour.fit`.
    t : (...) float
        Curve parameters (arc length, meters).

    Returns
    -------
    (..., 2) float
        Unit normals pointing into the object; NaN where the curve's tangent
        vanishes (a cusp of a truncated series), which the quality functions refuse.
    """
    t = np.asarray(t, dtype=float)
    tangent = evaluate(model, t.ravel(), derivative=1)
    # fit() orients every model with positive signed area (counter-clockwise
    # with y up), so the interior lies to the left: rotate the tangent by +90 deg.
    inward = np.stack([-tangent[:, 1], tangent[:, 0]], axis=-1)
    length = np.linalg.norm(inward, axis=-1, keepdims=True)
    with np.errstate(invalid="ignore", divide="ignore"):
        unit = np.where(length > tol.MIN_NORMAL, inward / length, np.nan)
    return unit.reshape(t.shape + (2,))


# ------------------------------------------------------------------ internals


def _edge_wrenches(p, n, mu, centre, rho) -> np.ndarray:
    """(g, 2k, 3) edge wrenches of g grasps from points, unit normals (g, k, 2), centre (g, 2), rho (g,)."""
    t = np.stack([-n[..., 1], n[..., 0]], axis=-1)
    f = n[..., None, :] + mu * np.array([1.0, -1.0])[:, None] * t[..., None, :]  # (g, k, 2, 2)
    with np.errstate(over="ignore", invalid="ignore"):  # overflow is refused just below
        arm = (p - centre[:, None, :])[..., None, :]
        tau = arm[..., 0] * f[..., 1] - arm[..., 1] * f[..., 0]
        w = np.concatenate([f, (tau / rho[:, None, None])[..., None]], axis=-1)
    if not np.all(np.isfinite(w)):
        raise QualityError("the contacts' torques overflow: the points lie too far from the centre "
                           "(or rho is too small) for the wrench space")
    return w.reshape(len(p), 2 * p.shape[1], 3)


def _frame(p, ok, centre, rho) -> tuple[np.ndarray, np.ndarray]:
    """Per-grasp torque reference (g, 2) and characteristic length (g,), defaults filled in."""
    g = len(p)
    if centre is None:
        count = np.maximum(ok.sum(axis=1, keepdims=True), 1)
        c = np.where(ok[..., None], p, 0.0).sum(axis=1) / count
    else:
        c = check.float_array("centre", centre, error=QualityError)
        if c.shape not in {(2,), (g, 2)} or not np.all(np.isfinite(c)):
            raise QualityError(f"centre must be a finite (2,) point (or (p, 2) for many grasps), got {c.shape}")
        c = np.broadcast_to(c, (g, 2))
    if rho is None:
        reach = np.where(ok, np.linalg.norm(p - c[:, None, :], axis=-1), 0.0).max(axis=1, initial=0.0)
        # Contacts all at the centre exert no torque whatever rho is; 1 avoids 0 / 0.
        return c, np.where(reach > 0.0, reach, 1.0)
    r = check.float_array("rho", rho, error=QualityError)
    if r.shape not in {(), (g,)} or not np.all(np.isfinite(r) & (r > 0)):
        raise QualityError(f"rho must be a positive finite length (or (p,) of them), got {rho!r}")
    return c, np.broadcast_to(r, (g,))


def _ball_radius(w: np.ndarray) -> float:
    """Radius of the largest origin-centred ball in conv(w), by Qhull; 0 if none or flat."""
    from scipy.spatial import ConvexHull, QhullError  # scipy loads here: 0.2 s a CLI call need not pay

    if len(w) < 4:
        return 0.0
    try:
        hull = ConvexHull(w)
    except QhullError:  # flat or otherwise degenerate: no interior, no closure
        return 0.0
    # equations are (unit outward normal, offset) with normal . x + offset <= 0 inside,
    # so -offset is the origin's distance to each facet, negative where it is outside.
    radius = float(np.min(-hull.equations[:, -1]))
    return radius if radius > tol.WRENCH_ZERO else 0.0


def _ball_radius_batch(w: np.ndarray, ok: np.ndarray) -> np.ndarray:
    """(g,) ball radii of conv(w[k][ok[k]]) for w (g, m, 3), without Qhull.

    A plane through three of the points with all points on one side is a
    facet's plane, and every facet has one, so the radius is the least
    distance of the origin to such a plane (negative when it is outside).
    A near-degenerate triple gives a poorly defined plane, but one that still
    passes the one-side test is a supporting plane, whose distance is never
    below the true radius: such planes cannot make the answer too small. A
    triple spanning no plane at all (:data:`tolerances.WRENCH_PLANE`) is
    skipped: where every triple is such (the wrenches on one line, e.g. two
    coincident contacts and a third without friction), a plane through it at
    any angle would pass the one-side test and report a radius the flat set
    does not have.
    """
    g, m, _ = w.shape
    if m < 4:
        return np.zeros(g)
    dist = ball_radii(np.ascontiguousarray(w), np.ascontiguousarray(ok), *_triples(m),
                      tol.WRENCH_PLANE, tol.WRENCH_ZERO)
    return np.where(np.isfinite(dist) & (dist > tol.WRENCH_ZERO), dist, 0.0)


@functools.lru_cache(maxsize=32)
def _triples(m: int) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    return tuple(np.array(list(itertools.combinations(range(m), 3))).T)


def _minkowski_sum(pairs: np.ndarray) -> np.ndarray:
    """(3**k, 3) sums of one of {0, w+, w-} per contact, from pairs (k, 2, 3)."""
    sums = np.zeros((1, 3))
    for edges in pairs:
        choices = np.vstack([np.zeros((1, 3)), edges])
        sums = (sums[:, None, :] + choices[None]).reshape(-1, 3)
    return sums


# ------------------------------------------------------------------ validation


def _check_contacts(points, normals) -> tuple[np.ndarray, np.ndarray]:
    """Points and unit normals (n, 2) of one grasp."""
    p, n = _as_float(points, "points"), _as_float(normals, "normals")
    if p.ndim != 2 or p.shape[1] != 2:
        raise QualityError(f"points must be an (n, 2) array, got shape {p.shape}")
    if n.shape != p.shape:
        raise QualityError(f"normals must have the shape of points {p.shape}, got {n.shape}")
    p, n = _check_values(p, n)
    return p, n


def _check_contact_batch(points, normals, valid) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Points, unit normals (g, k, 2) with invalid entries neutralised, and the valid mask (g, k)."""
    p, n = _as_float(points, "points"), _as_float(normals, "normals")
    if p.ndim != 3 or p.shape[2] != 2:
        raise QualityError(f"points must be a (p, n, 2) array, got shape {p.shape}")
    if n.shape != p.shape:
        raise QualityError(f"normals must have the shape of points {p.shape}, got {n.shape}")
    ok = _valid_mask(valid, p.shape[:2])
    # Invalid contacts may hold NaN; give them harmless values, the mask drops them later.
    p, n = _check_values(np.where(ok[..., None], p, 0.0), np.where(ok[..., None], n, 1.0))
    return p, n, ok


def _check_normal_batch(normals, valid) -> tuple[np.ndarray, np.ndarray]:
    """:func:`_check_contact_batch` for normals alone: unit normals (g, k, 2) and the valid mask (g, k)."""
    n = _as_float(normals, "normals")
    if n.ndim != 3 or n.shape[2] != 2:
        raise QualityError(f"normals must be a (p, n, 2) array, got shape {n.shape}")
    ok = _valid_mask(valid, n.shape[:2])
    return _check_values(None, np.where(ok[..., None], n, 1.0))[1], ok


def _valid_mask(valid, shape) -> np.ndarray:
    """(g, k) bool: which contacts exist (all when ``valid`` is None)."""
    try:
        ok = np.ones(shape, bool) if valid is None else np.asarray(valid)
    except (TypeError, ValueError):
        raise QualityError(f"valid must be a {shape} bool array") from None
    if ok.shape != shape or ok.dtype != bool:
        raise QualityError(f"valid must be a {shape} bool array, got {ok.dtype} {ok.shape}")
    return ok


def _check_values(p: np.ndarray | None, n: np.ndarray) -> tuple[np.ndarray | None, np.ndarray]:
    """Refuse non-finite entries and zero normals; return the normals normalised (points: None when not given)."""
    for name, a in (("points", p), ("normals", n)):
        if a is None:
            continue
        bad = ~np.all(np.isfinite(a), axis=-1)
        if np.any(bad):
            raise QualityError(f"{name}{_index(bad)} is not finite")
    with np.errstate(over="ignore"):
        length = np.linalg.norm(n, axis=-1)
    huge = ~np.isfinite(length)
    if np.any(huge):  # the squares overflowed: scale those normals down first
        n = np.where(huge[..., None], n / np.abs(n).max(axis=-1, keepdims=True), n)
        length = np.linalg.norm(n, axis=-1)
    if np.any(length <= tol.MIN_NORMAL):
        raise QualityError(f"normals{_index(length <= tol.MIN_NORMAL)} has zero length: no direction")
    return p, n / length[..., None]


def _check_mu(mu) -> float:
    return check.friction("mu", mu, tol.MAX_FRICTION, error=QualityError)


def _check_metric(metric) -> str:
    return check.choice("metric", metric, METRICS, error=QualityError)


def _check_linf_size(k: int) -> None:
    if k > tol.LINF_MAX_CONTACTS:
        raise QualityError(
            f"metric 'Linf' takes at most {tol.LINF_MAX_CONTACTS} contacts (3**n wrenches), got {k} points"
        )


def _as_float(a, name: str) -> np.ndarray:
    return check.float_array(name, a, error=QualityError)


def _index(mask: np.ndarray) -> str:
    """'[i]' or '[k, i]': the first True entry of mask."""
    return str(list(int(v) for v in np.argwhere(mask)[0]))
