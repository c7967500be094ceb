"""Inner problem and cost, exactly, at any list of poses (thesis 3.4.1-3.4.2)."""

from __future__ import annotations

from dataclasses import fields

import numpy as np

from ..contour import CURVATURE_MODES, efd
from .. import tolerances as tol
from .. import validation as check
from ..contour import EFD, CurvatureMode
from ..errors import PlannerError
from ..hand import Hand
from ._derived import polygon
from .cost import score
from .inner import solve
from .cost import PoseEvaluation
from .safeguards import Safeguards, fingers_clear, grade


def evaluate_poses(
    model: EFD,
    hand: Hand,
    poses: np.ndarray,
    *,
    curvature: CurvatureMode = "paper",
    d_min: float = 0.015,
    samples: int = tol.EFD_SAMPLES,
    safeguards: Safeguards = Safeguards(),
) -> PoseEvaluation:
    """Solve the inner problem exactly and the outer cost for each pose (see eq 3.22-3.41).

    The first touch is found on the EFD curve sampled as a polygon, then moved
    onto the curve itself by Newton's method on r(t) = p(lam) (the zero of
    eq 3.24 nearest the polygon's answer; :func:`contourgrasp.synthesis.inner.solve`).

    Parameters
    ----------
    model : EFD
    hand : Hand
    poses : (p, 3) float
        (x, y, yaw) of the hand in the image plane.
    curvature : {"paper", "geometric"}
    d_min : float
        D_min of eq 3.41, m.
    samples : int
        Points of the EFD polygon the fingers are intersected with first.
    safeguards : Safeguards
        Constraints and cost beyond the thesis's (default: none).

    Returns
    -------
    PoseEvaluation

    Raises
    ------
    PlannerError
        Naming the option that is malformed.
    """
    check.choice("curvature", curvature, CURVATURE_MODES, error=PlannerError)
    check.bounded("d_min", d_min, tol.MAX_SEARCH_LENGTH, " m", error=PlannerError)
    check.integer("samples", samples, 3, error=PlannerError)
    if not isinstance(safeguards, Safeguards):
        raise PlannerError(f"safeguards must be a Safeguards, got {type(safeguards).__name__}")
    poses = check.finite_array("poses", np.atleast_2d(poses), (None, 3), error=PlannerError)
    lam, t, point, start_inside = solve(model, hand, poses, samples)
    touching = np.isfinite(lam)
    curv = np.full(lam.shape, np.nan)
    curv[touching] = efd.curvature(model, t[touching], curvature)
    clear = np.ones(len(poses), bool)
    if safeguards.finger_thickness:
        contour = polygon(model, samples)[1]
        # chunks bound the (poses, contour points, chords) arrays when the candidate set widens
        clear = np.concatenate([fingers_clear(contour, hand, poses[rows], lam[rows], point[rows],
                                              clearance=safeguards.clearance)
                                for rows in np.array_split(np.arange(len(poses)), -(-len(poses) // tol.POSE_BATCH))])
    epsilon, imbalance = grade(model, point, t, touching, safeguards)
    return score(hand, poses, touching, lam, t, point, curv, start_inside, d_min, clear, epsilon, safeguards,
                 imbalance=imbalance, locus=model.locus)


def replace_rows(evaluation: PoseEvaluation, rows, source: PoseEvaluation, source_rows) -> PoseEvaluation:
    """``evaluation`` with its ``rows`` replaced by ``source_rows`` of ``source``."""
    def replaced(name):
        values = getattr(evaluation, name).copy()
        values[rows] = getattr(source, name)[source_rows]
        return values

    return PoseEvaluation(**{f.name: replaced(f.name) for f in fields(PoseEvaluation)})


def concatenate(*evaluations: PoseEvaluation) -> PoseEvaluation:
    """The poses of several evaluations, in order, as one."""
    return PoseEvaluation(**{f.name: np.concatenate([getattr(e, f.name) for e in evaluations])
                             for f in fields(PoseEvaluation)})
