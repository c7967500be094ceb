"""Depth segmentation: the region standing above the table, or its footprint on the table (a tilted camera).

Depth does not see shadows, printed texture or the table's edge; it misses
what is lower than ``min_height`` (a flat part), which
:func:`~contourgrasp.perception.colour.add_flat_parts` finds by colour.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import cv2
import numpy as np

from .. import validation
from ..errors import PerceptionError
from ..tolerances import (FOOTPRINT_CELL, FOOTPRINT_CLOSE, FOOTPRINT_MAX_CELLS, HIDDEN_SIDE_TILTS, MAX_HOLE_PX,
                          MIN_AREA_PX, MIN_HEIGHT, MIN_TABLE_HOLE_PX, PLANE_THRESHOLD, SENSOR_RANGE,
                          TILT_PLANE_THRESHOLD)
from ._frame import memoised
from ._pixels import check_pixel, connected_to, disc, fill_holes, grown_box, in_image, pixel_box
from .camera import Intrinsics, as_depth, check_intrinsics, fill_depth_holes, pixel_points, valid_depth
from .region import Segmentation, make_segmentation, pick_object
from .table import Plane, fit_table_plane, footprint_pixels, heights, plane_axes, table_points


def segment_depth(
    depth,
    intrinsics: Intrinsics,
    *,
    min_height: float = MIN_HEIGHT,
    plane: Plane | None = None,
    fill_holes: bool = True,
    max_hole_px: int = MAX_HOLE_PX,
    min_area_px: int = MIN_AREA_PX,
    depth_range=SENSOR_RANGE,
    footprint: bool | None = None,
    seed: int = 0,
    target=None,
    target_px=None,
) -> Segmentation:
    """The region standing above the table, or its footprint on the table.

    Small holes are filled (:func:`fill_depth_holes`, when ``fill_holes``);
    the table is fitted (:func:`fit_table_plane`) unless ``plane`` is given;
    pixels with a valid reading more than ``min_height`` above it are
    candidates, opened with a 3 x 3 element to drop speckle; the object is the
    largest 8-connected candidate region that touches neither the image border
    nor missing readings connected to it (the sensor's dead band), with its
    holes filled. With ``footprint`` that region is then moved onto the table
    (:func:`object_footprint`) and the result is marked ``on_table``.

    By default (``footprint=None``) the footprint is taken when the camera is
    tilted more than ``TILT_PLANE_THRESHOLD`` (2 deg) from the table's normal,
    where the region seen is displaced from where the object stands. A
    top-down camera keeps the thesis's reading, the region seen, which eq
    3.1-3.2 then measure at the table's depth (the outline overstated by
    height / depth); the footprint would measure it exactly, but it lowered
    the success rates of the simulated top-down bench (docs/perception.md),
    so it is an option there (``plan_grasp(footprint=True)``).

    An object, or a part of one, lower than ``min_height`` is invisible to this
    method: the flat metal head of the shared can opener (frame 6) is, and only
    its raised grip is found (:func:`add_flat_parts` finds the rest by colour).

    Parameters
    ----------
    depth : (H, W) or (H, W, 1) float
        Depth in meters.
    intrinsics : Intrinsics
        Of the depth image.
    min_height : float
        Height above the table (m) from which a pixel is object.
    plane : Plane, optional
        The table, if already known.
    fill_holes : bool
        Fill holes of at most ``max_hole_px`` pixels first.
    max_hole_px : int
        See :func:`fill_depth_holes`.
    min_area_px : int
        Smallest object, pixels.
    depth_range : (float, float)
        Valid depth readings, m.
    footprint : bool or None
        Return the object's footprint rather than the pixels that see it;
        None: when the camera is tilted (above).
    seed : int
        RANSAC seed.
    target : (H, W) bool, optional
        The object to take instead of the largest region: the region that
        overlaps this mask most (the ``mask`` of a
        :class:`~contourgrasp.perception.candidates.Candidate` chosen by
        :func:`~contourgrasp.perception.candidates.choose_target`).
    target_px : (int, int), optional
        The pixel (u, v) a user clicked on the object. A candidate may hold neighbours that touch
        in the view (candidates are split only where one encloses another); their footprints then
        fall apart, and the region taken is the one nearest where the clicked point stands on the
        table, not the largest (:func:`with_footprint`).

    Raises
    ------
    SegmentationError
        No table plane, nothing above it, the object touches the border, or it is tiny.
    """
    seen, d, _ = seen_above_table(depth, intrinsics, min_height=min_height, plane=plane, fill_holes=fill_holes,
                                   max_hole_px=max_hole_px, min_area_px=min_area_px, depth_range=depth_range,
                                   seed=seed, target=target)
    return with_footprint(seen, d, intrinsics, footprint, min_area_px, target_px=target_px)


def seen_above_table(depth, intrinsics, *, min_height, plane, fill_holes, max_hole_px, min_area_px, depth_range, seed,
                     target=None):
    """:func:`segment_depth` without the footprint: the region seen above the table, the hole-filled depth, and
    (H, W) bool the raised pixels joined to the ``target`` in the view but not in it: the objects it touches
    (:func:`~contourgrasp.perception.split_touching`; none without a target)."""
    d = as_depth(depth)
    check_intrinsics(intrinsics).check_shape(d.shape, "depth image")
    if plane is not None and not isinstance(plane, Plane):
        raise PerceptionError(f"plane must be a contourgrasp.perception.Plane, got {type(plane).__name__}")
    validation.flag("fill_holes", fill_holes, error=PerceptionError)
    seed = validation.integer("seed", seed, 0, error=PerceptionError)
    min_height = validation.positive("min_height", min_height, error=PerceptionError)
    min_area_px = validation.integer("min_area_px", min_area_px, 1, error=PerceptionError)
    filled = 0
    if fill_holes:
        d, filled = fill_depth_holes(d, max_hole_px=max_hole_px)
    if plane is None:
        plane = fit_table_plane(d, intrinsics, depth_range=depth_range, seed=seed)
    above, dead_band = raised_pixels(d, intrinsics, plane, min_height=min_height, depth_range=depth_range)
    touched = np.zeros(above.shape, dtype=bool)
    if target is not None and np.shape(target) == above.shape:  # (a wrong shape: pick_object's error)
        target = np.asarray(target, dtype=bool)
        touched = connected_to(above, above & target) & ~target
        above = above & target  # a candidate is split from what it touches (find_candidates, split_touching)
    mask, notes = pick_object(above, dead_band, min_area_px,
                               f"more than {min_height * 1000:.0f} mm above the table", target=target)
    return make_segmentation("depth", mask, notes, plane=plane, filled_px=filled), d, touched


def raised_pixels(depth, intrinsics: Intrinsics, plane: Plane, *, min_height: float = MIN_HEIGHT,
                  depth_range=SENSOR_RANGE) -> tuple[np.ndarray, np.ndarray]:
    """The pixels standing on the support surface, and the sensor's dead band.

    Shared by :func:`segment_depth` and
    :func:`~contourgrasp.perception.candidates.find_candidates`.

    Parameters
    ----------
    depth : (H, W) float
        Depth in meters (holes already filled, if wanted).
    intrinsics : Intrinsics
    plane : Plane
        The support surface.
    min_height : float
        Height above ``plane`` (m) from which a pixel stands on it.
    depth_range : (float, float)
        Valid depth readings, m.

    Returns
    -------
    above : (H, W) bool
        Valid pixels more than ``min_height`` above the plane, opened with a
        3 x 3 element to drop speckle.
    dead_band : (H, W) bool
        Missing readings connected (8-neighbour) to the image border: 0, NaN or nearer than the
        range, where a part of the object may hide. Readings beyond the range (a floor behind the
        table, 3 m away in a view at 60 deg) lie behind whatever they border, and are not in it.
    """
    valid = valid_depth(depth, depth_range)

    def dead_band():
        with np.errstate(invalid="ignore"):
            beyond = np.isfinite(depth) & (depth > depth_range[1])
        return _border_connected(~valid & ~beyond)

    def raised():
        with np.errstate(invalid="ignore"):
            above = valid & (heights(depth, intrinsics, plane) > min_height)
        return open_specks(above)

    lo_hi = tuple(map(float, depth_range))
    return (memoised(depth, ("raised", intrinsics, plane.key, float(min_height), lo_hi), raised),
            memoised(depth, ("dead band", lo_hi), dead_band))


def open_specks(above) -> np.ndarray:
    """(H, W) bool: ``above`` opened with a 3 x 3 square, which drops the depth's speckle (:func:`raised_pixels`)."""
    return cv2.morphologyEx(np.asarray(above, dtype=np.uint8), cv2.MORPH_OPEN, np.ones((3, 3), np.uint8)) > 0


