"""How a frame is read into a contour: :class:`PerceptionOptions`, the one source of their defaults."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .. import validation
from ..errors import PerceptionError
from ..tolerances import APPROACH_OFFSET, MAX_APPROACH_OFFSET
from .metric import DEPTH_MODES
from .segmentation import SEGMENT_METHODS


@dataclass(frozen=True, kw_only=True)
class PerceptionOptions:
    """The perception options of :func:`contourgrasp.pipeline.plan_frame` (a planner file's ``depth_mode`` and
    ``footprint``, the command line's ``plan`` flags).

    Attributes
    ----------
    segment : {"auto", "rgb", "depth"}
        Segmentation method (:func:`contourgrasp.perception.segment`); ignored with a user's mask.
    depth_mode : {"max", "plane"}
        Height of the contour's plane (:func:`contourgrasp.perception.contour_to_metric`). With ``"max"``
        depth segmentation returns the object's footprint when the camera is tilted, planned on the table
        itself; with ``"plane"`` always the pixels that see the object, planned at the object's top.
    footprint : bool or None
        With ``depth_mode="max"``: plan the object's footprint on the table
        (:func:`contourgrasp.perception.object_footprint`) even from a top-down camera (True), or never
        (False); None: only when the camera is tilted more than 2 deg.
    fill_holes : bool
        Fill small depth holes (nearest valid reading) before use.
    colour_offset_px : (int, int) or None
        The colour-depth misregistration (dx, dy) if known, ``(0, 0)`` for a pair registered to the pixel;
        None: ``"auto"`` segmentation estimates it (:func:`contourgrasp.perception.colour_offset`).
    approach_offset : float
        Added to the nearest depth inside the contour, m (section 3.1.1); at most
        ``tolerances.MAX_APPROACH_OFFSET`` either way.

    Raises
    ------
    PerceptionError
        Naming the option of the wrong type or value.
    """

    segment: str = "auto"
    depth_mode: str = "max"
    footprint: bool | None = None
    fill_holes: bool = True
    colour_offset_px: tuple[int, int] | None = None
    approach_offset: float = APPROACH_OFFSET

    def __post_init__(self):
        validation.choice("segment", self.segment, SEGMENT_METHODS, error=PerceptionError)
        validation.choice("depth_mode", self.depth_mode, DEPTH_MODES, error=PerceptionError)
        if self.footprint is not None and not isinstance(self.footprint, (bool, np.bool_)):
            raise PerceptionError(f"footprint must be True, False or None, got {self.footprint!r}")
        if self.footprint and self.depth_mode == "plane":
            raise PerceptionError("footprint=True needs depth_mode 'max': a footprint lies on the table, not at the "
                                  "object's top")
        object.__setattr__(self, "footprint", None if self.footprint is None else bool(self.footprint))
        object.__setattr__(self, "fill_holes", validation.flag("fill_holes", self.fill_holes, error=PerceptionError))
        if self.colour_offset_px is not None:
            object.__setattr__(self, "colour_offset_px", validation.pixel_offset(
                "colour_offset_px", self.colour_offset_px, error=PerceptionError))
        offset = validation.finite("approach_offset", self.approach_offset, error=PerceptionError)
        if abs(offset) > MAX_APPROACH_OFFSET:
            raise PerceptionError(f"approach_offset must be within +-{MAX_APPROACH_OFFSET:g} m of the object's top, "
                                  f"got {offset:g} m")
        object.__setattr__(self, "approach_offset", offset)
