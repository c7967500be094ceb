"""Every object standing on the support surface, and which one to grasp.

:func:`find_candidates` lists every connected region standing on the support
plane -- the same regions depth segmentation chooses from
(:func:`~contourgrasp.perception.segment_depth.raised_pixels`), each with its
outline, area, height and whether it is wholly in view.
:func:`choose_target` picks one: the candidate under a pixel the user
clicked, the one filling most of a region of interest, or by default by the
``"hand"`` rule: of the wholly visible candidates that fit the hand (the
width of their minimum-area rectangle, in meters, at most the hand's opening),
those at least ``SIMILAR_SIZE`` (half) as large as the largest of them are the
contenders, and the one nearest the image centre wins. The size floor keeps a
stray region from beating the object a user framed; the centre is where a
user points the camera. When no candidate fits the hand, the largest wholly
visible one is taken (the planner will say why it cannot grasp it). With one
object in view this is today's rule, the largest wholly visible region
(section 4.1.3 of the thesis; :func:`~contourgrasp.perception.region.pick_object`),
so a frame with one object plans as before. Regions that touch the image
border (a bin's wall, the robot's own fingers at the image's edge) are listed
but never chosen: they are not a reason to refuse unless the chosen target
touches it.
"""

from __future__ import annotations

from dataclasses import dataclass

import cv2
import numpy as np
from scipy import ndimage

from .. import validation
from ..errors import PerceptionError, SegmentationError
from ..tolerances import (CANDIDATE_DEPTH_STEP, CLICK_REACH_PX, CONTAINER_FLOOR_AREA, ENCLOSED_FRACTION, FLAT_HEIGHT_SIGMAS,
                          LOW_PART_REACH_PX, LOW_PART_STEP, MIN_AREA_PX, MIN_HEIGHT, SENSOR_RANGE,
                          SIMILAR_SIZE)
from ._pixels import check_pixel, connected_to, even_box, fill_holes, stats_in_image
from .camera import Intrinsics, as_depth, check_intrinsics, valid_depth
from .region import mask_contour, touching_regions
from .segment_depth import open_specks, raised_pixels
from .table import Plane, above_table_noise, heights, median_heights

#: The target rules of :func:`choose_target`.
TARGET_RULES: tuple[str, ...] = ("hand", "largest", "centre")


@dataclass(frozen=True, eq=False)
class Candidate:
    """One region standing on the support surface.

    Attributes
    ----------
    label : int
        1, 2, ... in order of decreasing area (ties: image order).
    mask : (H, W) bool
        The region's pixels, its holes filled.
    contour_px : (n, 2) float
        Its outer outline (u, v), as :attr:`Segmentation.contour_px
        <contourgrasp.perception.region.Segmentation>`.
    area_px : int
        Pixels of the region (before its holes are filled: what stands up).
    height : float
        Its highest valid point above the support plane, m.
    centroid_px : (float, float)
        Mean pixel (u, v) of the region.
    bbox : (int, int, int, int)
        Bounding box (x, y, w, h), pixels.
    in_view : bool
        The region touches neither the image border nor the sensor's dead
        band (missing readings connected to the border): it is wholly seen.
    extent : (float, float)
        Length and width (length >= width) of the outline's minimum-area
        rectangle, m, at the region's median depth (pixels x depth / fx):
        the size a hand must span, to a few percent on a tilted camera.
    touching : bool
        Split from a region it shared with an object it touches
        (:func:`~contourgrasp.perception.touching.split_touching`).
    """

    label: int
    mask: np.ndarray
    contour_px: np.ndarray
    area_px: int
    height: float
    centroid_px: tuple[float, float]
    bbox: tuple[int, int, int, int]
    in_view: bool
    extent: tuple[float, float] = (0.0, 0.0)
    touching: bool = False


