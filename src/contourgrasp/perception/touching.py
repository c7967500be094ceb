"""Touching objects: a candidate split where both its colour and its surface change.

Depth alone joins objects that touch: a clamp lying across a bottle, a cup behind a bowl in an
oblique view, are one raised region (:func:`~contourgrasp.perception.candidates.find_candidates`
splits only a bin's walls from what leans on them). :func:`split_touching` splits such a region in
two where two things hold together:

* **Colour**: its pixels fall into two colour clusters (k-means on CIELAB, 5 x 5 median-filtered)
  that differ in the surface's colour more than lighting changes it: their chromaticities (CIELAB
  a, b) lie at least ``TOUCHING_CHROMA`` apart, or one reflects at least ``TOUCHING_ALBEDO_RATIO``
  times the light of the other (linear luminance). Shading on one surface changes both less on
  the shared real frames (a mug's inside and outside: chroma 1, luminance 2.2 times).
* **Surface**: where the two clusters meet (bands ``TOUCHING_BAND_PX`` wide on either side) the
  surface steps -- at the median pixel of the bands the heights above the support within 5 x 5 px
  span at least ``TOUCHING_STEP`` -- and does not fold outward: the bands' mean points and normals
  are not locally convex (Stein et al., CVPR 2014, LCCP; :func:`_convex`). One object lies on, or
  in an oblique view in front of, the other (on the shared frames -0.8 to 0.1). A two-coloured
  object's parts meet on one surface -- a bottle's cap, a drill's grip (4 to 8 mm on the shared
  frames) -- and a can's lit top and dark side wall, seen from above, at a convex edge: each stays
  whole.

Each cluster's largest 8-connected piece (opened 5 x 5) must hold ``min_area_px`` and
``TOUCHING_MIN_SHARE`` of the region; every pixel of the region then goes to the piece nearest it.
A piece is split again the same way, up to ``MAX_TOUCHING_PIECES`` pieces per region. Only wholly
visible candidates are split (the others are never targets). No rendered single YCB object is split
(288 frames, tilts 0-60 deg, docs/perception.md).

Not done: objects of one colour that touch stay one candidate (their concave crease alone is not
taken as a boundary: a mug's handle meets its body in one too).
"""

from __future__ import annotations

from dataclasses import replace

import cv2
import numpy as np
from scipy import ndimage

from .. import validation
from ..errors import PerceptionError
from ..tolerances import (MAX_TOUCHING_PIECES, MIN_AREA_PX, MIN_HEIGHT, TOUCHING_ALBEDO_RATIO, TOUCHING_BAND_PX,
                          TOUCHING_CHROMA, TOUCHING_CONVEX, TOUCHING_MIN_SHARE, TOUCHING_STEP)
from .camera import Intrinsics, as_depth, as_rgb, check_intrinsics, pixel_points_at
from .candidates import Candidate, candidate_from_mask
from .colour import colour_offset
from .table import Plane, heights

_KMEANS_CRITERIA = (cv2.TERM_CRITERIA_EPS + cv2.TERM_CRITERIA_MAX_ITER, 20, 0.5)
#: At most this many pixels of a region are clustered (every k-th); all are then assigned.
_KMEANS_SAMPLES = 2000


