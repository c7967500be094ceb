"""Perception: the object's contour and approach depth from one RGB-D frame (thesis 3.1, 3.1.1).

Every function here works on arrays; reading files is :mod:`contourgrasp.io.camera_file`'s job.
One module per stage, in the order the pipeline runs them:

* :func:`one_frame` -- the derived images of the frame being perceived (valid readings, heights)
  computed once for all the stages below
* :mod:`~contourgrasp.perception.camera` -- intrinsics, depth images (validity, hole filling,
  denoising for nearest points), points of pixels, colour images
* :mod:`~contourgrasp.perception.table` -- the table plane (RANSAC), heights above it
* :mod:`~contourgrasp.perception.region` -- picking the object's region in a mask, its outline,
  :class:`Segmentation`
* :mod:`~contourgrasp.perception.segment_rgb` -- the thesis's RGB steps (3.1)
* :mod:`~contourgrasp.perception.segment_depth` -- the region above the table, its footprint
* :mod:`~contourgrasp.perception.candidates` -- every region standing on the table
  (:class:`Candidate`), the target to grasp among them
* :mod:`~contourgrasp.perception.touching` -- a candidate that holds touching objects split where
  colour and surface both change
* :mod:`~contourgrasp.perception.support` -- the support surface (a table or a bin's floor), the
  candidates standing on it (:class:`Support`)
* :mod:`~contourgrasp.perception.colour` -- colour-depth registration, flat parts found by colour
* :mod:`~contourgrasp.perception.segmentation` -- :func:`segment` (the methods and the ``"auto"``
  rule), a user's mask
* :mod:`~contourgrasp.perception.metric` -- pixels to meters in the planning plane (eq 3.1-3.2),
  the approach depth (3.1.1)
* :mod:`~contourgrasp.perception.height_map` -- heights above the table on a grid in the planning
  frame, the object's cells marked (:class:`HeightMap`)
* :mod:`~contourgrasp.perception.cross_section` -- the object's outline at a height, from the height
  map (:func:`cross_section`)
* :mod:`~contourgrasp.perception.view_along` -- the scene seen along a side or tilted approach: the
  target's outline and a height map in the approach's frame (:func:`view_along`)
* :mod:`~contourgrasp.perception.options` -- how a frame is read (:class:`PerceptionOptions`)

Conventions: see :mod:`~contourgrasp.perception.camera`. The thresholds are in
:mod:`contourgrasp.tolerances`; measured results (IoU against the hand-made
masks, timings) in docs/perception.md and ``benchmarks/``.
"""

from __future__ import annotations

from ..errors import PerceptionError, PerceptionWarning, SegmentationError
from ._frame import one_frame
from ._pixels import deepest_pixel
from .camera import Intrinsics, as_depth, backproject, colour_on_depth, denoised_depth, fill_depth_holes, valid_depth
from .candidates import TARGET_RULES, Candidate, choose_target, find_candidates, hand_opening, low_part_candidate
from .colour import add_flat_parts, colour_offset, register_colour
from .cross_section import cross_section
from .height_map import HeightMap, height_map
from .metric import DEPTH_MODES, DepthMode, MetricContour, approach_depth, contour_to_metric
from .options import PerceptionOptions
from .region import Segmentation, mask_contour
from .segment_depth import hidden_side, object_footprint, open_table_holes, segment_depth
from .segment_rgb import segment_rgb
from .segmentation import SEGMENT_METHODS, SegmentMethod, segment, segment_from_mask
from .support import Support, find_support
from .table import Plane, fit_plane, fit_table_plane
from .touching import split_touching
from .view_along import Approach, ApproachView, view_along

__all__ = [
    "Approach", "ApproachView", "Candidate", "DEPTH_MODES", "DepthMode", "HeightMap", "Intrinsics", "MetricContour", "PerceptionError", "PerceptionOptions", "PerceptionWarning", "Plane",
    "SEGMENT_METHODS", "SegmentMethod", "Segmentation", "SegmentationError", "Support", "TARGET_RULES", "add_flat_parts", "approach_depth",
    "as_depth", "backproject", "choose_target", "colour_on_depth", "colour_offset", "contour_to_metric", "denoised_depth", "fill_depth_holes",
    "cross_section", "deepest_pixel", "find_candidates", "find_support", "fit_plane", "fit_table_plane", "hand_opening", "height_map", "hidden_side", "low_part_candidate", "mask_contour", "object_footprint", "one_frame", "open_table_holes", "register_colour", "segment",
    "segment_depth", "segment_from_mask", "segment_rgb", "split_touching", "valid_depth", "view_along",
]
