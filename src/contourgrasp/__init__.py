"""contourgrasp: contour-based grasp synthesis for multi-fingered, underactuated hands.

The pipeline, one module per stage (thesis chapter 3):

* :mod:`contourgrasp.efd` — contour model: Elliptic Fourier Descriptors, curvature (3.2)
* :mod:`contourgrasp.hand` — finger trajectories and hands (3.3)
* :mod:`contourgrasp.synthesis` — inner and outer problems, the grasp plan (3.4)
* :mod:`contourgrasp.perception` — RGB-D frame -> object contour in meters (3.1)
* :mod:`contourgrasp.pipeline` — perception + synthesis -> 6-DoF grasp pose (4.1.4)
* :mod:`contourgrasp.sim` — MuJoCo simulation of the grasping experiment (4.2.4)
* :mod:`contourgrasp.visualize` — figures
* :mod:`contourgrasp.io` — file formats (contours, hands, plans)
* :mod:`contourgrasp.cli` — the ``contourgrasp`` command
"""

from __future__ import annotations

import math

from . import efd, hand, synthesis
from .efd import EFD
from .errors import ContourError, HandFileError, InputError, NoFeasibleGrasp, UnitWarning
from .hand import Arc, Finger, Hand, Ray
from .io.contour_file import example_contour, example_names, read_contour
from .io.hand_file import load_hand, preset_names
from .synthesis import GraspPlan

__version__ = "0.1.0"


def synthesize(
    contour_xy,
    hand,
    *,
    harmonics: int = 4,
    curvature: str = "paper",
    xy_step: float = 0.05,
    yaw_step: float = math.radians(2.0),
    d_max=(0.15, 0.15),
    d_min: float = 0.015,
    top_k: int = 10,
) -> GraspPlan:
    """Plan a grasp on a metric contour; ``hand`` is a preset name, a TOML path or a :class:`Hand`.

    See :func:`contourgrasp.synthesis.synthesize` for the parameters.

    Examples
    --------
    >>> plan = synthesize(example_contour("can"), "three-finger", yaw_step=math.radians(10))
    >>> plan.grid_size
    1764
    """
    return synthesis.synthesize(
        contour_xy,
        load_hand(hand),
        harmonics=harmonics,
        curvature=curvature,
        xy_step=xy_step,
        yaw_step=yaw_step,
        d_max=d_max,
        d_min=d_min,
        top_k=top_k,
    )


def plan_grasp(rgb, depth, intrinsics, hand="five-finger-linear", **options):
    """Plan a grasp on one RGB-D frame; ``hand`` is a preset name, a TOML path or a :class:`Hand`.

    Returns an :class:`contourgrasp.pipeline.ImageGraspPlan` (``.plan`` is the
    :class:`GraspPlan`, ``.T_camera_hand`` the 6-DoF pose); see
    :func:`contourgrasp.pipeline.plan_grasp` for the options.
    """
    from .pipeline import plan_grasp as _plan_grasp

    return _plan_grasp(rgb, depth, intrinsics, load_hand(hand), **options)


__all__ = [
    "Arc", "ContourError", "EFD", "Finger", "GraspPlan", "Hand", "HandFileError", "InputError",
    "NoFeasibleGrasp", "Ray", "UnitWarning", "efd", "example_contour", "example_names", "hand",
    "load_hand", "plan_grasp", "preset_names", "read_contour", "synthesis", "synthesize",
]
