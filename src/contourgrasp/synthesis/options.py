"""The search's options and the 3-D hand's: frozen dataclasses, each the one source of its defaults.

A planner file (:mod:`contourgrasp.io.planner_file`), the command line and the ROS node's parameters
all build these; :func:`~contourgrasp.synthesis.search` takes :class:`SearchOptions`, and
:func:`contourgrasp.pipeline.plan_frame` takes both inside its :class:`~contourgrasp.pipeline.PlanOptions`.
Every option is checked by name when the dataclass is built. The defaults are the thesis's.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Literal

import numpy as np

from .. import tolerances as tol
from .. import validation as check
from ..contour import CURVATURE_MODES, CurvatureMode
from ..errors import PlannerError
from ..hand import SLICE_CONTOUR as HAND_SLICE_CONTOUR
from ..perception.view_along import APPROACH_KINDS
from .grasp_height import check_rule as check_grasp_height
from .grid import SearchGrid
from .safeguards import Safeguards

def check_approaches(approaches) -> str:
    """``approaches`` if it is kinds of :data:`APPROACH_KINDS` joined by ``+``, each once (their order is kept).

    Raises
    ------
    PlannerError
        Not a string, an unknown kind or one named twice, naming ``approaches``.
    """
    if not isinstance(approaches, str):
        raise PlannerError(f"approaches must be a string of {', '.join(APPROACH_KINDS)} joined by '+', "
                           f"got {approaches!r}")
    kinds = approaches.split("+")
    for kind in kinds:
        check.choice("approaches", kind, APPROACH_KINDS, error=PlannerError)
    if len(set(kinds)) < len(kinds):
        raise PlannerError(f"approaches names a kind twice: {approaches!r}")
    return approaches

#: The values of :attr:`SceneOptions.slice_contour`: a hand's, or the hand's own.
SLICE_CONTOUR = (*HAND_SLICE_CONTOUR, "hand")


@dataclass(frozen=True, kw_only=True)
class SearchOptions:
    """How the search models the outline, which poses it tries and which it refuses (thesis 3.2, 3.4).

    Attributes
    ----------
    harmonics : int or "adaptive"
        EFD harmonics (thesis: 4; at most ``tolerances.MAX_HARMONICS``); ``"adaptive"`` chooses
        them per object (:func:`contourgrasp.contour.choose_harmonics` with its defaults).
    curvature : {"paper", "geometric"}
        Curvature flavour of the cost, see :mod:`contourgrasp.contour`.
    grid : SearchGrid
        The pose grid: ``xy_step``, ``yaw_step``, ``d_max``, ``d_min`` (Tables 4.1-4.2).
    safeguards : Safeguards
        ``finger_thickness``, ``clearance``, ``friction``, ``require_closure``, ``quality_gain``,
        ``centring_gain``, ``max_imbalance`` (all off: the thesis's problem); ``max_imbalance`` may be
        ``"hand"``, the hand's own.
    top_k : int
        Number of distinct ranked poses the plan keeps in ``alternatives``.
    refine : bool
        Refine the grid's best poses continuously (:func:`~contourgrasp.synthesis.refine_poses`).
    small_objects : bool
        The small-object rule: fewer touching fingers, then the fingertips as balls, where no pose
        satisfies the constraints (:func:`~contourgrasp.synthesis.search`).

    Raises
    ------
    PlannerError
        Naming the option of the wrong type or out of range.
    """

    harmonics: int | Literal["adaptive"] = 4
    curvature: CurvatureMode = "paper"
    grid: SearchGrid = SearchGrid()
    safeguards: Safeguards = Safeguards()
    top_k: int = 10
    refine: bool = False
    small_objects: bool = False

    def __post_init__(self):
        _check_harmonics(self.harmonics)
        check.choice("curvature", self.curvature, CURVATURE_MODES, error=PlannerError)
        _check_type("grid", self.grid, SearchGrid)
        _check_type("safeguards", self.safeguards, Safeguards)
        object.__setattr__(self, "harmonics", self.harmonics if self.harmonics == "adaptive" else int(self.harmonics))
        object.__setattr__(self, "top_k", check.integer("top_k", self.top_k, 1, maximum=tol.MAX_GRID_POSES,
                                                        error=PlannerError))
        object.__setattr__(self, "refine", check.flag("refine", self.refine, error=PlannerError))
        object.__setattr__(self, "small_objects", check.flag("small_objects", self.small_objects, error=PlannerError))


@dataclass(frozen=True, kw_only=True)
class SceneOptions:
    """Planning with the hand's 3-D bodies in the scene's 3-D: what :func:`contourgrasp.pipeline.plan_frame` adds to
    the search when the frame has a table (its height map). All off: the thesis's 2-D problem.

    Attributes
    ----------
    descent : bool
        A pose is feasible only if the open hand descends to the grasp height without any finger's body or
        the palm passing below the height map (:class:`~contourgrasp.synthesis.Descent`).
    grasp_height : {"clearance", "auto"} or float or None
        The open tips' height above the table at the grasp
        (:func:`~contourgrasp.synthesis.grasp_height.grasp_height`); None: ``"clearance"`` with
        ``descent``, else not planned (the executor chooses how deep to go, as in the thesis).
    slice_contour : bool or "unbalanced" or "hand"
        Plan on the object's cross-section at the grasp height rather than its outline seen
        (:func:`contourgrasp.perception.cross_section`); ``"unbalanced"`` only where no pose balances the
        squeeze on the outline seen; ``"hand"`` the hand's own (:attr:`Hand.slice_contour`).
    closing_sweep : bool
        With ``descent``: refuse a pose where a touching finger's chain meets the scene before its tip
        reaches its grasp point (:mod:`contourgrasp.synthesis.sweep`).
    closing_obstacles : bool
        With ``descent``: refuse a pose where a closing finger runs into a neighbouring object or a bin's wall.
    low_objects : bool
        Plan an object lower than ``tolerances.LOW_OBJECT_HEIGHT`` first as a pinch of the thumb against
        one finger with the fingertips as balls.
    approaches : str
        The approach kinds a plan tries, in order: kinds of :data:`APPROACH_KINDS` joined by ``+``, e.g.
        ``"top"`` (top-down only, the thesis's), ``"top+tilted"`` (tilted where top-down has no feasible
        pose, or where it failed: :func:`contourgrasp.pipeline.approach_order`), ``"side"`` (a shelf, an arm
        that cannot reach over the object). ``side``: horizontal, ``tilted``: 45 deg down, each from four
        directions along and across the object's footprint, the lowest cost among them
        (:func:`contourgrasp.pipeline.approach_set`); they need ``descent`` and a table (docs/approaches.md).

    Raises
    ------
    PlannerError
        Naming the option of the wrong type or value.
    """

    descent: bool = False
    grasp_height: str | float | None = None
    slice_contour: bool | str = False
    closing_sweep: bool = False
    closing_obstacles: bool = False
    low_objects: bool = False
    approaches: str = "top"

    def __post_init__(self):
        for name in ("descent", "closing_sweep", "closing_obstacles", "low_objects"):
            object.__setattr__(self, name, check.flag(name, getattr(self, name), error=PlannerError))
        if self.grasp_height is not None:
            object.__setattr__(self, "grasp_height", check_grasp_height(self.grasp_height))
        object.__setattr__(self, "slice_contour", check.choice("slice_contour", self.slice_contour, SLICE_CONTOUR,
                                                               error=PlannerError))
        object.__setattr__(self, "approaches", check_approaches(self.approaches))


def _check_harmonics(harmonics) -> None:
    """An integer in 1..``tolerances.MAX_HARMONICS`` or ``"adaptive"``."""
    if isinstance(harmonics, str) and harmonics == "adaptive":
        return
    if isinstance(harmonics, str) or isinstance(harmonics, bool) or not isinstance(harmonics, (int, np.integer)):
        raise PlannerError(f"harmonics must be an integer or 'adaptive', got {harmonics!r}")
    check.integer("harmonics", harmonics, 1, maximum=tol.MAX_HARMONICS, error=PlannerError)


def _check_type(name: str, value, kind: type) -> None:
    if not isinstance(value, kind):
        raise PlannerError(f"{name} must be a contourgrasp.synthesis.{kind.__name__}, got {type(value).__name__}")
