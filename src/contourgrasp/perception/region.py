"""The object's region in a mask, picked the same way by every segmentation method, and its outline.

Which region is the object: the thesis takes the largest contour (3.1);
section 4.1.3 also assumes the object is completely visible, so every method
takes the largest region that does *not* touch the image border (for depth
also: nor the sensor's dead band of missing readings connected to the
border). On the shared PrimeSense frames the largest contour of the plain RGB
steps is the mat's edge, which touches the border; the next one is the
object. When every candidate touches the border the object is refused as not
completely visible; a second region of at least ``SIMILAR_SIZE`` times the
chosen one's area gives a :class:`~contourgrasp.errors.PerceptionWarning`.
"""

from __future__ import annotations

import warnings
from dataclasses import dataclass

import cv2
import numpy as np

from ..contour.polygon import repair_self_intersections
from ..errors import PerceptionWarning, SegmentationError
from ..tolerances import CONTOUR_EPSILON_PX, MAX_OUTLINE_POINTS, SIMILAR_SIZE
from ._pixels import components, fill_holes
from .table import Plane


@dataclass(frozen=True, eq=False)
class Segmentation:
    """The object found in an image.

    Attributes
    ----------
    method : {"rgb", "depth", "depth+rgb", "mask"}
        The method that produced the mask (for ``"auto"``, the one it used;
        ``"depth+rgb"``: depth with flat parts added by :func:`add_flat_parts`).
    mask : (H, W) bool
        The object's pixels, one connected region with its holes filled.
    contour_px : (n, 2) float
        The mask's outer outline as pixel coordinates (u, v), through the
        centres of the outermost object pixels (so about half a pixel inside
        the true edge), simplified to within ``CONTOUR_EPSILON_PX`` and at most
        ``MAX_OUTLINE_POINTS`` points, its self-intersections repaired; not closed (the first point is not
        repeated), either orientation.
    area_px : int
        Number of mask pixels.
    warnings : tuple of str
        Doubts raised on the way (also issued as :class:`PerceptionWarning`).
    plane : Plane or None
        The table plane, when the depth method found one.
    filled_px : int
        Depth pixels filled by :func:`fill_depth_holes` before segmenting.
    on_table : bool
        The mask is the object's footprint (:func:`object_footprint`): drawn where
        the table is, not where the camera sees the object.
    colour_offset_px : (int, int) or None
        When colour was used with depth: the shift (dx, dy) that carried the
        colour image onto the depth image (:func:`colour_offset`). The mask and
        contour are in depth pixels; on the colour image they lie at
        (u - dx, v - dy).
    """

    method: str
    mask: np.ndarray
    contour_px: np.ndarray
    area_px: int
    warnings: tuple[str, ...] = ()
    plane: Plane | None = None
    filled_px: int = 0
    on_table: bool = False
    colour_offset_px: tuple[int, int] | None = None


def touching_regions(labels, count, outside) -> np.ndarray:
    """(count + 1,) bool: which labels of ``labels`` touch the image border or a pixel of ``outside`` (8-neighbour).

    Entry 0 is the background's. Shared by :func:`pick_object` and
    :func:`~contourgrasp.perception.candidates.find_candidates`.
    """
    beyond = np.pad(outside, 1, constant_values=True).astype(np.uint8)
    near = cv2.dilate(beyond, np.ones((3, 3), np.uint8))[1:-1, 1:-1] > 0
    touching = np.zeros(count + 1, dtype=bool)
    touching[labels[near]] = True
    return touching