def find_candidates(
    depth,
    intrinsics: Intrinsics,
    plane: Plane,
    *,
    min_height: float = MIN_HEIGHT,
    min_area_px: int = MIN_AREA_PX,
    depth_range=SENSOR_RANGE,
) -> tuple[Candidate, ...]:
    """Every connected region standing on the support surface.

    The pixels more than ``min_height`` above ``plane``, opened against
    speckle (:func:`~contourgrasp.perception.segment_depth.raised_pixels`,
    what :func:`~contourgrasp.perception.segment_depth.segment_depth`
    chooses from), split into 8-connected regions; those of at least
    ``min_area_px`` pixels are the candidates. An object against a bin's wall
    is one such region with the wall, so a region is also split where the depth
    steps by more than ``tolerances.CANDIDATE_DEPTH_STEP`` between raised
    4-neighbours and one piece then encloses another, or the region closes round a
    container's floor (:func:`split_at_depth_steps`).

    Parameters
    ----------
    depth : (H, W) or (H, W, 1) float
        Depth in meters, small holes already filled if wanted
        (:func:`~contourgrasp.perception.fill_depth_holes`).
    intrinsics : Intrinsics
        Of the depth image.
    plane : Plane
        The support surface (:func:`~contourgrasp.perception.fit_table_plane`).
    min_height : float
        Height above the plane (m) from which a pixel stands on it.
    min_area_px : int
        Smallest candidate, pixels.
    depth_range : (float, float)
        Valid depth readings, m.

    Returns
    -------
    tuple of Candidate
        Largest first; empty when nothing stands on the surface.
    """
    d = as_depth(depth)
    check_intrinsics(intrinsics).check_shape(d.shape, "depth image")
    if not isinstance(plane, Plane):
        raise PerceptionError(f"plane must be a contourgrasp.perception.Plane, got {type(plane).__name__}")
    min_height = validation.positive("min_height", min_height, error=PerceptionError)
    min_area_px = validation.integer("min_area_px", min_area_px, 1, error=PerceptionError)
    above, dead_band = raised_pixels(d, intrinsics, plane, min_height=min_height, depth_range=depth_range)
    count, labels, stats, centroids = split_at_depth_steps(above, d, min_area_px,
                                                           focal=(intrinsics.fx, intrinsics.fy))
    if count == 0:
        return ()
    touching = touching_regions(labels, count, dead_band)
    areas = stats[:, cv2.CC_STAT_AREA]
    valid = valid_depth(d, depth_range)
    with np.errstate(invalid="ignore"):
        h = np.where(valid, heights(d, intrinsics, plane), -np.inf)
    order = [i for i in np.argsort(-areas[1:], kind="stable") + 1 if areas[i] >= min_area_px]
    found = []
    for label, i in enumerate(order, start=1):
        x, y, w, hh = (int(v) for v in stats[i, :4])
        box = np.s_[y:y + hh, x:x + w]  # a region's top and fill on its box only: speckle makes thousands of labels
        top = float(h[box][labels[box] == i].max())
        mask = _filled(labels == i, (x, y, w, hh))
        contour = mask_contour(mask)
        found.append(Candidate(label, mask, contour, int(areas[i]), top,
                               (float(centroids[i, 0]), float(centroids[i, 1])), (x, y, w, hh), not bool(touching[i]),
                               _extent(contour, d[box][labels[box] == i], intrinsics)))
    return tuple(found)