def with_footprint(seg, depth, intrinsics, footprint, min_area_px, *, target_px=None) -> Segmentation:
    """``seg`` moved onto the table (:func:`object_footprint`) when ``footprint``, or when None and the camera is
    tilted; either way with the holes through which the table is seen opened again (:func:`open_table_holes`).

    Where the footprint falls into several regions, the largest is taken, or with ``target_px`` (u, v) the one
    nearest the clicked point's own footprint (:func:`clicked_region`)."""
    if target_px is not None:
        target_px = check_pixel(target_px, seg.mask.shape)
    if footprint is None:
        footprint = seg.plane.tilt > TILT_PLANE_THRESHOLD
    elif not isinstance(footprint, (bool, np.bool_)):
        raise PerceptionError(f"footprint must be True, False or None, got {footprint!r}")
    if not footprint:
        return replace(seg, **_opened(seg.mask, depth, intrinsics, seg.plane))
    moved = object_footprint(seg.mask, depth, intrinsics, seg.plane)
    target = None if target_px is None else clicked_region(moved, target_px, depth, intrinsics, seg.plane, min_area_px)
    mask, notes = pick_object(moved, np.zeros_like(moved), min_area_px, "in the object's footprint on the table",
                              target=target)
    result = make_segmentation(seg.method, mask, notes, plane=seg.plane, filled_px=seg.filled_px, on_table=True,
                           colour_offset_px=seg.colour_offset_px)
    return replace(result, warnings=(*seg.warnings, *result.warnings), **_opened(mask, depth, intrinsics, seg.plane))


