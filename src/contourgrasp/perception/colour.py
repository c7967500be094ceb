"""Colour with depth: the colour-depth registration, and the object's parts too flat for depth to see.

Colour-depth registration. The shared PrimeSense pairs are sold as registered,
but an object's outline in depth lies a few pixels above its outline in colour
(docs/perception.md). So ``"auto"`` segmentation first finds that shift where
the object is (:func:`colour_offset`, edge correlation) and moves the colour
image onto the depth image (:func:`register_colour`) before it looks for flat
parts (:func:`add_flat_parts`); masks and contours stay in depth pixels (the
shift is in ``Segmentation.colour_offset_px``).

Flat parts. Depth misses the parts of an object lower than ``min_height`` (a
can opener lying flat: depth sees only its raised grip). The pixels unlike the
table's colour connected to the depth mask are its candidates, of which only
the parts more than ``HALO_PX`` beyond the depth outline and of at least
``min_area_px`` are added: nearer colour evidence is shadow and the object's
side, which the depth outline bounds better. An image without hue (grey: its
three channels equal) cannot tell a light part from a light table by colour;
there the evidence is completed from depth, by the pixels that stand above
the table by more than its noise, however little, less the other objects
standing on the table, and pieces a few pixels from the object
(``FLAT_GAP_PX``) are joined to it: a part's hinge or neck can look like the
table (:func:`add_flat_parts`).
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import cv2
import numpy as np
from scipy import ndimage

from .. import validation
from ..errors import PerceptionError
from ..tolerances import (COLOUR_DISTANCE, EVIDENCE_OPEN_PX, FLAT_GAP_PX, FLAT_HEIGHT_SIGMAS, FLAT_WINDOW_PX, HALO_PX,
                          LIGHTNESS_WEIGHT, MAX_COLOUR_OFFSET_PX, MIN_AREA_PX, MIN_HEIGHT, REGISTRATION_MARGIN_PX,
                          SHADOW_LIGHTNESS)
from ._pixels import components, connected_to, dilate, grown_box, opening, pixel_box
from .camera import as_depth, as_rgb, check_intrinsics, valid_depth
from .region import Segmentation, make_segmentation, pick_object
from .table import above_table_noise, heights, median_heights


def add_flat_parts(
    rgb,
    seg: Segmentation,
    depth=None,
    intrinsics=None,
    *,
    colour_distance: float = COLOUR_DISTANCE,
    lightness_weight: float = LIGHTNESS_WEIGHT,
    shadow_lightness: float = SHADOW_LIGHTNESS,
    halo_px: int = HALO_PX,
    gap_px: int = FLAT_GAP_PX,
    height_sigmas: float = FLAT_HEIGHT_SIGMAS,
    min_height: float = MIN_HEIGHT,
    min_area_px: int = MIN_AREA_PX,
    others=None,
) -> Segmentation:
    """Add to a depth segmentation the parts of the object too flat for depth to see.

    1. Colour evidence: the pixels whose colour is more than
       ``colour_distance`` from the table's, or whose lightness is below
       ``shadow_lightness`` times the table's, opened with a 5 x 5 element to
       drop thin straps and specks. The table's colour is the median CIELAB
       colour of the table-plane inliers ``halo_px`` to ``4 * halo_px``
       pixels around the depth mask; the distance weighs lightness by
       ``lightness_weight``, because a shadow on the table changes its
       lightness far more than its hue. A dark grey part on a light grey
       table differs in lightness only, hence the second test: no soft shadow
       is that dark.
    2. Without hue (every pixel's three channels equal, as a grayscale
       camera stores its image) the first test sees lightness only, which a
       shadow changes as much as a part does: a part as light as the table is
       lost. With ``depth`` the evidence then also holds the pixels whose
       height above the table, median-filtered over 5 x 5 pixels, exceeds
       its median on the same table ring (the surface the object stands on
       there: a bin's floor lies a few millimetres above the table's fitted
       plane) by ``height_sigmas`` times its spread there (1.4826 x the
       median absolute deviation) and by ``MIN_FLAT_HEIGHT``: whatever stands
       above the table's noise, lower than ``min_height`` as it may be. The
       filter cuts the noise about fivefold and keeps a part's edge. Colour
       is not given this test, because a colour image bounds a part more
       sharply than a depth sensor's low steps do.
    3. Without hue and with ``depth``, evidence on another object is
       dropped: a region standing more than ``min_height`` above the table
       outside the depth mask, of at least ``min_area_px``, is a neighbour
       (segmented on its own, or a bin's wall the candidate was split from),
       not a flat part; else the heights of step 2 would reach every neighbour.
    4. The evidence connected to the depth mask; without hue also the pieces
       of at least ``min_area_px`` that come within ``gap_px`` of what is
       joined so far, each joined by the shortest segment across the gap (as
       wide as the narrowest strip the opening keeps): a part's hinge or neck
       may be as light as the table. Colour does not need the gap, and there
       it would join a neighbour's evidence (it lowered the clutter scenes'
       target IoU, ``benchmarks/segmentation.py``).
    5. Flat parts: that evidence farther than ``halo_px`` from the depth
       mask, in pieces of at least ``min_area_px``. Nearer evidence is the
       band of shadow and the object's side seen by a tilted camera, which
       the depth outline already bounds better, and is ignored.
    6. The flat parts (with the evidence within ``halo_px`` of them, which
       joins them to the rest) are added to the depth mask, and the object is
       picked again as in the other methods (largest region not touching the
       image border, holes filled).

    Without flat parts the depth segmentation is returned unchanged.

    :func:`segment` calls this on the region seen above the table
    (``segment_depth(footprint=False)``) with the colour image registered to
    the depth image (:func:`register_colour`) and the hole-filled depth
    image, and takes the footprint of the result afterwards.

    Parameters
    ----------
    rgb : (H, W, 3) uint8
        Colour image in RGB order, registered to the depth image, or (H, W) uint8 grayscale.
    seg : Segmentation
        From :func:`segment_depth` (it needs the table ``plane``), best without the footprint.
    depth : (H, W) or (H, W, 1) float, optional
        Depth in meters (holes filled, as segmented), for steps 2 and 3 (a grey image only).
    intrinsics : Intrinsics, optional
        Of the depth image; needed with ``depth``.
    colour_distance : float
        Euclidean distance in OpenCV's 8-bit CIELAB (L scaled to 0-255), after
        the lightness is multiplied by ``lightness_weight``.
    lightness_weight : float
        Weight of the lightness difference, 0-1.
    shadow_lightness : float
        Fraction of the table's lightness below which a pixel is object, 0-1 (0: no such test).
    halo_px : int
        As above, pixels.
    gap_px : int
        Widest gap joined without hue, pixels (0: none).
    height_sigmas : float
        As above.
    min_height : float
        Height (m) from which a pixel stands on the table, as in :func:`segment_depth`.
    min_area_px : int
        Smallest flat part, smallest piece joined and smallest object, pixels.
    others : (H, W) bool, optional
        Pixels of other objects, which are no part of this one: the objects it touches, split
        from it (:func:`~contourgrasp.perception.split_touching`), stand out from the table's
        colour as much as a flat part does.

    Returns
    -------
    Segmentation
        Method ``"depth+rgb"`` when flat parts were added, else ``seg``.

    Raises
    ------
    SegmentationError
        Kind ``"not-visible"`` when the grown object touches the image border.
    """
    image = as_rgb(rgb)
    validation.same_size(image.shape, seg.mask.shape, "rgb image", "mask", error=PerceptionError)
    colour_distance = validation.positive("colour_distance", colour_distance, error=PerceptionError)
    lightness_weight = validation.fraction("lightness_weight", lightness_weight, error=PerceptionError)
    shadow_lightness = validation.fraction("shadow_lightness", shadow_lightness, error=PerceptionError)
    halo_px = validation.integer("halo_px", halo_px, 1, error=PerceptionError)
    gap_px = validation.integer("gap_px", gap_px, 0, error=PerceptionError)
    height_sigmas = validation.positive("height_sigmas", height_sigmas, error=PerceptionError)
    min_height = validation.positive("min_height", min_height, error=PerceptionError)
    min_area_px = validation.integer("min_area_px", min_area_px, 1, error=PerceptionError)
    if seg.plane is None or seg.plane.inliers.shape != seg.mask.shape:
        raise PerceptionError("add_flat_parts needs a depth segmentation with its table plane")
    d = None if depth is None else _checked_depth(depth, intrinsics, seg.mask.shape)
    grey = not _has_hue(image)
    height = _heights(d, intrinsics, seg.plane) if grey and d is not None else None
    halo = dilate(seg.mask, halo_px)
    unlike = _unlike_table(image, seg.mask, halo, seg.plane.inliers, height, _Evidence(
        colour_distance, lightness_weight, shadow_lightness, halo_px, gap_px if grey else 0, height_sigmas, min_height,
        min_area_px))
    if others is not None:
        validation.same_size(np.shape(others), seg.mask.shape, "others", "mask", error=PerceptionError)
        unlike &= ~np.asarray(others, dtype=bool)
    _, labels, areas = components(unlike & ~halo)
    large = areas >= min_area_px
    large[0] = False
    flat = large[labels]
    if not flat.any():
        return seg
    grown = seg.mask | (unlike & dilate(flat, halo_px))
    mask, notes = pick_object(grown, np.zeros(grown.shape, dtype=bool), min_area_px, "in the depth and colour masks")
    result = make_segmentation("depth+rgb", mask, notes, plane=seg.plane, filled_px=seg.filled_px, on_table=seg.on_table)
    return replace(result, warnings=(*seg.warnings, *result.warnings))


@dataclass(frozen=True)
class _Evidence:
    """The options of :func:`add_flat_parts` that decide its evidence."""

    colour_distance: float
    lightness_weight: float
    shadow_lightness: float
    halo_px: int
    gap_px: int
    height_sigmas: float
    min_height: float
    min_area_px: int


def _has_hue(image) -> bool:
    """Whether an (H, W, 3) image has a pixel whose three channels differ (else it is grey)."""
    return bool(np.any(image[..., 0] != image[..., 1]) or np.any(image[..., 1] != image[..., 2]))


def _checked_depth(depth, intrinsics, shape) -> np.ndarray:
    """(H, W) float: ``depth`` checked against its ``intrinsics`` and the mask's ``shape``."""
    if intrinsics is None:
        raise PerceptionError("add_flat_parts: a depth image needs intrinsics")
    d = as_depth(depth)
    check_intrinsics(intrinsics).check_shape(d.shape, "depth image")
    validation.same_size(d.shape, shape, "depth image", "mask", error=PerceptionError)
    return d