def candidate_from_mask(mask, depth, pixel_heights, intrinsics: Intrinsics, label: int, *,
                        min_height: float = MIN_HEIGHT, within=np.s_[:, :]) -> Candidate:
    """The wholly visible :class:`Candidate` ``label`` whose mask is ``mask`` ((H, W) bool, not empty, inside the
    slices ``within``), as :func:`find_candidates` describes its regions: its pixels more than ``min_height``
    above the support (``pixel_heights``, m) are what stands up."""
    y, x = ndimage.find_objects(mask[within].astype(np.uint8))[0]
    y0, x0 = within[0].start or 0, within[1].start or 0
    y, x = slice(y.start + y0, y.stop + y0), slice(x.start + x0, x.stop + x0)
    with np.errstate(invalid="ignore"):
        raised = mask[y, x] & (pixel_heights[y, x] > min_height)
    rows, cols = np.nonzero(raised if raised.any() else mask[y, x])
    rows, cols = rows + y.start, cols + x.start
    contour = mask_contour(mask)
    return Candidate(label, mask, contour, int(raised.sum()), float(np.nanmax(pixel_heights[rows, cols])),
                     (float(cols.mean()), float(rows.mean())), (x.start, y.start, x.stop - x.start, y.stop - y.start),
                     True, _extent(contour, depth[rows, cols], intrinsics))


def split_at_depth_steps(above, depth, min_area_px: int, *, focal=None):
    """8-connected regions of ``above``, split where the depth steps by more than ``CANDIDATE_DEPTH_STEP``.

    The pixels on either side of such a step between two raised 4-neighbours are cut out; the rest
    falls into 8-connected pieces. A region is split only where one of its pieces of at least
    ``min_area_px`` has another mostly (``ENCLOSED_FRACTION``) inside its filled outline -- a bin's
    walls around an object that touches them -- or, with ``focal``, where the region closes round
    holes of at least ``CONTAINER_FLOOR_AREA`` at its median depth: the walls and an object that
    stands in front of one of them in the view (a tall object seen from a tilted camera hides the
    wall behind it, so the walls' ring is closed only through it). An object's own steps -- a block
    standing on a clamp's body, a lid on a box -- leave pieces side by side around no floor, and the
    region whole. In a split region the cut pixels (and the smaller pieces) go to the nearest large
    piece; a region with no such step is returned exactly as before.

    Parameters
    ----------
    above : (H, W) bool
    depth : (H, W) float
        Depth in meters (valid wherever ``above``).
    min_area_px : int
    focal : (float, float), optional
        The camera's (fx, fy), px: the floor a region closes round in m^2. None: the enclosure test alone.

    Returns
    -------
    count, labels, stats, centroids
        As :func:`cv2.connectedComponentsWithStats` (``count`` without the background), computed on
        ``above``'s bounding box (:func:`~contourgrasp.perception._pixels.even_box`): the labels, boxes
        and centroids are the whole image's, the background's row describes the box's background.

    Examples
    --------
    A 10 cm ring of wall around a box 5 cm tall that touches it is two regions; the same step
    between two surfaces side by side is one object:

    >>> above = np.zeros((60, 60), bool); above[5:55, 5:55] = True; above[10:50, 10:50] = False
    >>> above[20:40, 10:40] = True
    >>> depth = np.full((60, 60), 0.60); depth[20:40, 10:40] = 0.65
    >>> split_at_depth_steps(above, depth, 100)[0]
    2
    >>> side = np.zeros((30, 50), bool); side[5:25, 5:45] = True
    >>> step = np.full((30, 50), 0.60); step[:, 25:] = 0.65
    >>> split_at_depth_steps(side, step, 100)[0]
    1
    """
    labels = np.zeros(above.shape, dtype=np.int32)
    box = even_box(above)
    count, labels[box], stats, centroids = _split_in(above[box], depth[box], min_area_px, focal,
                                                     (box[1].start, box[0].start))
    return count, labels, stats, centroids