def clicked_region(footprint, target_px, depth, intrinsics: Intrinsics, plane: Plane, min_area_px: int):
    """(H, W) bool or None: the region of ``footprint`` (8-connected, at least ``min_area_px``) nearest the pixel
    where the point seen at ``target_px`` (u, v) stands on the table; None when that point has no valid depth,
    stands outside the image, or no region is large enough (then the largest region is taken).

    A candidate holding two objects that touch in a tilted view (a bottle standing over scissors) is
    one region seen, two footprints: the click says which object is meant.
    """
    u, v = target_px
    if not valid_depth(depth[v:v + 1, u:u + 1])[0, 0]:
        return None
    inside, fu, fv = in_image(footprint_pixels(depth, intrinsics, plane, np.array([v]), np.array([u])), footprint.shape)
    _, labels, stats, _ = cv2.connectedComponentsWithStats(footprint.astype(np.uint8), connectivity=8)
    large = np.flatnonzero(stats[1:, cv2.CC_STAT_AREA] >= min_area_px) + 1
    if not inside[0] or len(large) < 2:
        return None
    rows, cols = np.nonzero(np.isin(labels, large))
    nearest = np.argmin((rows - fv[0]) ** 2 + (cols - fu[0]) ** 2)
    return labels == labels[rows[nearest], cols[nearest]]


def _opened(mask, depth, intrinsics, plane) -> dict:
    """The ``mask`` and ``area_px`` of a :class:`Segmentation` whose ``mask`` had its table holes opened."""
    opened = open_table_holes(mask, depth, intrinsics, plane)
    return {"mask": opened, "area_px": int(opened.sum())}


def open_table_holes(mask, depth, intrinsics: Intrinsics, plane: Plane, *, min_px: int = MIN_TABLE_HOLE_PX) -> np.ndarray:
    """(H, W) bool: ``mask`` less its holes through which the support surface is seen (a clamp's eye).

    Every method fills the object's holes (:func:`~contourgrasp.perception.region.pick_object`): a
    hole of missing readings or of the object's own shadow is object. A hole of at least ``min_px``
    pixels more than half of whose pixels see the plane (within ``PLANE_THRESHOLD`` of it) shows
    the table through the object and is object-free again. The outline is the outer one either
    way (:attr:`Segmentation.contour_px`), so this changes the mask, not the plan's contour.
    """
    if not mask.any():
        return mask
    box = grown_box(mask, 1)  # holes lie inside the mask's box: the work is done there
    m = mask[box]
    with np.errstate(invalid="ignore"):
        on_plane = m & valid_depth(depth[box]) & (np.abs(heights(depth, intrinsics, plane)[box]) < PLANE_THRESHOLD)
    if not on_plane.any():
        return mask
    standing = m & ~on_plane
    holes = fill_holes(standing) & ~standing
    count, labels = cv2.connectedComponents(holes.astype(np.uint8), connectivity=4)
    size = np.bincount(labels.ravel(), minlength=count)
    seen = np.bincount(labels.ravel(), weights=on_plane.ravel(), minlength=count)
    table = (size >= min_px) & (seen > 0.5 * size)
    table[0] = False
    out = mask.copy()
    out[box] &= ~table[labels]
    return out


