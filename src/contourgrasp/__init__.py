"""contourgrasp: contour-based grasp synthesis for multi-fingered, underactuated hands.

The pipeline, one module per stage (thesis chapter 3):

* :mod:`contourgrasp.efd` — contour model: Elliptic Fourier Descriptors, curvature (3.2)
* :mod:`contourgrasp.hand` — finger trajectories and hands (3.3)
* :mod:`contourgrasp.synthesis` — inner and outer problems, the grasp plan (3.4)
* :mod:`contourgrasp.quality` — force closure and the Ferrari-Canny epsilon (6.1 item 2)
* :mod:`contourgrasp.perception` — RGB-D frame -> object contour in meters (3.1)
* :mod:`contourgrasp.pipeline` — perception + synthesis -> 6-DoF grasp pose (4.1.4)
* :mod:`contourgrasp.sim` — MuJoCo simulation of the grasping experiment (4.2.4)
* :mod:`contourgrasp.visualize` — figures
* :mod:`contourgrasp.io` — file formats (contours, hands, planners, plans)
* :mod:`contourgrasp.cli` — the ``contourgrasp`` command
"""

from __future__ import annotations

from . import efd, hand, synthesis, validation
from .contour import EFD
from .errors import ContourError, HandFileError, InputError, NoFeasibleGrasp, PlannerError, UnitWarning
from .hand import Arc, Finger, Hand, Ray
from .io.contour_file import example_contour, example_names, read_contour
from .io.hand_file import load_hand, preset_names
from .io.planner_file import load_planner, planner_names
from .synthesis import GraspPlan

__version__ = "0.1.0"


def synthesize(contour_xy, hand, *, planner=None, **options) -> GraspPlan:
    """Plan a grasp on a metric contour: :func:`contourgrasp.synthesis.search` with names resolved.

    ``hand`` is a preset name, a TOML path or a :class:`Hand`; ``planner`` a
    planner preset name (``"paper"``, ``"default"``), a planner TOML path or
    None (the options' defaults, which are the thesis's). ``options`` are
    keyword options of :func:`contourgrasp.synthesis.search` and override
    the planner's.

    Raises
    ------
    InputError
        A bad contour (ContourError), hand (HandError, HandFileError), planner or option
        (PlannerError, naming it).
    NoFeasibleGrasp
        No pose satisfies the constraints.

    Examples
    --------
    >>> import math
    >>> plan = synthesize(example_contour("can"), "three-finger", yaw_step=math.radians(10))
    >>> plan.grid_size
    1764
    """
    validation.options("synthesize", options, synthesis.search, error=PlannerError)
    settings = {} if planner is None else load_planner(planner).synthesis_options
    return synthesis.search(contour_xy, load_hand(hand), **(settings | options))


def plan_grasp(rgb, depth, intrinsics, hand="five-finger-linear", *, planner=None, **options):
    """Plan a grasp on one RGB-D frame; ``hand`` and ``planner`` as in :func:`synthesize`.

    Returns an :class:`contourgrasp.pipeline.ImageGraspPlan` (``.plan`` is the
    :class:`GraspPlan`, ``.T_camera_hand`` the 6-DoF pose); see
    :func:`contourgrasp.pipeline.plan_frame` for the options, which override the planner's.
    """
    from .pipeline import plan_frame

    settings = {} if planner is None else load_planner(planner).plan_options
    return plan_frame(rgb, depth, intrinsics, load_hand(hand), **(settings | options))


__all__ = [
    "Arc", "ContourError", "EFD", "Finger", "GraspPlan", "Hand", "HandFileError", "InputError",
    "NoFeasibleGrasp", "Ray", "UnitWarning", "efd", "example_contour", "example_names", "hand",
    "load_hand", "load_planner", "plan_grasp", "planner_names", "preset_names", "read_contour", "synthesis",
    "synthesize",
]