def _split_in(above, depth, min_area_px, focal, origin):
    """:func:`split_at_depth_steps` on a box of the image whose corner is at ``origin`` (x, y): the labels on the
    box, the boxes and centroids in the image (the sums of the pixels' image coordinates, as OpenCV's)."""
    step = np.zeros_like(above)
    down = above[:-1] & above[1:] & (np.abs(depth[1:] - depth[:-1]) > CANDIDATE_DEPTH_STEP)
    right = above[:, :-1] & above[:, 1:] & (np.abs(depth[:, 1:] - depth[:, :-1]) > CANDIDATE_DEPTH_STEP)
    step[:-1] |= down
    step[1:] |= down
    step[:, :-1] |= right
    step[:, 1:] |= right
    count, regions, boxes, centroids = cv2.connectedComponentsWithStats(above.astype(np.uint8), connectivity=8)
    whole = count - 1, regions, *stats_in_image(boxes, centroids, origin)
    if not step.any():
        return whole
    _, pieces, stats = cv2.connectedComponentsWithStats((above & ~step).astype(np.uint8), connectivity=8)[:3]
    keep = (stats[:, cv2.CC_STAT_AREA] >= min_area_px)[pieces] & (pieces > 0)
    labels = None
    for region in np.unique(regions[step]):
        x, y, w, h = boxes[region, :4]
        box = np.s_[y:y + h, x:x + w]
        inside, seeds = regions[box] == region, keep[box] & (regions[box] == region)
        if _encloses(pieces[box], seeds, stats, (x, y)) or _holds_floor(inside, depth[box], focal):
            labels = np.where(above, pieces.max() + regions, 0) if labels is None else labels  # the rest stay whole
            rows, cols = ndimage.distance_transform_edt(~seeds, return_distances=False, return_indices=True)
            labels[box][inside] = pieces[box][rows[inside], cols[inside]]
    if labels is None:
        return whole
    values = np.unique(labels[above])
    compact = np.zeros(labels.shape, dtype=np.int32)
    compact[above] = np.searchsorted(values, labels[above]) + 1
    count = len(values)
    rows, cols = np.indices(labels.shape)
    rows, cols = rows + origin[1], cols + origin[0]
    area = np.bincount(compact.ravel(), minlength=count + 1)
    centroids = np.stack([np.bincount(compact.ravel(), cols.ravel(), count + 1),
                          np.bincount(compact.ravel(), rows.ravel(), count + 1)], axis=1) / np.maximum(area, 1)[:, None]
    stats = np.zeros((count + 1, 5), dtype=np.int32)
    for i, found in enumerate(ndimage.find_objects(compact), start=1):
        stats[i] = (found[1].start + origin[0], found[0].start + origin[1], found[1].stop - found[1].start,
                    found[0].stop - found[0].start, area[i])
    return count, compact, stats, centroids


def _holds_floor(region, depth, focal) -> bool:
    """Whether ``region`` (bool, on its box) closes round at least ``CONTAINER_FLOOR_AREA`` m^2 at its median depth."""
    if focal is None:
        return False
    holes = int(fill_holes(region).sum() - region.sum())
    z = float(np.median(depth[region]))
    return holes * z * z >= CONTAINER_FLOOR_AREA * focal[0] * focal[1]


def _encloses(pieces, seeds, stats, origin) -> bool:
    """Whether one labelled piece of ``seeds`` (the region's large pieces) has another mostly inside its filled outline.

    ``pieces`` and ``seeds`` are the region's box at ``origin`` (x, y) of the image, ``stats`` the pieces'
    :func:`cv2.connectedComponentsWithStats` rows in the image: only a piece within another's bounding box can
    be inside its outline, so only such pairs are filled (on that box) and counted.
    """
    found = np.unique(pieces[seeds])
    x, y = stats[found, 0] - origin[0], stats[found, 1] - origin[1]
    w, h = stats[found, 2], stats[found, 3]
    for i, p in enumerate(found):
        within = (x >= x[i]) & (y >= y[i]) & (x + w <= x[i] + w[i]) & (y + h <= y[i] + h[i]) & (found != p)
        if not within.any():
            continue
        box = np.s_[y[i]:y[i] + h[i], x[i]:x[i] + w[i]]
        filled = fill_holes(pieces[box] == p)
        for q in found[within]:
            other = pieces[box] == q
            if (filled & other).sum() > ENCLOSED_FRACTION * other.sum():
                return True
    return False