def object_footprint(mask, depth, intrinsics: Intrinsics, plane: Plane) -> np.ndarray:
    """Where the table holds what ``mask`` sees: the object's outline as a top-down view measures it.

    A camera that is not top-down sees a tall object's top displaced from its
    base, by height x sin(tilt) / depth x f pixels (8 px for 5 cm at 0.7 m,
    12.7 deg, f = 525 px), sees its near side as well, and does not see its far
    side; a top-down camera sees the top enlarged by depth / (depth - height).
    The footprint undoes the first two and bounds the third:

    1. Every valid pixel of ``mask`` is back-projected and moved along the
       table's normal onto the table, into a grid of ``FOOTPRINT_CELL`` (0.5 mm)
       cells on the table; the cells hit are closed with a disc of
       ``FOOTPRINT_CLOSE`` (4 mm), which joins the samples that steep sides
       spread apart, their holes are filled, and they are grown by half a
       pixel's width on the table (the outermost points seen lie up to a
       pixel inside the object's edge): the *seen footprint*. Where the top
       is seen (most objects, at most tilts), its outline bounds the far side.
    2. At large tilts much of the far side is hidden, and holes in the
       readings (40 % of a 62 deg RealSense frame) leave the seen footprint
       open there: the table points hidden behind the object that lie in its
       visual hull are added (:func:`hidden_side`), the hull of a column as
       tall as the object is seen from ``HIDDEN_SIDE_TILTS[1]`` (35 deg) up, and
       from ``HIDDEN_SIDE_TILTS[0]`` (25 deg) to there of one taller by the
       factor :func:`hidden_side_weight` divides by (twice as tall at 30 deg),
       which adds less of the hidden band: no tilt switches it on or off. A
       mug at 62 deg whose far wall returned no readings is whole. Below 25 deg
       the top seen bounds the far side, and the hull would close the hidden
       gap between touching neighbours and the concavities in an object's own
       shadow (between a tool's head and handle): the rule is not applied.
    3. The footprint is drawn into the image: the pixels whose rays meet the
       table in it.

    What the footprint leaves out stays unknown to the planner: the height map bounds it by the
    camera's rays (:meth:`~contourgrasp.perception.HeightMap.conservative`).

    It is where the object stands, the outline a hand approaching along the
    table's normal closes on, and on the shared PrimeSense frames it is nearer
    to the hand-made masks than the region seen above the table
    (``benchmarks/segmentation.py``, docs/perception.md).

    Parameters
    ----------
    mask : (H, W) bool
        Pixels that see the object.
    depth : (H, W) float
        Depth in meters.
    intrinsics : Intrinsics
        Of the depth image.
    plane : Plane
        The table.

    Returns
    -------
    (H, W) bool
    """
    valid = valid_depth(depth)
    rows, cols = np.nonzero(mask & valid)
    out = np.zeros(mask.shape, dtype=bool)
    if not len(rows):
        return out
    axes = plane_axes(plane.normal)[:, :2]
    points = pixel_points(depth, intrinsics, rows, cols)
    grid = _TableGrid.around((points - plane.height(points)[:, None] * plane.normal) @ axes)
    seen = grid.raster(spacing=float(np.median(points[:, 2])) / intrinsics.fx)
    box = _image_box(grid, axes, plane, intrinsics, mask)
    prow, pcol = np.mgrid[box]
    inside, i, j = grid.cells(table_points(intrinsics, plane, prow, pcol) @ axes)
    out[box] = inside & seen[i, j]
    weight = hidden_side_weight(plane.tilt)
    if weight > 0:
        top = float(np.percentile(plane.height(points), 95))
        out |= hidden_side(mask, intrinsics, plane, top=top / weight)
    return out


def hidden_side_weight(tilt: float) -> float:
    """How much of the hidden side :func:`object_footprint` adds at a camera ``tilt`` (rad): 0 below
    ``HIDDEN_SIDE_TILTS[0]``, 1 above ``HIDDEN_SIDE_TILTS[1]``, linear between; the visual hull's column is the
    object's seen height divided by it.

    >>> round(hidden_side_weight(np.radians(30.0)), 6), hidden_side_weight(0.1), hidden_side_weight(1.0)
    (0.5, 0.0, 1.0)
    """
    low, high = HIDDEN_SIDE_TILTS
    return float(np.clip((tilt - low) / (high - low), 0.0, 1.0))