def split_touching(candidates, rgb, depth, intrinsics: Intrinsics, plane: Plane, *, colour_offset_px=None,
                   min_area_px: int = MIN_AREA_PX) -> tuple[Candidate, ...]:
    """The candidates with every wholly visible one that holds touching objects split (module docstring).

    Parameters
    ----------
    candidates : sequence of Candidate
        From :func:`~contourgrasp.perception.candidates.find_candidates` on ``depth`` and ``plane``.
    rgb : (H, W, 3) or (H, W) uint8
        Colour on the depth image's grid (:func:`~contourgrasp.perception.colour_on_depth`).
    depth : (H, W) float
        The depth image the candidates were found on, m.
    intrinsics : Intrinsics
    plane : Plane
        The support surface.
    colour_offset_px : (int, int), optional
        The shift (dx, dy) that moves the colour onto the depth, px
        (:func:`~contourgrasp.perception.register_colour`); None: estimated on each candidate
        (:func:`~contourgrasp.perception.colour_offset`).
    min_area_px : int
        Smallest piece, pixels.

    Returns
    -------
    tuple of Candidate
        Largest first and labelled 1, 2, ... again; a split region's pieces have ``touching`` set.
        The same candidates when none is split.
    """
    candidates = tuple(candidates)
    if not all(isinstance(c, Candidate) for c in candidates):
        raise PerceptionError("candidates must be contourgrasp.perception.Candidate objects (find_candidates)")
    image = as_rgb(rgb)
    d = as_depth(depth)
    check_intrinsics(intrinsics).check_shape(d.shape, "depth image")
    validation.same_size(image.shape, d.shape, "rgb image", "depth image", error=PerceptionError)
    min_area_px = validation.integer("min_area_px", min_area_px, 1, error=PerceptionError)
    if colour_offset_px is not None:
        colour_offset_px = validation.pixel_offset("colour_offset_px", colour_offset_px, error=PerceptionError)
    tried = [c.in_view and c.area_px >= 2 * min_area_px for c in candidates]
    if not any(tried):
        return candidates
    h = heights(d, intrinsics, plane)
    found, split = [], False
    for c, to_try in zip(candidates, tried, strict=True):
        if not to_try:
            found.append(c)
            continue
        # each its own: the colour-depth shift varies across a frame by several pixels (parallax, misregistration)
        offset = colour_offset(image, d, c.mask) if colour_offset_px is None else colour_offset_px
        box = _grown(c.bbox, d.shape)
        rows, cols = np.mgrid[box]
        points = pixel_points_at(d[box], intrinsics, rows, cols)
        pieces = _pieces(c.mask[box], _lab(image, offset, box), h[box], points, min_area_px)
        split |= len(pieces) > 1
        found.extend(c if len(pieces) == 1 else
                     replace(candidate_from_mask(_in_image(p, box, d.shape), d, h, intrinsics, c.label, within=box),
                             touching=True)
                     for p in pieces)
    if not split:
        return candidates
    order = sorted(found, key=lambda c: (-c.area_px, c.bbox[1], c.bbox[0]))
    return tuple(replace(c, label=i) for i, c in enumerate(order, start=1))


def _grown(bbox, shape) -> tuple[slice, slice]:
    """A candidate's bounding box (x, y, w, h) grown by 3 px, as slices of an image of ``shape``."""
    x, y, w, h = bbox
    return np.s_[max(y - 3, 0):min(y + h + 3, shape[0]), max(x - 3, 0):min(x + w + 3, shape[1])]


def _in_image(piece, box, shape) -> np.ndarray:
    """(H, W) bool: ``piece`` (bool, on ``box``) in an image of ``shape``."""
    out = np.zeros(shape, dtype=bool)
    out[box] = piece
    return out


def _lab(image, offset, box) -> np.ndarray:
    """(h, w, 3) float32: CIELAB (OpenCV's 8-bit scale), 5 x 5 median-filtered, of the colour image shifted by
    ``offset`` (dx, dy) px onto the depth image (:func:`~contourgrasp.perception.register_colour`), on the depth's
    ``box``; the edge repeats beyond the image."""
    rows = np.clip(np.arange(box[0].start, box[0].stop) - offset[1], 0, image.shape[0] - 1)
    cols = np.clip(np.arange(box[1].start, box[1].stop) - offset[0], 0, image.shape[1] - 1)
    colour = np.ascontiguousarray(image[np.ix_(rows, cols)])
    return cv2.cvtColor(cv2.medianBlur(colour, 5), cv2.COLOR_RGB2Lab).astype(np.float32)


def _pieces(region, lab, h, points, min_area_px) -> list[np.ndarray]:
    """``region`` (bool, on a box) split into the pieces of touching objects, at most ``MAX_TOUCHING_PIECES``;
    ``lab``, the heights ``h`` and the camera-frame ``points`` on the same box."""
    todo, done = [region], []
    while todo:
        piece = todo.pop()
        halves = None
        if len(done) + len(todo) + 2 <= MAX_TOUCHING_PIECES:
            halves = _split(piece, lab, h, points, min_area_px)
        if halves is None:
            done.append(piece)
        else:
            todo.extend(halves)
    return done