def _extent(contour_px, region_depth, intrinsics) -> tuple[float, float]:
    """(length, width) in m of the outline's minimum-area rectangle, at the median valid depth of the region."""
    sides = sorted(cv2.minAreaRect(contour_px.astype(np.float32))[1], reverse=True)
    z = region_depth[np.isfinite(region_depth) & (region_depth > 0)]
    scale = float(np.median(z)) / intrinsics.fx if len(z) else 0.0
    return float(sides[0] * scale), float(sides[1] * scale)


def _filled(region, bbox) -> np.ndarray:
    """``region`` with its holes filled, on its bounding box padded by one pixel of background."""
    x, y, w, h = bbox
    box = np.s_[y:y + h, x:x + w]
    out = np.zeros(region.shape, dtype=bool)
    out[box] = fill_holes(region[box])
    return out


def choose_target(candidates, *, target_px=None, roi=None, rule: str = "hand",
                  max_width: float | None = None, pixel_heights=None) -> tuple[Candidate, str]:
    """The candidate to grasp, and why it was chosen (one line).

    Parameters
    ----------
    candidates : sequence of Candidate
        From :func:`find_candidates`.
    target_px : (int, int), optional
        A pixel (u, v): the candidate under it (the user clicked on it).
    roi : (int, int, int, int), optional
        A region of interest (x, y, w, h), pixels: the wholly visible
        candidate with most pixels inside it.
    rule : {"hand", "largest", "centre"}
        Without ``target_px`` and ``roi``: ``"hand"`` (the default) the rule
        of the module docstring; ``"largest"`` the largest wholly visible
        candidate -- the rule of every segmentation method
        (:func:`~contourgrasp.perception.region.pick_object`); ``"centre"``
        the wholly visible candidate whose centroid lies nearest the image
        centre, whatever its size.
    max_width : float, optional
        The ``"hand"`` rule: the widest object the hand spans, m
        (:func:`hand_opening`); None: every candidate fits.
    pixel_heights : (H, W) float, optional
        With ``target_px``: every pixel's height above the support plane, m
        (:func:`~contourgrasp.perception.table.heights`; NaN where unknown). A
        pixel that stands less than ``MIN_HEIGHT`` up but above the table's
        noise lies on a low part of an object -- a fork's handle, a tool's flat
        blade -- which no candidate holds: the target is the candidate that
        part leads to (:func:`low_part_candidate`). None: the candidate under
        the pixel only.

    Returns
    -------
    candidate : Candidate
    reason : str

    Raises
    ------
    PerceptionError
        Both ``target_px`` and ``roi``, a malformed pixel or ROI, an unknown rule.
    SegmentationError
        One line: nothing stands on the surface (``"no-object"``), no object at
        ``target_px`` (the message names the nearest candidate's nearest pixel) or in ``roi`` (``"no-object"``), the target -- or every
        candidate -- touches the image border (``"not-visible"``).
    """
    candidates = tuple(candidates)
    if not all(isinstance(c, Candidate) for c in candidates):
        raise PerceptionError("candidates must be contourgrasp.perception.Candidate objects (find_candidates)")
    if target_px is not None and roi is not None:
        raise PerceptionError("give target_px or roi, not both")
    rule = validation.choice("rule", rule, TARGET_RULES, error=PerceptionError)
    shape = candidates[0].mask.shape if candidates else None
    if target_px is not None:
        pixel = check_pixel(target_px, shape)
        if pixel_heights is not None and candidates:
            validation.same_size(np.shape(pixel_heights), shape, "pixel_heights", "the depth image",
                                 error=PerceptionError)
            found = _beside_in_container(candidates, pixel, pixel_heights)
            if found is not None:
                return found, f"the candidate beside pixel ({pixel[0]}, {pixel[1]}), inside the container clicked in"
            found = low_part_candidate(candidates, pixel, pixel_heights)
            if found is not None:
                return found, f"the candidate the low part under pixel ({pixel[0]}, {pixel[1]}) belongs to"
        return _at_pixel(candidates, pixel, shape)
    if roi is not None:
        return _in_roi(candidates, check_roi(roi, shape))
    if not candidates:
        raise SegmentationError("no-object", "no object found: nothing stands on the support surface")
    inner = [c for c in candidates if c.in_view]
    if not inner:
        largest = max(c.area_px for c in candidates)
        raise SegmentationError(
            "not-visible",
            f"the object is not completely visible: every region on the support surface (the largest {largest} px) "
            f"touches the image border (thesis 4.1.3 assumes the whole object is in view)",
        )
    if rule == "largest":
        return inner[0], f"the largest wholly visible candidate ({inner[0].area_px} px, of {len(candidates)})"
    if rule == "centre":
        return _nearest_centre(inner), f"the wholly visible candidate nearest the image centre (of {len(candidates)})"
    if max_width is not None:
        max_width = validation.positive("max_width", max_width, error=PerceptionError)
    fit = [c for c in inner if max_width is None or c.extent[1] <= max_width]
    if not fit:
        return inner[0], (f"the largest wholly visible candidate ({inner[0].area_px} px, of {len(candidates)}): "
                          f"none is narrower than the hand's opening ({max_width * 1000:.0f} mm)")
    contenders = [c for c in fit if c.area_px >= SIMILAR_SIZE * fit[0].area_px]
    best = _nearest_centre(contenders)
    return best, (f"of the {len(fit)} wholly visible candidate(s) that fit the hand (of {len(candidates)}), "
                  f"the one nearest the image centre among the {len(contenders)} at least "
                  f"{SIMILAR_SIZE:.0%} as large as the largest ({best.area_px} px)")


