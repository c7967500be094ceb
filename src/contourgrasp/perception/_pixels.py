"""Small helpers on masks and pixels shared by the perception stages: boxes, morphology, connectivity."""

from __future__ import annotations

import cv2
import numpy as np

from .. import validation
from ..errors import PerceptionError, SegmentationError


def connected_to(region, mask):
    """(H, W) bool: the 8-connected parts of ``region`` that hold a pixel of ``mask`` (a subset of it)."""
    count, labels = cv2.connectedComponents(region.astype(np.uint8), connectivity=8)
    keep = np.zeros(count, dtype=bool)
    keep[labels[mask]] = True
    return keep[labels]


def components(mask):
    """(count, labels, areas): the 8-connected regions of ``mask``, labelled as
    :func:`cv2.connectedComponentsWithStats` labels them (0 the background, counted in ``count``),
    and each label's pixels.

    OpenCV's statistics (every label's box and centroid, the background's too) cost several
    times the labelling; where only areas are needed they are one bincount. Both run on the
    mask's :func:`even_box` only (an object is a few percent of a frame).

    Examples
    --------
    >>> mask = np.zeros((4, 6), bool); mask[1, 1] = True; mask[1:3, 3:5] = True
    >>> count, labels, areas = components(mask)
    >>> int(count), areas.tolist()
    (3, [19, 1, 4])
    """
    mask = np.asarray(mask, dtype=bool)
    labels = np.zeros(mask.shape, dtype=np.int32)
    box = even_box(mask)
    count, labels[box] = cv2.connectedComponents(mask[box].astype(np.uint8), connectivity=8)
    areas = np.bincount(labels[box].ravel(), minlength=count)
    areas[0] += mask.size - labels[box].size
    return count, labels, areas


def even_box(mask):
    """(rows, cols) slices of ``mask``'s bounding box, its corner moved to an even row and column; the whole
    image for an empty mask.

    OpenCV's connected components scan 2 x 2 blocks and number the labels in that scan's order, so
    labelled on this box a mask's labels are numbered as on the whole image (tested).
    """
    if not mask.any():
        return slice(0, mask.shape[0]), slice(0, mask.shape[1])
    rows, cols = grown_box(mask, 0)
    return slice(rows.start - rows.start % 2, rows.stop), slice(cols.start - cols.start % 2, cols.stop)


def stats_in_image(boxes, centroids, origin):
    """OpenCV's ``boxes`` and ``centroids`` of a box at ``origin`` (x, y), in the image.

    A centroid is an integer sum over the area, which the box's centroid times the area gives back
    exactly; shifted, it is divided as OpenCV divides it, so the image's centroids are its own to the bit.
    """
    boxes = boxes.copy()
    boxes[:, cv2.CC_STAT_LEFT] += origin[0]
    boxes[:, cv2.CC_STAT_TOP] += origin[1]
    area = boxes[:, cv2.CC_STAT_AREA].astype(float)[:, None]
    sums = np.rint(centroids * area) + area * np.asarray(origin, dtype=float)
    return boxes, sums / np.maximum(area, 1)


def deepest_pixel(mask) -> tuple[int, int]:
    """The pixel (u, v) of a non-empty (H, W) bool ``mask`` farthest from its edge (a distance transform's maximum,
    the first in image order on ties): where to click on an object."""
    distance = cv2.distanceTransform(np.pad(np.asarray(mask, dtype=np.uint8), 1), cv2.DIST_L2, 5)[1:-1, 1:-1]
    v, u = np.unravel_index(int(np.argmax(distance)), distance.shape)
    return int(u), int(v)


def disc(radius):
    """OpenCV's elliptic structuring element of ``radius`` px."""
    return cv2.getStructuringElement(cv2.MORPH_ELLIPSE, (2 * radius + 1, 2 * radius + 1))


def dilate(mask, radius):
    """(H, W) bool: ``mask`` dilated by a disc of ``radius`` px."""
    return morph(cv2.MORPH_DILATE, mask, radius)


def opening(mask, radius):
    """(H, W) bool: ``mask`` opened by a disc of ``radius`` px (drops parts thinner than the disc)."""
    return morph(cv2.MORPH_OPEN, mask, radius)


def morph(operation, mask, radius):
    """(H, W) bool: ``mask`` dilated or opened by a disc, as OpenCV does it on the whole image.

    The operation runs on the mask's bounding box grown by ``radius`` only: the
    result is empty farther out, and within the box every disc around a mask
    pixel is inside it (or beyond the image's edge, as on the whole image).
    """
    out = np.zeros(mask.shape, dtype=bool)
    if mask.any():
        box = grown_box(mask, radius)
        out[box] = cv2.morphologyEx(mask[box].astype(np.uint8), operation, disc(radius)) > 0
    return out


def grown_box(mask, margin):
    """(rows, cols) slices of ``mask``'s bounding box grown by ``margin`` px, within the image; ``mask`` is not empty."""
    return pixel_box(np.flatnonzero(mask.any(axis=1)), np.flatnonzero(mask.any(axis=0)), margin, mask.shape)


def pixel_box(rows, cols, margin, shape):
    """(rows, cols) slices of the bounding box of the pixels (rows, cols), not empty, grown by ``margin`` px,
    within an image of ``shape``."""
    return (slice(max(rows.min() - margin, 0), min(rows.max() + margin + 1, shape[0])),
            slice(max(cols.min() - margin, 0), min(cols.max() + margin + 1, shape[1])))


def in_image(uv, shape):
    """Which of the (n, 2) float pixels round to a pixel of an image of ``shape``, and their columns and rows."""
    seen = np.isfinite(uv).all(axis=1)
    u, v = np.zeros(len(uv), dtype=int), np.zeros(len(uv), dtype=int)
    u[seen], v[seen] = np.rint(uv[seen]).astype(int).T
    seen &= (u >= 0) & (u < shape[1]) & (v >= 0) & (v < shape[0])
    return seen, u, v


def check_pixel(target_px, shape=None) -> tuple[int, int]:
    """``target_px`` as two integers (u, v), inside an image of ``shape`` (H, W) when given."""
    u, v = validation.integers("target_px", target_px, "u, v", error=PerceptionError)
    if shape is not None and not (0 <= u < shape[1] and 0 <= v < shape[0]):
        raise SegmentationError("no-object", f"pixel ({u}, {v}) is outside the {shape[1]}x{shape[0]} image")
    return u, v


def fill_holes(mask) -> np.ndarray:
    """(h, w) bool: ``mask`` with its holes filled -- :func:`scipy.ndimage.binary_fill_holes`' result (the background
    not 4-connected to the outside), by one flood fill from outside the border (a tenth of its time on a box).

    >>> ring = np.zeros((5, 5), bool); ring[1:4, 1:4] = True; ring[2, 2] = False
    >>> bool(fill_holes(ring)[2, 2]), int(fill_holes(ring).sum())
    (True, 9)
    """
    m = np.asarray(mask, dtype=bool)
    padded = np.zeros((m.shape[0] + 2, m.shape[1] + 2), np.uint8)
    padded[1:-1, 1:-1] = m
    cv2.floodFill(padded, None, (0, 0), 2, flags=4)
    return padded[1:-1, 1:-1] != 2