def _heights(depth, intrinsics, plane) -> np.ndarray:
    """(H, W) float: height (m) above ``plane`` of every valid depth pixel, 0 elsewhere."""
    valid = valid_depth(depth)
    return np.where(valid, heights(np.where(valid, depth, 0.0), intrinsics, plane), 0.0)


def _unlike_table(image, depth_mask, halo, table, height, options):
    """(H, W) bool: the evidence of flat parts joined to ``depth_mask`` (without it): steps 1-4 of
    :func:`add_flat_parts`.

    ``halo`` is the depth mask dilated by ``halo_px``; ``height`` the heights
    above the table of steps 2 and 3 (a grey image), or None;
    ``options.gap_px`` is 0 for a colour image. The work is done in a window
    ``FLAT_WINDOW_PX`` beyond the table ring around the depth mask (a
    fraction of the frame), and again on the whole image only when the
    evidence found comes within reach of the opening of the window's edges
    inside the image, where it could continue: the result is the whole
    image's either way (a neighbour cut by the window's edge, which step 3
    may then miss, reaches it too; the median filter's and a gap's reach at
    the edge are covered by that reach).
    """
    window = grown_box(depth_mask, 4 * options.halo_px + FLAT_WINDOW_PX)
    found = _unlike_in(image[window], depth_mask[window], halo[window], table[window],
                       None if height is None else height[window], options)
    if _reaches_inner_edge(found, window, depth_mask.shape, 2 * EVIDENCE_OPEN_PX + 1 + options.gap_px):
        return _unlike_in(image, depth_mask, halo, table, height, options)
    unlike = np.zeros(depth_mask.shape, dtype=bool)
    unlike[window] = found
    return unlike