def _nearest_centre(candidates):
    """The candidate whose centroid lies nearest the image centre."""
    height, width = candidates[0].mask.shape
    centre = np.array([(width - 1) / 2, (height - 1) / 2])
    return min(candidates, key=lambda c: float(np.hypot(*(np.array(c.centroid_px) - centre))))


def hand_opening(hand) -> float:
    """The widest object a hand spans, m: the largest distance between two of its fingers' start points."""
    starts = np.asarray(hand.starts, dtype=float)
    return float(np.max(np.linalg.norm(starts[:, None] - starts[None], axis=-1)))


def check_roi(roi, shape=None) -> tuple[int, int, int, int]:
    """``roi`` as four integers (x, y, w, h), w and h positive, overlapping an image of ``shape`` (H, W) when given."""
    x, y, w, h = validation.integers("roi", roi, "x, y, w, h", error=PerceptionError)
    if w <= 0 or h <= 0:
        raise PerceptionError(f"roi width and height must be positive, got {w}x{h}")
    if shape is not None and (x >= shape[1] or y >= shape[0] or x + w <= 0 or y + h <= 0):
        raise SegmentationError("no-object", f"the ROI ({x}, {y}, {w}, {h}) is outside the {shape[1]}x{shape[0]} image")
    return x, y, w, h


def _beside_in_container(candidates, pixel, pixel_heights) -> Candidate | None:
    """The candidate a click on the support inside a container (a bin's walls) meant, or None.

    A click on an object's inside seen through its opening (a mug's bottom) lands on the support
    when the object's rim is broken by missing readings: the object's filled mask does not hold the
    pixel, the bin's does. When the clicked pixel stands less than ``MIN_HEIGHT`` above the support,
    the innermost candidate holding it encloses others, and one of those comes within
    ``CLICK_REACH_PX`` of the pixel, that nearest one is meant. A click in a roll of tape's eye, with
    nothing inside the tape, stays the tape's.
    """
    u, v = pixel
    if not pixel_heights[v, u] < MIN_HEIGHT:
        return None
    holding = sorted((c for c in candidates if c.mask[v, u]), key=lambda c: int(c.mask.sum()))
    if not holding:
        return None
    container = holding[0]
    inside = [c for c in candidates if c is not container
              and (c.mask & container.mask).sum() > ENCLOSED_FRACTION * c.mask.sum()]
    near = [(np.hypot(*(np.array(_nearest_pixel(c.mask, u, v)) - (u, v))), c) for c in inside]
    near = [(d, c) for d, c in near if d <= CLICK_REACH_PX]
    return min(near, key=lambda dc: dc[0])[1] if near else None