def pick_object(candidates, outside, min_area_px, where, target=None):
    """The largest candidate region touching neither the image border nor ``outside``, holes filled; the warnings.

    With ``target`` ((H, W) bool, the mask of a chosen
    :class:`~contourgrasp.perception.candidates.Candidate`) the region that
    overlaps it most is taken instead, and no "similar size" warning is given;
    it must not touch the border or ``outside``.
    """
    count, labels, areas = components(candidates)
    count -= 1
    if count == 0:
        raise SegmentationError("no-object", f"no object found: no region {where}")
    touching = touching_regions(labels, count, outside)
    if target is not None:
        return _pick_target(labels, count, touching, np.asarray(target, dtype=bool), where)
    inner = [i for i in np.argsort(-areas[1:], kind="stable") + 1 if not touching[i]]
    largest_touching = int(areas[1:][touching[1:]].max(initial=0))
    if not inner or areas[inner[0]] < min_area_px <= largest_touching:
        raise SegmentationError(
            "not-visible",
            f"the object is not completely visible: the largest region {where} ({largest_touching} px) touches "
            f"the image border (thesis 4.1.3 assumes the whole object is in view)",
        )
    if areas[inner[0]] < min_area_px:
        raise SegmentationError(
            "tiny", f"object too small: the largest region {where} has {areas[inner[0]]} px, below min_area_px = {min_area_px}"
        )
    notes = []
    similar = [i for i in inner[1:] if areas[i] >= SIMILAR_SIZE * areas[inner[0]]]
    if similar:
        sizes = ", ".join(f"{areas[i]} px" for i in [inner[0], *similar])
        notes.append(f"{len(similar) + 1} regions {where} of similar size ({sizes}): took the largest")
    return _fill_holes(labels == inner[0]), notes


def _pick_target(labels, count, touching, target, where):
    """:func:`pick_object` with a target mask: the region overlapping it most, holes filled; no notes."""
    if target.shape != labels.shape:
        raise SegmentationError("no-object", f"the target mask has shape {target.shape}, the image {labels.shape}")
    overlap = np.bincount(labels[target], minlength=count + 1)
    overlap[0] = 0
    best = int(np.argmax(overlap))
    if overlap[best] == 0:
        raise SegmentationError("no-object", f"no object found: no region {where} under the target")
    if touching[best]:
        raise SegmentationError(
            "not-visible",
            "the object is not completely visible: the target touches the image border "
            "(thesis 4.1.3 assumes the whole object is in view)",
        )
    return _fill_holes(labels == best), []


def _fill_holes(region):
    """(H, W) bool: ``region`` with its holes filled, for a region that does not touch the image border.

    Filled on the region's bounding box grown by one pixel: that frame is
    background connected to the image border, so the holes are the same.
    """
    rows, cols = np.flatnonzero(region.any(axis=1)), np.flatnonzero(region.any(axis=0))
    box = np.s_[rows[0] - 1: rows[-1] + 2, cols[0] - 1: cols[-1] + 2]
    out = np.zeros(region.shape, dtype=bool)
    out[box] = fill_holes(region[box])
    return out


def make_segmentation(method, mask, notes, *, plane=None, filled_px=0, on_table=False, colour_offset_px=None) -> Segmentation:
    """The :class:`Segmentation` of a picked ``mask`` with its outline; each note is also issued as a warning."""
    contour = mask_contour(mask)
    for note in notes:
        warnings.warn(note, PerceptionWarning, stacklevel=3)
    return Segmentation(method, mask, contour, int(mask.sum()), tuple(notes), plane, filled_px, on_table,
                        colour_offset_px)


def mask_contour(mask) -> np.ndarray:
    """(n, 2) float: outer outline (u, v) of a one-region mask, simplified (see :class:`Segmentation`).

    Simplifying and capping a pixel staircase can make the outline cross
    itself where the region is one or two pixels thin; those small loops are
    removed (:func:`contourgrasp.contour.polygon.repair_self_intersections`,
    which keeps the larger part), so that no segmentation is refused for its
    own staircase. A simple outline passes unchanged.

    Raises
    ------
    SegmentationError
        Kind ``"tiny"`` when the region has no interior (a line of pixels).
    """
    contours, _ = cv2.findContours(np.asarray(mask, dtype=np.uint8), cv2.RETR_EXTERNAL, cv2.CHAIN_APPROX_NONE)
    if not contours:
        raise SegmentationError("no-object", "no object found: the mask is empty")
    outline = max(contours, key=cv2.contourArea)
    poly = cv2.approxPolyDP(outline, CONTOUR_EPSILON_PX, True)[:, 0, :].astype(float)
    if len(poly) > MAX_OUTLINE_POINTS:
        poly = poly[np.linspace(0, len(poly), MAX_OUTLINE_POINTS, endpoint=False).astype(int)]
    poly = repair_self_intersections(poly)
    if len(poly) < 3 or cv2.contourArea(poly.astype(np.float32)) <= 0:
        raise SegmentationError("tiny", f"the object's outline has no interior ({len(outline)} pixels in a line)")
    return poly