def _split(region, lab, h, points, min_area_px):
    """The two halves of ``region`` (bool, on its box) where colour and surface both change, or None."""
    raised = region & (h > MIN_HEIGHT)  # not the holes filled in the candidate's mask: the table seen through them
    pixels = lab[raised]
    if len(pixels) < 2 * min_area_px:
        return None
    sample = pixels[::max(len(pixels) // _KMEANS_SAMPLES, 1)]
    cv2.setRNGSeed(0)
    _, _, centres = cv2.kmeans(sample, 2, None, _KMEANS_CRITERIA, 2, cv2.KMEANS_PP_CENTERS)
    if not _surfaces_differ(centres):
        return None
    nearer = np.linalg.norm(lab - centres[0], axis=-1) < np.linalg.norm(lab - centres[1], axis=-1)
    a = _largest_piece(raised & nearer)
    b = _largest_piece(raised & ~nearer)
    least = max(min_area_px, TOUCHING_MIN_SHARE * raised.sum())
    if a.sum() < least or b.sum() < least:
        return None
    seam_a, seam_b = _seam(a, b)
    if not _steps(seam_a | seam_b, a | b, h) or _convex(seam_a, seam_b, points):
        return None
    rows, cols = ndimage.distance_transform_edt(~(a | b), return_distances=False, return_indices=True)
    to_a = a[rows, cols]
    return region & to_a, region & ~to_a


def _surfaces_differ(centres) -> bool:
    """Whether two CIELAB colours (OpenCV's 8-bit scale) differ in chromaticity or albedo, not in lighting."""
    chroma = float(np.linalg.norm(centres[0, 1:] - centres[1, 1:]))
    luminance = ((centres[:, 0] / 2.55 + 16.0) / 116.0) ** 3  # CIE L* to linear Y (L* > 8)
    return chroma >= TOUCHING_CHROMA or float(luminance.max() / luminance.min()) >= TOUCHING_ALBEDO_RATIO


def _largest_piece(pixels) -> np.ndarray:
    """The largest 8-connected piece of ``pixels`` opened 5 x 5 (empty when none)."""
    opened = cv2.morphologyEx(pixels.astype(np.uint8), cv2.MORPH_OPEN, np.ones((5, 5), np.uint8))
    count, labels, stats, _ = cv2.connectedComponentsWithStats(opened, connectivity=8)
    if count < 2:
        return np.zeros_like(pixels)
    return labels == 1 + int(np.argmax(stats[1:, cv2.CC_STAT_AREA]))


def _seam(a, b) -> tuple[np.ndarray, np.ndarray]:
    """The pixels of ``a`` within ``TOUCHING_BAND_PX`` of ``b``, and of ``b`` within it of ``a``."""
    grow = np.ones((2 * TOUCHING_BAND_PX + 1,) * 2, np.uint8)
    return a & (cv2.dilate(b.astype(np.uint8), grow) > 0), b & (cv2.dilate(a.astype(np.uint8), grow) > 0)


def _steps(seam, region, h) -> bool:
    """Whether the surface steps at the ``seam``: the heights ``h`` (m) within 5 x 5 px of a pixel of the
    ``region`` span at least ``TOUCHING_STEP`` at the seam's median pixel."""
    if not seam.any():
        return False
    square = np.ones((5, 5), np.uint8)
    top = cv2.dilate(np.where(region, h, -np.inf).astype(np.float32), square)
    bottom = -cv2.dilate(np.where(region, -h, -np.inf).astype(np.float32), square)
    return float(np.median(top[seam] - bottom[seam])) >= TOUCHING_STEP


def _convex(seam_a, seam_b, points) -> bool:
    """Whether the surface folds outward where ``a`` meets ``b``: one object's edge, a can's top and its side.

    The locally convex connection of Stein et al. (CVPR 2014, LCCP): with the seams' mean points
    x_a, x_b and mean normals n_a, n_b (towards the camera), (n_a - n_b) . (x_a - x_b) / |x_a - x_b|
    is at least ``TOUCHING_CONVEX``. A top face and its side (normals 90 deg apart) give about 0.7;
    an object lying on another (both tops facing up) or standing in front of it about 0.
    """
    normals = _normals(points)
    inside_a, inside_b = seam_a & np.isfinite(normals[..., 0]), seam_b & np.isfinite(normals[..., 0])
    if not inside_a.any() or not inside_b.any():
        return False
    n_a, n_b = normals[inside_a].mean(axis=0), normals[inside_b].mean(axis=0)
    gap = points[inside_a].mean(axis=0) - points[inside_b].mean(axis=0)
    length = float(np.linalg.norm(gap))
    return length > 0 and float((n_a - n_b) @ gap) / length >= TOUCHING_CONVEX


def _normals(points) -> np.ndarray:
    """(h, w, 3): unit surface normals of camera-frame ``points`` (h, w, 3), towards the camera; NaN where unknown."""
    smooth = cv2.blur(points.astype(np.float32), (3, 3))
    normals = np.cross(np.gradient(smooth, axis=1), np.gradient(smooth, axis=0))
    with np.errstate(invalid="ignore", divide="ignore"):
        normals /= np.linalg.norm(normals, axis=-1, keepdims=True)
    flip = np.sum(normals * points, axis=-1) > 0
    normals[flip] *= -1
    return normals