def _unlike_in(image, depth_mask, halo, table, height, options):
    """:func:`_unlike_table` on the given arrays (the whole image or a window holding the table ring)."""
    lab = cv2.cvtColor(np.ascontiguousarray(image), cv2.COLOR_RGB2LAB)
    ring = dilate(depth_mask, 4 * options.halo_px) & ~halo & table
    if not ring.any():
        return np.zeros(depth_mask.shape, dtype=bool)
    # Squared distance per channel by table look-up, summed: 8-bit values less a median (a multiple
    # of 0.5) square to multiples of 0.25 below 2^16, which float32 and their sum hold exactly.
    table_lab = np.median(lab[ring], axis=0)
    squares = (np.arange(256.0)[:, None] - table_lab) ** 2
    per_channel = cv2.LUT(lab, squares.astype(np.float32)[None])
    weights = np.array([[options.lightness_weight ** 2, 1.0, 1.0]])
    unlike = cv2.transform(per_channel, weights) > np.float64(options.colour_distance) ** 2
    unlike |= lab[..., 0] < options.shadow_lightness * table_lab[0]
    if height is not None:
        unlike |= above_table_noise(median_heights(height), ring, options.height_sigmas)
        unlike &= ~_other_objects(height > options.min_height, depth_mask, options.min_area_px)
    evidence = opening(unlike, EVIDENCE_OPEN_PX) & ~depth_mask
    return _joined(evidence, depth_mask, options.gap_px, options.min_area_px) & ~depth_mask