def _at_pixel(candidates, pixel, shape):
    """The innermost candidate under the pixel: an object in a bin lies inside the walls' filled ring too."""
    u, v = pixel
    for c in sorted(candidates, key=lambda c: int(c.mask.sum())):
        if c.mask[v, u]:
            if not c.in_view:
                raise SegmentationError(
                    "not-visible",
                    f"the object at pixel ({u}, {v}) is not completely visible: it touches the image border "
                    f"(thesis 4.1.3 assumes the whole object is in view)",
                )
            return c, f"the candidate under pixel ({u}, {v})"
    if not candidates:
        raise SegmentationError("no-object", f"no object at pixel ({u}, {v}); nothing stands on the support surface")
    cu, cv = min((_nearest_pixel(c.mask, u, v) for c in candidates), key=lambda p: (p[0] - u) ** 2 + (p[1] - v) ** 2)
    raise SegmentationError("no-object", f"no object at pixel ({u}, {v}); the nearest candidate is at ({cu}, {cv})")


def low_part_candidate(candidates, pixel, pixel_heights, *, min_height: float = MIN_HEIGHT,
                       min_area_px: int = MIN_AREA_PX) -> Candidate | None:
    """The candidate a low-lying part under ``pixel`` belongs to, or None when the pixel is not on one.

    Thin parts lying on the table (a fork's handle, a spoon's bowl, a blade)
    stand less than ``min_height`` up, so they are not candidates, and a user
    who clicks on one clicks beside every candidate -- or, in a bin, inside the
    walls' filled ring. Within ``LOW_PART_REACH_PX`` of the pixel the heights
    are median-filtered over 5 x 5 pixels (as the grey images' flat-part
    evidence, :mod:`~contourgrasp.perception.colour`); the pixel is on a low part
    when it stands more than ``FLAT_HEIGHT_SIGMAS`` times the table's spread
    there (its median absolute deviation on the window's pixels below
    ``min_height``, scaled to a Gaussian's sigma; the low part itself is a
    small share of them) above the table's level. The part
    is the 8-connected region of such pixels around it that no candidate
    stands on, and it leads to the candidates it rises into without a step:
    their raised pixels (above ``min_height``, opened 3 x 3 and in a region of
    at least ``min_area_px``, as :func:`find_candidates` has them; not merely
    inside a filled outline) next to it that stand less than
    ``LOW_PART_STEP`` higher. A fork's handle rises into its raised neck; a
    bottle it lies against stands up sharply beside it. The target is the
    candidate so reached nearest the pixel; of candidates nested in one
    another, the innermost.

    Parameters
    ----------
    candidates : sequence of Candidate
    pixel : (int, int)
        (u, v), inside the image.
    pixel_heights : (H, W) float
        Height above the support plane, m (NaN where unknown).
    min_height, min_area_px : float, int
        :func:`find_candidates`': the height from which a pixel stands on the surface (m), and the
        smallest candidate (px). A raised speck smaller than that under the pixel is part of a low part.

    Returns
    -------
    Candidate or None
        None when the pixel stands on a candidate's raised pixels already, is not
        above the table's noise, or its part reaches no candidate within the window.

    Examples
    --------
    >>> import numpy as np
    >>> h = np.zeros((60, 80)); h[20:40, 10:30] = 0.015; h[28:32, 30:70] = 0.005  # a flat block, a thin handle
    >>> block = Candidate(1, h > 0.01, np.zeros((0, 2)), 400, 0.015, (19.5, 29.5), (10, 20, 20, 20), True)
    >>> low_part_candidate([block], (60, 30), h) is block
    True
    >>> low_part_candidate([block], (60, 50), h) is None  # the bare table
    True
    """
    u, v = pixel
    h = np.asarray(pixel_heights)
    box = np.s_[max(v - LOW_PART_REACH_PX, 0):min(v + LOW_PART_REACH_PX + 1, h.shape[0]),
                max(u - LOW_PART_REACH_PX, 0):min(u + LOW_PART_REACH_PX + 1, h.shape[1])]
    at = (v - box[0].start, u - box[1].start)
    window = np.nan_to_num(h[box].astype(np.float32), nan=0.0, posinf=0.0, neginf=0.0)  # the window only
    # raised as find_candidates has it (opened 3 x 3); a speck inside a bin's filled ring is not the ring's
    raised = open_specks(window > min_height)
    standing = _standing(raised, min_area_px)
    if standing[at] and any(c.mask[v, u] for c in candidates):
        return None
    part = _low_part(window, raised, at, min_height) & ~standing
    # where the part rises into a candidate without a step: a neighbour it merely touches stands up sharply there
    joins = cv2.dilate(part.astype(np.uint8), np.ones((3, 3), np.uint8)) > 0
    joins &= standing & (window < min_height + LOW_PART_STEP)
    rows, cols = np.mgrid[box]
    best, nearest = None, np.inf
    for c in sorted(candidates, key=lambda c: int(c.mask.sum())):  # innermost first: it wins a tie
        reached = joins & c.mask[box]
        if reached.any():
            distance = float(np.min((rows[reached] - v) ** 2 + (cols[reached] - u) ** 2))
            if distance < nearest:
                best, nearest = c, distance
    return best


