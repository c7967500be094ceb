"""contourgrasp: contour-based grasp synthesis for multi-fingered, underactuated hands.

The pipeline, one package or module per stage (thesis chapter 3):

* :mod:`contourgrasp.perception` — RGB-D frame -> object contour in meters, height map (3.1)
* :mod:`contourgrasp.contour` — contour model: Elliptic Fourier Descriptors, curvature (3.2)
* :mod:`contourgrasp.hand` — finger trajectories, finger chains and hands (3.3)
* :mod:`contourgrasp.synthesis` — inner and outer problems, the grasp plan (3.4)
* :mod:`contourgrasp.quality` — force closure and the Ferrari-Canny epsilon (6.1 item 2)
* :mod:`contourgrasp.pipeline` — perception + synthesis -> 6-DoF grasp pose (4.1.4); its options,
  :class:`~contourgrasp.pipeline.PlanOptions`
* :mod:`contourgrasp.visualize` — figures
* :mod:`contourgrasp.handmodels` — hand files from MuJoCo models of hands (the ``[sim]`` extra)
* :mod:`contourgrasp.sim` — MuJoCo simulation of the grasping experiment and the bench (4.2.4; ``[sim]``)
* :mod:`contourgrasp.io` — file formats (contours, hands, planners, camera files, plans)
* :mod:`contourgrasp.validation`, :mod:`contourgrasp.tolerances`, :mod:`contourgrasp.errors` —
  argument checks, thresholds, exceptions
* :mod:`contourgrasp.cli`, :mod:`contourgrasp.ros` — the ``contourgrasp`` command; the ROS 2 node and rosbag2
  frames (``[ros]``)
"""

from __future__ import annotations

import importlib

from .errors import ContourError, HandFileError, InputError, NoFeasibleGrasp, PlannerError, UnitWarning

# The package's names load on first use (PEP 562), so that ``import contourgrasp`` and a CLI call pay
# only for the stages they use: numba's kernels, scipy and pydantic cost tenths of a second to import.
_LAZY = {
    "contour": (".contour", None), "hand": (".hand", None), "synthesis": (".synthesis", None),
    "validation": (".validation", None), "EFD": (".contour", "EFD"), "GraspPlan": (".synthesis", "GraspPlan"),
    "Arc": (".hand", "Arc"), "Finger": (".hand", "Finger"), "Hand": (".hand", "Hand"), "Ray": (".hand", "Ray"),
    "FingerChain": (".hand", "FingerChain"), "Palm": (".hand", "Palm"), "SampledChain": (".hand", "SampledChain"),
    "example_contour": (".io.contour_file", "example_contour"), "example_names": (".io.contour_file", "example_names"),
    "read_contour": (".io.contour_file", "read_contour"), "read_rgbd": (".io.camera_file", "read_rgbd"),
    "load_hand": (".io.hand_file", "load_hand"),
    "preset_names": (".io.hand_file", "preset_names"), "load_planner": (".io.planner_file", "load_planner"),
    "planner_names": (".io.planner_file", "planner_names"),
}


def __getattr__(name: str):
    if name not in _LAZY:
        raise AttributeError(f"module 'contourgrasp' has no attribute {name!r}")
    module, attribute = _LAZY[name]
    value = importlib.import_module(module, __name__)
    value = value if attribute is None else getattr(value, attribute)
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(_LAZY))


from ._version import __version__


def synthesize(contour_xy, hand, *, planner=None, **options):
    """Plan a grasp on a metric contour: :func:`contourgrasp.synthesis.search` with names resolved.

    ``hand`` is a preset name, a TOML path or a :class:`Hand`; ``planner`` a
    planner preset name (``"paper"``, ``"default"``), a planner TOML path, a loaded planner, or
    None (the thesis's settings). ``options`` are the search's options by name
    (:class:`~contourgrasp.synthesis.SearchOptions`: ``harmonics``, ``xy_step``, ``friction``, ...),
    which override the planner's, and :func:`~contourgrasp.synthesis.search`'s own keywords
    (``descent``, ``low_object``, ``balance_required``, ``balanced_alternative``).

    Returns
    -------
    GraspPlan
        The best pose, its cost, contacts, quality and alternatives.

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
    >>> from contourgrasp import example_contour
    >>> plan = synthesize(example_contour("can"), "three-finger", yaw_step=math.radians(10))
    >>> plan.grid_size
    1764
    """
    from . import synthesis, validation
    from .io.hand_file import load_hand
    from .io.planner_file import load_planner

    calls = validation.options("synthesize", {k: v for k, v in options.items() if k in _SEARCH_CALL},
                               synthesis.search, error=PlannerError)
    base = synthesis.SearchOptions() if planner is None else load_planner(planner).options.search
    chosen = validation.with_options(base, {k: v for k, v in options.items() if k not in _SEARCH_CALL},
                                     what="synthesize", error=PlannerError)
    return synthesis.search(contour_xy, load_hand(hand), chosen, **calls)


#: :func:`contourgrasp.synthesis.search`'s own keywords, which :func:`synthesize` passes on.
_SEARCH_CALL = ("descent", "low_object", "balance_required", "balanced_alternative")
#: :func:`contourgrasp.pipeline.plan_frame`'s own keywords, which :func:`plan_grasp` passes on.
_FRAME_CALL = ("mask", "target_px", "roi", "T_base_camera", "colour_intrinsics", "memory")


def plan_grasp(rgb, depth, intrinsics, hand="five-finger-linear", *, planner=None, **options):
    """Plan a grasp on one RGB-D frame; ``hand`` and ``planner`` as in :func:`synthesize`.

    ``options`` are :class:`~contourgrasp.pipeline.PlanOptions` by name (``segment``, ``depth_mode``,
    ``xy_step``, ``descent``, ``standoff``, ...), which override the planner's, and
    :func:`~contourgrasp.pipeline.plan_frame`'s own keywords (``mask``, ``target_px``, ``roi``,
    ``T_base_camera``, ``colour_intrinsics``, ``memory``). Returns an :class:`contourgrasp.pipeline.ImageGraspPlan` (``.plan`` is the
    :class:`GraspPlan`, ``.T_camera_hand`` the 6-DoF pose).
    """
    from . import validation
    from .io.hand_file import load_hand
    from .io.planner_file import load_planner
    from .pipeline import PlanOptions, plan_frame

    base = PlanOptions() if planner is None else load_planner(planner).options
    chosen = validation.with_options(base, {k: v for k, v in options.items() if k not in _FRAME_CALL},
                                     what="plan_grasp", error=PlannerError)
    return plan_frame(rgb, depth, intrinsics, load_hand(hand), chosen,
                      **{k: v for k, v in options.items() if k in _FRAME_CALL})


__all__ = [
    "Arc", "ContourError", "EFD", "Finger", "FingerChain", "GraspPlan", "Hand", "HandFileError", "InputError",
    "NoFeasibleGrasp", "Palm", "Ray", "SampledChain", "UnitWarning", "contour", "example_contour", "example_names", "hand",
    "load_hand", "load_planner", "plan_grasp", "planner_names", "preset_names", "read_contour", "read_rgbd", "synthesis",
    "synthesize",
]
