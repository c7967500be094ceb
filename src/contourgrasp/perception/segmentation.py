"""Segmentation: the object's mask and outline by the chosen method, and the ``"auto"`` rule.

Methods, each returning a :class:`~contourgrasp.perception.region.Segmentation`:

``"rgb"`` (:func:`~contourgrasp.perception.segment_rgb.segment_rgb`)
    The thesis's steps (3.1).
``"depth"`` (:func:`~contourgrasp.perception.segment_depth.segment_depth`)
    The region standing above the table; with a tilted camera its footprint.
``"auto"`` (:func:`segment`)
    Depth, plus the flat parts found by colour in the colour image registered
    to the depth image (:mod:`contourgrasp.perception.colour`; in a grey image
    also by their few millimetres of height); the RGB steps when depth cannot
    be used.
``"mask"`` (:func:`segment_from_mask`)
    A binary mask given by the user.

The ``"auto"`` rule (our reading; the thesis uses RGB only). Depth first: it
does not see shadows, printed texture or the table's edge, and on the shared
PrimeSense frames it is far nearer to the hand-made masks than the RGB steps
(docs/perception.md), except where the object is partly flat; so, with a
colour image, the flat parts are added by colour. The RGB steps are used when
there is no depth image, no table plane (:class:`SegmentationError` of kind
``"no-plane"``), or nothing of size stands above the table (kinds
``"no-object"``, ``"tiny"``: a flat object), and when every region standing
above the table touches the image border (a robot's arm or fingers in view
beside a flat object): the RGB steps then look for a region wholly in view,
and where they find none the depth's refusal (``"not-visible"``) stands. The
segmentation then carries a warning that says why.
"""

from __future__ import annotations

import warnings
from dataclasses import replace
from typing import Literal

import numpy as np

from .. import validation
from ..errors import PerceptionError, PerceptionWarning, SegmentationError
from ..tolerances import MIN_AREA_PX
from .camera import Intrinsics, as_depth, as_image, check_intrinsics
from .colour import add_flat_parts, colour_offset, register_colour
from .region import Segmentation, make_segmentation, pick_object
from .segment_depth import seen_above_table, segment_depth, with_footprint
from .segment_rgb import segment_rgb


SegmentMethod = Literal["auto", "rgb", "depth"]


SEGMENT_METHODS: tuple[str, ...] = ("auto", "rgb", "depth")


#: SegmentationError kinds after which ``"auto"`` falls back from depth to RGB.
_DEPTH_FALLBACK_KINDS = ("no-plane", "no-object", "tiny")