def _low_part(window, raised, at, min_height) -> np.ndarray:
    """(h, w) bool: the 8-connected region around ``at`` of the window's 5 x 5 median heights above the table's
    noise (:func:`low_part_candidate`); empty when ``at`` is not above it."""
    filtered = median_heights(window)
    table = ~raised & (filtered < min_height)  # a bin's floor lies inside the walls' filled ring
    seed = np.zeros(window.shape, dtype=bool)
    if not table.any():
        return seed
    low = above_table_noise(filtered, table, FLAT_HEIGHT_SIGMAS)
    seed[at] = low[at]  # connected_to would keep the background for a seed on it
    return connected_to(low, seed)


def _standing(raised, min_area_px) -> np.ndarray:
    """(h, w) bool: the 8-connected regions of ``raised`` as large as a candidate, or cut by the window's edge."""
    _, labels, stats, _ = cv2.connectedComponentsWithStats(raised.astype(np.uint8), connectivity=8)
    x, y, w, h, area = stats.T
    keep = (area >= min_area_px) | (x == 0) | (y == 0) | (x + w == raised.shape[1]) | (y + h == raised.shape[0])
    keep[0] = False
    return keep[labels]


def _nearest_pixel(mask, u, v) -> tuple[int, int]:
    """The pixel (u', v') of ``mask`` nearest (u, v)."""
    rows, cols = np.nonzero(mask)
    i = int(np.argmin((cols - u) ** 2 + (rows - v) ** 2))
    return int(cols[i]), int(rows[i])


def _in_roi(candidates, roi):
    x, y, w, h = roi
    inside = [(int(c.mask[max(y, 0):y + h, max(x, 0):x + w].sum()), c) for c in candidates]
    visible = [(n, c) for n, c in inside if n > 0 and c.in_view]
    if not visible:
        cut = sum(1 for n, c in inside if n > 0)
        why = f"{cut} region(s) in it touch the image border" if cut else "nothing stands on the support surface there"
        raise SegmentationError("no-object", f"no candidate in the ROI ({x}, {y}, {w}, {h}): {why}")
    n, best = max(visible, key=lambda item: item[0])
    return best, f"the wholly visible candidate with most area in the ROI ({x}, {y}, {w}, {h}): {n} px"