def _other_objects(standing, mask, min_area_px) -> np.ndarray:
    """(H, W) bool: the 8-connected regions of ``standing`` outside ``mask`` of at least ``min_area_px``.

    Outside the mask, not merely not touching it: a candidate split from a bin's wall
    (:func:`~contourgrasp.perception.candidates.split_at_depth_steps`) touches the wall.
    """
    _, labels, areas = components(standing & ~mask)
    other = areas >= min_area_px
    other[0] = False
    return other[labels]


def _joined(evidence, mask, gap_px, min_area_px) -> np.ndarray:
    """(H, W) bool: ``mask`` with the ``evidence`` connected to it, and the pieces of at least ``min_area_px``
    within ``gap_px`` of what is joined so far, each with the shortest segment across its gap."""
    joined = connected_to(evidence | mask, mask)
    if gap_px == 0:
        return joined
    count, labels, areas = components(evidence & ~joined)
    pending = [i for i in range(1, count) if areas[i] >= min_area_px]
    while pending:
        rows, cols = np.nonzero(np.isin(labels, pending))
        box = pixel_box(rows, cols, gap_px, mask.shape)
        if not joined[box].any():
            break
        distance, nearest = ndimage.distance_transform_edt(~joined[box], return_indices=True)
        reached = [i for i in pending if distance[labels[box] == i].min() <= gap_px]
        if not reached:
            break
        bridges = np.zeros(distance.shape, dtype=np.uint8)
        for i in reached:
            r, c = ndimage.minimum_position(distance, labels[box], i)
            cv2.line(bridges, (int(c), int(r)), (int(nearest[1][r, c]), int(nearest[0][r, c])), 1,
                     2 * EVIDENCE_OPEN_PX + 1)
        joined[box] |= (bridges > 0) | np.isin(labels[box], reached)
        pending = [i for i in pending if i not in reached]
    return joined


def _reaches_inner_edge(region, window, shape, width) -> bool:
    """Whether ``region`` (the ``window`` of an image of ``shape``) has a pixel within ``width`` of a window edge
    that is not the image's edge."""
    rows, cols = window
    return bool((rows.start > 0 and region[:width].any()) or (rows.stop < shape[0] and region[-width:].any())
                or (cols.start > 0 and region[:, :width].any()) or (cols.stop < shape[1] and region[:, -width:].any()))


