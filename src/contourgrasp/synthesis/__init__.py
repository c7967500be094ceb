"""Grasp synthesis: the inner and outer problems of thesis section 3.4, one module per stage.

* :mod:`~contourgrasp.synthesis.inner` — the inner problem (eq 3.22-3.31): where each finger
  first touches the contour at a pose (:func:`first_touch`, Newton onto the curve, the closest
  approach of a finger that misses);
* :mod:`~contourgrasp.synthesis.cost` — the outer problem's cost (eq 3.34-3.38,
  :func:`ratio_cost`) and its constraint on the fingers' starts (eq 3.41);
* :mod:`~contourgrasp.synthesis.safeguards` — constraints beyond the thesis's (:class:`Safeguards`,
  :func:`fingers_clear`, :func:`grasp_epsilon`, :func:`grasp_imbalance`);
* :mod:`~contourgrasp.synthesis.evaluate` — inner problem and cost exactly at any poses
  (:func:`evaluate_poses`);
* :mod:`~contourgrasp.synthesis.grid` — the pose grid (eq 3.33, 3.39-3.40, :class:`SearchGrid`), its
  compiled screen (:func:`screen_grid`, :func:`screen_reaching`) and distinct best poses;
* :mod:`~contourgrasp.synthesis.refine` — continuous refinement off the grid (:func:`refine_poses`);
* :mod:`~contourgrasp.synthesis.descent` — the open 3-D hand's descent onto the scene's height map
  (:class:`Descent`, :func:`descent_feasible`, :func:`descent_floor`), a constraint of the search;
* :mod:`~contourgrasp.synthesis.options` — the search's options and the 3-D hand's (:class:`SearchOptions`,
  :class:`SceneOptions`);
* :mod:`~contourgrasp.synthesis.memory` — the grasps that failed, avoided by the next search in the
  object's frame (:class:`GraspMemory`, :func:`object_frame`), one per object of a scene (:class:`SceneMemory`);
* :mod:`~contourgrasp.synthesis.outer` — the search itself (eq 3.32, :func:`search`);
* :mod:`~contourgrasp.synthesis.plan` — what it returns (:class:`GraspPlan`, :class:`Cost`, ...).

:func:`contourgrasp.synthesize` is :func:`search` with a hand and a planner given by name.
"""

from .cost import PoseEvaluation, distance, ratio_cost
from .descent import Descent, DescentCheck, descent_clearance, descent_feasible, descent_floor
from .evaluate import evaluate_poses
from .grid import SearchGrid, distinct_best, screen_grid, screen_reaching
from .inner import closest_approach, first_touch
from .memory import GraspMemory, SceneMemory, object_frame
from .options import SceneOptions, SearchOptions
from .outer import search
from .plan import Alternative, Cost, FingerContact, GraspPlan, Refinement
from .refine import refine_poses
from .safeguards import Safeguards, fingers_clear, grasp_epsilon, grasp_imbalance

__all__ = [
    "Alternative", "Cost", "Descent", "DescentCheck", "FingerContact", "GraspMemory", "GraspPlan", "PoseEvaluation", "Refinement", "Safeguards", "SceneMemory", "SceneOptions", "SearchOptions",
    "SearchGrid", "closest_approach", "descent_clearance", "descent_feasible", "descent_floor", "distance", "distinct_best", "evaluate_poses", "fingers_clear",
    "first_touch", "grasp_epsilon", "grasp_imbalance", "object_frame", "ratio_cost", "refine_poses", "screen_grid", "screen_reaching", "search",
]
