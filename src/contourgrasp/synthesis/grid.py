"""The outer problem's pose grid (Tables 4.1-4.2, eq 3.33 and 3.39-3.40), its fast screen, and distinct poses.

:func:`screen_grid` evaluates every grid pose with a compiled kernel (contacts on the EFD
polygon, curvature from tables; :mod:`contourgrasp.synthesis._grid_kernels`); there is no Python
loop per pose. :func:`distinct_best` ranks poses, skipping grid neighbours of those taken.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..contour import curvature_from_derivatives, evaluate_derivatives
from .. import tolerances as tol
from .. import validation as check
from ..contour import EFD, CurvatureMode
from ..errors import PlannerError
from ..hand import Hand
from ._derived import hand_arrays, polygon
from ._grid_kernels import grid_first_touch, interpolate_curvature, touch_counts
from .cost import PoseEvaluation, score
from .safeguards import Safeguards


@dataclass(frozen=True)
class SearchGrid:
    """Resolution and extent of the outer problem's pose grid (Tables 4.1-4.2).

    Implements eq 3.39 and 3.40: positions lie within (D_max,x, D_max,y) of the EFD locus
    (A0, C0), on a square lattice of step ``xy_step`` through it; yaws cover [0, 2 pi) in steps
    of ``yaw_step``.

    Attributes
    ----------
    xy_step : float
        Position resolution, m.
    yaw_step : float
        Orientation resolution, rad, in (0, 2 pi].
    d_max : (2,) float
        (D_max,x, D_max,y): largest offset of the hand from the locus, m (one number: both).
    d_min : float
        D_min: smallest distance from a fingertip's start to its grasp point, m.

    Raises
    ------
    PlannerError
        Naming the attribute that is not a number in range, or when the grid would have more
        than ``tolerances.MAX_GRID_POSES`` poses.

    Examples
    --------
    >>> SearchGrid().shape  # Tables 4.1-4.2: 7 x 7 positions, 180 yaws
    (7, 7, 180)
    """

    xy_step: float = 0.05
    yaw_step: float = math.radians(2.0)
    d_max: tuple[float, float] = (0.15, 0.15)
    d_min: float = 0.015

    def __post_init__(self):
        d_max = check.float_array("d_max", self.d_max, error=PlannerError)
        if d_max.shape not in {(), (1,), (2,)}:
            raise PlannerError(f"d_max must be a number or two numbers (x, y), got shape {d_max.shape}")
        d_max = tuple(check.bounded("d_max", v, tol.MAX_SEARCH_LENGTH, " m", error=PlannerError)
                      for v in np.broadcast_to(d_max, (2,)).tolist())
        object.__setattr__(self, "d_max", d_max)
        check.bounded("xy_step", self.xy_step, tol.MAX_SEARCH_LENGTH, " m", strict=True, error=PlannerError)
        check.bounded("yaw_step", self.yaw_step, 2 * math.pi, " rad", strict=True, error=PlannerError)
        check.bounded("d_min", self.d_min, tol.MAX_SEARCH_LENGTH, " m", error=PlannerError)
        self._check_size()

    def _check_size(self) -> None:
        """Refuse a grid of more than ``tolerances.MAX_GRID_POSES`` poses before any is made."""
        counts = [2 * (extent / self.xy_step) + 1 for extent in self.d_max] + [2 * math.pi / self.yaw_step]
        total = math.prod(counts)
        if total > tol.MAX_GRID_POSES:
            shape = " × ".join(f"{axis} {n:.0f}" if n < 1e15 else f"{axis} {n:.2g}"
                               for axis, n in zip(("x", "y", "yaw"), counts))
            raise PlannerError(f"the search grid would have {total:.2g} poses ({shape}); at most "
                               f"{tol.MAX_GRID_POSES:,}: use a coarser xy_step or yaw_step, or a smaller d_max")

    @property
    def shape(self) -> tuple[int, int, int]:
        """(nx, ny, nyaw): the number of x, y and yaw values of the grid."""
        nx, ny = (2 * int(math.floor(extent / self.xy_step + 1e-9)) + 1 for extent in self.d_max)
        return nx, ny, int(math.ceil(2 * math.pi / self.yaw_step - 1e-9))

    def axes(self, locus) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The grid's x (nx,), y (ny,) and yaw (nyaw,) values around ``locus`` (2,)."""
        nx, ny, n_yaw = self.shape
        xy = [centre + self.xy_step * np.arange(-(n // 2), n // 2 + 1) for centre, n in zip(locus, (nx, ny))]
        return xy[0], xy[1], self.yaw_step * np.arange(n_yaw)

    def poses(self, locus) -> np.ndarray:
        """(p, 3) float: every (x, y, yaw) of the grid around ``locus`` (2,), yaw varying fastest.

        Implements eq 3.33: each row is a pose rho = (x_p, y_p, phi_p).
        """
        x, y, yaw = self.axes(locus)
        poses = np.empty((len(x), len(y), len(yaw), 3))
        poses[..., 0], poses[..., 1], poses[..., 2] = x[:, None, None], y[:, None], yaw
        return poses.reshape(-1, 3)


def screen_grid(
    model: EFD, hand: Hand, grid: SearchGrid, *, curvature: CurvatureMode = "paper", samples: int = tol.EFD_SAMPLES,
    centring_gain: float = 0.0,
) -> PoseEvaluation:
    """Evaluate every pose of a grid fast, to within the EFD polygon's accuracy.

    Contacts stay on the sampled polygon (``samples`` points) and curvature is
    interpolated from tables (``tol.CURVATURE_TABLE`` samples), so costs differ
    from :func:`~contourgrasp.synthesis.evaluate_poses` by about 1e-4 relative (up to ~1 where a
    contact grazes the contour); :func:`~contourgrasp.synthesis.search` re-evaluates the best
    candidates exactly. The inner loop is the compiled
    :func:`contourgrasp.synthesis._grid_kernels.grid_first_touch`.

    Parameters
    ----------
    model : EFD
    hand : Hand
    grid : SearchGrid
    curvature : {"paper", "geometric"}
    samples : int
    centring_gain : float
        The one safeguard of the screen: its cost orders the poses evaluated exactly.

    Returns
    -------
    PoseEvaluation
        Of ``grid.poses(model.locus)``, without safeguards but the centring cost.
    """
    poses, touches, tables, n_yaw = _first_touches(model, hand, grid, curvature, samples)
    return _scored(model, hand, grid, poses, touches, tables, centring_gain, n_yaw)


def screen_reaching(
    model: EFD, hand: Hand, grid: SearchGrid, *, curvature: CurvatureMode = "paper", samples: int = tol.EFD_SAMPLES,
    centring_gain: float = 0.0,
) -> tuple[PoseEvaluation, np.ndarray, bool]:
    """:func:`screen_grid` of only the grid poses where at least ``hand.min_touching`` fingers touch.

    Every other pose is infeasible whatever the rest (eq 3.41 needs that many fingers on the
    object), and on a dense grid they are about nine poses in ten: the search scores only these.
    Each kept pose's evaluation is the one :func:`screen_grid` gives it, bit for bit; they keep
    the grid's order.

    Returns
    -------
    screen : PoseEvaluation
        Of the kept poses.
    touching : (p,) int
        The fingers that touch at each kept pose (``screen.touching`` counted).
    any_outside : bool
        Whether any pose of the whole grid starts with every fingertip outside the contour (what a
        search that finds no pose says first).
    """
    poses, touches, tables, _ = _first_touches(model, hand, grid, curvature, samples)
    counts, any_outside = touch_counts(touches[0], touches[3])
    kept = np.flatnonzero(counts >= hand.min_touching)  # np.take of these rows: 5x faster than boolean indexing
    screen = _scored(model, hand, grid, poses[kept], tuple(np.take(a, kept, axis=0) for a in touches), tables,
                     centring_gain, None)
    return screen, counts[kept], bool(any_outside)


def _first_touches(model: EFD, hand: Hand, grid: SearchGrid, curvature: CurvatureMode, samples: int):
    """The grid's poses (p, 3); per pose and finger the first touch on the EFD polygon, (lam, t, point,
    start_inside) as the compiled kernel gives them; the curvature tables; the number of yaws."""
    xs, ys, yaws = grid.axes(model.locus)
    contour_t, contour = polygon(model, samples)
    arrays = hand_arrays(hand)
    seg = arrays.segments
    lam, t, point, start_inside = grid_first_touch(
        contour, contour_t, model.T, xs, ys, yaws, seg.start, seg.end - seg.start, seg.finger, seg.lam0, arrays.first,
        len(hand.fingers), tol.PARALLEL,
    )
    # The paper's curvature jumps where the contour turns from convex to concave; its magnitude and
    # the turning direction r' x r'' do not, so they are tabulated and interpolated apart.
    table_t = np.linspace(0.0, model.T, tol.CURVATURE_TABLE, endpoint=False)
    d1, d2 = evaluate_derivatives(model, table_t, (1, 2))
    turn = d1[:, 0] * d2[:, 1] - d1[:, 1] * d2[:, 0]
    magnitude = np.abs(curvature_from_derivatives(d1, d2, model.T, curvature))
    return grid.poses(model.locus), (lam, t, point, start_inside), (magnitude, turn), len(yaws)


def _scored(model: EFD, hand: Hand, grid: SearchGrid, poses, touches, tables, centring_gain: float,
            n_yaw: int | None) -> PoseEvaluation:
    """:func:`~contourgrasp.synthesis.cost.score` of ``poses`` from their first ``touches`` and the curvature
    ``tables``; ``n_yaw`` as there."""
    lam, t, point, start_inside = touches
    curv = interpolate_curvature(*tables, t, model.T)
    touching = np.isfinite(lam)
    n = len(poses)
    return score(hand, poses, touching, np.where(touching, lam, np.nan), t, point, curv, start_inside,
                 grid.d_min, np.ones(n, bool), np.full(n, np.nan), Safeguards(centring_gain=centring_gain),
                 n_yaw=n_yaw, locus=model.locus)


def distinct_best(result: PoseEvaluation, grid: SearchGrid, k: int, block: int = 512) -> list[int]:
    """Indices of the k cheapest feasible poses, skipping grid neighbours of those already taken.

    Candidates are compared with each other ``block`` at a time, in increasing cost.

    Parameters
    ----------
    result : PoseEvaluation
    grid : SearchGrid
        Its steps define neighbours (:func:`neighbours`).
    k, block : int

    Returns
    -------
    list of int
        At most k indices into ``result``, best first.
    """
    candidates = np.flatnonzero(result.feasible)
    order = candidates[np.argsort(result.cost[candidates], kind="stable")]
    taken: list[int] = []
    for start in range(0, len(order), block):
        rows = order[start:start + block]
        blocked = neighbours(result.poses[rows], result.poses[taken], grid).any(axis=1)
        near = neighbours(result.poses[rows], result.poses[rows], grid)
        for j, i in enumerate(rows.tolist()):
            if blocked[j]:
                continue
            taken.append(i)
            if len(taken) == k:
                return taken
            blocked |= near[j]
    return taken


def neighbours(a: np.ndarray, b: np.ndarray, grid: SearchGrid) -> np.ndarray:
    """(len(a), len(b)) bool: poses a (n, 3) and b (m, 3) are grid neighbours in x, y and yaw at once."""
    delta = np.abs(a[:, None, :] - b[None, :, :])
    delta[..., 2] = np.minimum(delta[..., 2], 2 * math.pi - delta[..., 2])
    slack = 1.0 + 1e-6
    return (delta[..., :2] <= grid.xy_step * slack).all(axis=-1) & (delta[..., 2] <= grid.yaw_step * slack)