def colour_offset(rgb, depth, mask, *, max_offset_px: int = MAX_COLOUR_OFFSET_PX) -> tuple[int, int]:
    """The colour-depth misregistration near the object: the shift (dx, dy) that carries colour onto depth.

    Depth pixel (u + dx, v + dy) sees what colour pixel (u, v) sees. Of the
    integer shifts up to ``max_offset_px`` each way, the one at which the two
    images' edges agree best around the object: the normalised
    cross-correlation (OpenCV's ``TM_CCOEFF_NORMED``) of the colour image's
    gradient magnitude (Sobel, summed over the CIELAB channels) with the depth
    image's, over ``mask``'s bounding box grown by ``REGISTRATION_MARGIN_PX``.
    A window without edges in either image gives (0, 0).

    A "registered" PrimeSense pair is not registered to the pixel (module
    docstring); the object's edges are used because the registration error
    of such sensors changes with depth.

    Parameters
    ----------
    rgb : (H, W, 3) uint8
        Colour image in RGB order, or (H, W) uint8 grayscale.
    depth : (H, W) or (H, W, 1) float
        Depth in meters, of the same size; invalid readings are ignored.
    mask : (H, W) bool
        The object as depth sees it.
    max_offset_px : int
        Largest shift searched, pixels.

    Returns
    -------
    (int, int)
        (dx, dy), pixels.

    Examples
    --------
    >>> depth = np.full((120, 160), 0.7); depth[40:80, 50:110] = 0.65
    >>> rgb = np.full((120, 160, 3), 200, np.uint8); rgb[43:83, 48:108] = 30
    >>> colour_offset(rgb, depth, depth < 0.68)
    (2, -3)
    """
    image = as_rgb(rgb)
    d = as_depth(depth)
    validation.same_size(image.shape, d.shape, "rgb image", "depth image", error=PerceptionError)
    validation.same_size(np.shape(mask), d.shape, "mask", "depth image", error=PerceptionError)
    r = validation.integer("max_offset_px", max_offset_px, 0, error=PerceptionError)
    m = np.asarray(mask, dtype=bool)
    if not m.any():
        raise PerceptionError("colour_offset needs a mask with at least one object pixel")
    rows, cols = grown_box(m, REGISTRATION_MARGIN_PX)
    height, width = d.shape
    top, bottom = max(rows.start, r), min(rows.stop, height - r)
    left, right = max(cols.start, r), min(cols.stop, width - r)
    if r == 0 or bottom - top < 3 or right - left < 3:
        return 0, 0
    window = np.s_[top - r: bottom + r, left - r: right + r]
    lab = cv2.cvtColor(image[window], cv2.COLOR_RGB2LAB).astype(np.float32)
    colour_edges = sum(_gradient_magnitude(lab[..., k]) for k in range(3))[r:-r, r:-r]
    near = d[window].astype(np.float32)
    valid = np.isfinite(near) & (near > 0)
    if not valid.any():
        return 0, 0
    near[~valid] = np.median(near[valid])
    depth_edges = _gradient_magnitude(near)
    if colour_edges.std() == 0 or depth_edges.std() == 0:
        return 0, 0
    score = cv2.matchTemplate(depth_edges, colour_edges, cv2.TM_CCOEFF_NORMED)
    dy, dx = np.unravel_index(np.argmax(score), score.shape)
    return int(dx) - r, int(dy) - r


def register_colour(rgb, offset) -> np.ndarray:
    """(H, W, 3) uint8: the colour image shifted by ``offset`` = (dx, dy) onto the depth image (:func:`colour_offset`).

    The strip uncovered at the edge repeats the edge pixels.
    """
    image = as_rgb(rgb)
    dx, dy = offset
    shift = np.array([[1.0, 0.0, dx], [0.0, 1.0, dy]])
    return cv2.warpAffine(image, shift, image.shape[1::-1], flags=cv2.INTER_NEAREST, borderMode=cv2.BORDER_REPLICATE)


def _gradient_magnitude(image):
    return cv2.magnitude(cv2.Sobel(image, cv2.CV_32F, 1, 0), cv2.Sobel(image, cv2.CV_32F, 0, 1))