def hidden_side(mask, intrinsics: Intrinsics, plane: Plane, *, top: float) -> np.ndarray:
    """(H, W) bool: the pixels of ``mask`` whose rays meet the table where the object may stand, unseen.

    The table behind an object is seen by no ray: a ray through a pixel of ``mask`` meets the object
    first, and the table point T where it would have met the table is hidden. T is taken as object
    when the point ``top`` (m) above it -- the object's highest seen height -- projects into ``mask``
    too: the object's visual hull, as tall as it is seen (a lower column there would be allowed as
    well; a taller one would have been seen above the silhouette). Behind a mug seen at 62 deg that is
    its base's far half, up to where its far rim meets the silhouette's edge; behind a box or a lying
    bottle, whose far top edge is the silhouette's, it is nothing.

    Parameters
    ----------
    mask : (H, W) bool
        The pixels that see the object.
    intrinsics : Intrinsics
    plane : Plane
        The table.
    top : float
        The object's height, m.
    """
    rows, cols = np.nonzero(mask)
    raised = table_points(intrinsics, plane, rows, cols) + top * plane.normal
    with np.errstate(divide="ignore", invalid="ignore"):
        ok, u, v = in_image(intrinsics.project(raised), mask.shape)
    ok[ok] = mask[v[ok], u[ok]]
    out = np.zeros(mask.shape, dtype=bool)
    out[rows[ok], cols[ok]] = True
    return out


@dataclass(frozen=True)
class _TableGrid:
    """Cells of side ``cell`` (m) on the table, from ``origin`` (2,), holding the footprints ``xy`` (n, 2)."""

    xy: np.ndarray
    origin: np.ndarray
    cell: float
    shape: tuple

    @classmethod
    def around(cls, xy):
        margin = 2 * FOOTPRINT_CLOSE
        lo, hi = xy.min(axis=0) - margin, xy.max(axis=0) + margin
        cell = max(FOOTPRINT_CELL, float(np.sqrt(np.prod(hi - lo) / FOOTPRINT_MAX_CELLS)))
        shape = tuple(int(n) for n in np.ceil((hi - lo) / cell)[::-1] + 1)  # (rows: y, cols: x)
        return cls(xy, lo, cell, shape)

    def cells(self, xy):
        """Which of the (..., 2) points lie in the grid, and their cells' rows and columns (0 outside)."""
        ij = np.floor((xy - self.origin) / self.cell)
        inside = np.isfinite(ij).all(axis=-1)
        ij = np.where(inside[..., None], ij, 0).astype(int)
        inside &= (ij >= 0).all(axis=-1) & (ij[..., 1] < self.shape[0]) & (ij[..., 0] < self.shape[1])
        ij[~inside] = 0
        return inside, ij[..., 1], ij[..., 0]

    def raster(self, *, spacing: float) -> np.ndarray:
        """(rows, cols) bool: the cells hit, closed, with their holes filled and grown by half the pixels'
        ``spacing`` (m): the outermost points seen lie up to a pixel inside the object's edge, half on average."""
        hit = np.zeros(self.shape, dtype=np.uint8)
        _, i, j = self.cells(self.xy)
        hit[i, j] = 1
        radius = max(1, int(round(FOOTPRINT_CLOSE / self.cell)))
        closed = fill_holes(cv2.morphologyEx(hit, cv2.MORPH_CLOSE, disc(radius)) > 0)
        grow = int(round(0.5 * spacing / self.cell))
        return cv2.dilate(closed.astype(np.uint8), disc(grow)) > 0 if grow else closed


def _image_box(grid, axes, plane, intrinsics, mask):
    """(rows, cols) slices of the image that can see the grid: the box of its corners' pixels and of ``mask``
    (the whole image when a corner is not in front of the camera)."""
    (h, w), lo = grid.shape, grid.origin
    corners = -plane.offset * plane.normal + (lo + np.array([[0, 0], [w, 0], [0, h], [w, h]]) * grid.cell) @ axes.T
    if np.any(corners[:, 2] <= 0):
        return np.s_[:, :]
    u, v = intrinsics.project(corners).T
    rows, cols = np.nonzero(mask)
    rows = np.r_[rows, np.clip(v, -1, mask.shape[0]).astype(int)]
    cols = np.r_[cols, np.clip(u, -1, mask.shape[1]).astype(int)]
    return pixel_box(rows, cols, 1, mask.shape)


def _border_connected(missing) -> np.ndarray:
    """(H, W) bool: the pixels of ``missing`` connected (8-neighbour) to the image border."""
    _, labels = cv2.connectedComponents(np.pad(missing, 1, constant_values=True).astype(np.uint8), connectivity=8)
    return (labels == labels[0, 0])[1:-1, 1:-1]