def segment(
    rgb,
    depth,
    intrinsics: Intrinsics | None,
    *,
    method: SegmentMethod = "auto",
    rgb_options: dict | None = None,
    depth_options: dict | None = None,
    colour_options: dict | None = None,
    colour_offset_px: tuple[int, int] | None = None,
) -> Segmentation:
    """Segment the object with the chosen method.

    Parameters
    ----------
    rgb : (H, W, 3) uint8 or None
        Colour image, RGB order, registered to the depth image.
    depth : (H, W) or (H, W, 1) float or None
        Depth in meters.
    intrinsics : Intrinsics or None
        Needed with depth.
    method : {"auto", "rgb", "depth"}
        ``"auto"``: :func:`segment_depth` when depth and intrinsics are given;
        with a colour image too, the region it sees above the table is grown by
        :func:`add_flat_parts` on the colour image registered to the depth
        image (:func:`colour_offset`, :func:`register_colour`) and, for a grey
        image, on the depth image, before it is moved onto the table; :func:`segment_rgb` when there is no depth, or
        when depth finds no table or nothing standing on it (the module
        docstring explains the rule). The result's ``method`` says what was
        used: ``"depth"``, ``"depth+rgb"`` or ``"rgb"``.
    rgb_options, depth_options, colour_options : dict, optional
        Keyword options of :func:`segment_rgb`, :func:`segment_depth` and
        :func:`add_flat_parts`, checked by name.
    colour_offset_px : (int, int), optional
        ``"auto"`` with colour: the colour-depth shift (dx, dy) if known
        ((0, 0) for a pair registered to the pixel); by default it is
        estimated by :func:`colour_offset`.

    Raises
    ------
    InputError
        Unknown method or option, a missing or mismatched image.
    SegmentationError
        From the method used.
    """
    method = validation.choice("method", method, SEGMENT_METHODS, error=PerceptionError)
    rgb_options = validation.options("rgb_options", rgb_options, segment_rgb, error=PerceptionError)
    depth_options = validation.options("depth_options", depth_options, segment_depth, error=PerceptionError)
    colour_options = validation.options("colour_options", colour_options, add_flat_parts, error=PerceptionError)
    offset = None if colour_offset_px is None else validation.pixel_offset("colour_offset_px", colour_offset_px, error=PerceptionError)
    if depth is not None and intrinsics is None:
        raise PerceptionError("a depth image needs intrinsics")
    if intrinsics is not None:
        check_intrinsics(intrinsics)
    have_depth = depth is not None
    rgb = None if rgb is None else as_image(rgb)
    if rgb is not None and depth is not None:
        validation.same_size(np.shape(rgb), as_depth(depth).shape, error=PerceptionError)
    if method == "rgb" or (method == "auto" and not have_depth):
        if rgb is None:
            raise PerceptionError(f"method {method!r} needs an RGB image" + ("" if method == "rgb" else " or a depth image with intrinsics"))
        return segment_rgb(rgb, **rgb_options)
    if not have_depth:
        raise PerceptionError("method 'depth' needs a depth image and intrinsics")
    if method == "depth" or rgb is None:
        return segment_depth(depth, intrinsics, **depth_options)
    seen_options = {**validation.keyword_defaults(segment_depth), **depth_options}
    footprint, target_px = seen_options.pop("footprint"), seen_options.pop("target_px")
    try:
        seen, d, touched = seen_above_table(depth, intrinsics, **seen_options)
    except SegmentationError as err:
        if err.kind == "not-visible":  # only regions cut by the border stand up: a robot's arm, its fingers
            try:
                result = segment_rgb(rgb, **rgb_options)
            except SegmentationError:
                raise err from None
            note = f"depth saw only regions touching the image border ({err}); used the RGB method instead"
            warnings.warn(note, PerceptionWarning, stacklevel=2)
            return replace(result, warnings=(note, *result.warnings))
        if err.kind not in _DEPTH_FALLBACK_KINDS:
            raise
        note = f"depth segmentation failed ({err}); used the RGB method instead"
    else:
        if offset is None:
            offset = colour_offset(rgb, d, seen.mask)
        grown = add_flat_parts(register_colour(rgb, offset), seen, d, intrinsics,
                               **{"min_height": seen_options["min_height"], "others": touched, **colour_options})
        return with_footprint(replace(grown, colour_offset_px=offset), d, intrinsics, footprint,
                               seen_options["min_area_px"], target_px=target_px)
    result = segment_rgb(rgb, **rgb_options)
    warnings.warn(note, PerceptionWarning, stacklevel=2)
    return replace(result, warnings=(note, *result.warnings))


def segment_from_mask(mask, *, min_area_px: int = MIN_AREA_PX) -> Segmentation:
    """A user's binary mask as a :class:`Segmentation` (method ``"mask"``).

    Non-zero pixels are object. The same rules as the other methods apply:
    the largest region not touching the border, holes filled, a warning when
    there are several of similar size.

    Parameters
    ----------
    mask : (H, W) or (H, W, 1) bool or number
        The object's pixels.
    min_area_px : int
        Smallest object, pixels.
    """
    m = np.asarray(mask)
    if m.ndim == 3 and m.shape[2] == 1:
        m = m[..., 0]
    if m.ndim != 2 or m.size == 0:
        raise PerceptionError(f"mask must be an (H, W) array, got shape {m.shape}")
    if not (m.dtype == bool or np.issubdtype(m.dtype, np.number)):
        raise PerceptionError(f"mask must hold booleans or numbers, got {m.dtype}")
    min_area_px = validation.integer("min_area_px", min_area_px, 1, error=PerceptionError)
    with np.errstate(invalid="ignore"):
        region = np.nan_to_num(m.astype(float)) != 0
    picked, notes = pick_object(region, np.zeros(m.shape, dtype=bool), min_area_px, "in the mask")
    return make_segmentation("mask", picked, notes)
