"""The contour in meters and the approach depth (thesis 3.1 eq 3.1-3.2, 3.1.1), in the plane the hand plans in.

Tilted cameras: the thesis plans in a plane parallel to the image plane, which
only works when that plane is parallel to the table; a tilted camera's contour
is planned in the table's plane instead (:func:`contour_to_metric`).
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass
from typing import Literal

import cv2
import numpy as np

from .. import validation
from ..errors import PerceptionError, PerceptionWarning, SegmentationError
from ..tolerances import APPROACH_OFFSET, MIN_RAY_COSINE, PLANE_THRESHOLD, SENSOR_RANGE, TILT_PLANE_THRESHOLD, TILT_WARN
from ._pixels import connected_to, in_image
from .camera import Intrinsics, as_depth, check_intrinsics, denoised_at, pixel_points, pixel_points_at, valid_depth
from .table import IMAGE_PLANE, Plane, fit_table_plane, footprint_pixels, heights, plane_axes


DepthMode = Literal["max", "plane"]


DEPTH_MODES: tuple[str, ...] = ("max", "plane")


@dataclass(frozen=True, eq=False)
class MetricContour:
    """The object's contour in meters, in the frame the hand plans in.

    The planning frame has its x and y axes in the plane the contour was
    projected on and its z axis, the hand's approach direction, pointing away
    from the camera along that plane's normal. Without tilt it *is* the
    camera frame shifted along the optical axis (thesis eq 3.1-3.2).

    Attributes
    ----------
    contour_xy : (n, 2) float
        Contour points (x, y) in the planning frame, m, in the order of the pixel contour.
    R_camera_plane : (3, 3) float
        Rotation from the planning frame to the camera frame: its columns are
        the planning x, y, z axes in camera coordinates.
    origin : (3,) float
        Camera-frame position of the planning frame's origin: where the
        optical axis meets the contour's plane.
    z_max : float
        Largest valid depth on the contour pixels, m (eq 3.1-3.2).
    approach_depth : float
        How far the hand travels from the camera along the approach axis
        (planning z) before the grasp: the nearest valid point within or on
        the contour (on the depth median-filtered 3 x 3, :func:`denoised_depth`),
        plus the offset (section 3.1.1), m.
    invalid_depth_px : int
        Contour pixels without a valid depth reading.
    tilt : float or None
        Angle between the table's normal and the optical axis, rad; None when
        no table plane was known.
    frame : {"camera", "table"}
        ``"camera"``: the thesis's plane parallel to the image plane (tilt at
        most ``TILT_PLANE_THRESHOLD`` or unknown); ``"table"``: a plane
        parallel to the table.
    depth_mode : {"max", "plane"}
        Which height the contour was placed at (see :func:`contour_to_metric`).
    on_table : bool
        The contour was a footprint, placed on the table itself.
    """

    contour_xy: np.ndarray
    R_camera_plane: np.ndarray
    origin: np.ndarray
    z_max: float
    approach_depth: float
    invalid_depth_px: int
    tilt: float | None
    frame: str
    depth_mode: str
    on_table: bool = False

    def to_camera(self, xy, depth: float | None = None) -> np.ndarray:
        """(n, 3) float: camera-frame points of planning-frame points (n, 2).

        ``depth`` places them at that distance from the camera along the
        approach axis (e.g. ``approach_depth``); None keeps them in the
        contour's plane.
        """
        xy = np.asarray(xy, dtype=float).reshape(-1, 2)
        points = self.origin + xy @ self.R_camera_plane[:, :2].T
        if depth is not None:
            axis = self.R_camera_plane[:, 2]
            points = points + (depth - float(axis @ self.origin)) * axis
        return points


def approach_depth(depth, mask, *, offset: float = APPROACH_OFFSET, depth_range=SENSOR_RANGE) -> float:
    """Minimum valid depth within the mask plus ``offset`` (section 3.1.1), m.

    The minimum is taken over the depth median-filtered over
    ``APPROACH_MEDIAN_PX`` (3 x 3) pixels (:func:`denoised_depth`): the
    minimum of raw readings is their noise's extreme, a few millimetres nearer
    than the surface (which would eat half of the 1 cm offset), or a single
    flying pixel.

    The thesis adds "a small offset, since we do not want the end-effector to
    collide with the object" without giving its sign convention. Read
    literally, a positive offset puts the target *beyond* the nearest surface
    along the optical axis; pass a negative one for a stand-off. The value is
    a depth along the optical axis; :func:`contour_to_metric` gives the same
    quantity along the table normal for a tilted camera.

    Parameters
    ----------
    depth : (H, W) or (H, W, 1) float
        Depth in meters.
    mask : (H, W) bool
        Pixels within or on the contour.
    offset : float
        Added to the minimum depth, m.
    depth_range : (float, float)
        Valid readings, m.

    Raises
    ------
    InputError
        Mismatched shapes, or no valid reading in the mask.
    """
    d = as_depth(depth)
    m = np.asarray(mask, dtype=bool)
    validation.same_size(m.shape, d.shape, "mask", "depth image", error=PerceptionError)
    offset = validation.finite("offset", offset, error=PerceptionError)
    valid = valid_depth(d, depth_range)
    if not (m & valid).any():
        lo, hi = validation.depth_range("depth_range", depth_range, error=PerceptionError)
        raise PerceptionError(f"no valid depth inside the object: all {int(m.sum())} pixels are 0, NaN or outside [{lo}, {hi}] m")
    return float(denoised_at(d, valid, *np.nonzero(m & valid)).min()) + offset


def contour_to_metric(
    contour_px,
    depth,
    intrinsics: Intrinsics,
    *,
    depth_mode: DepthMode = "max",
    plane: Plane | None = None,
    on_table: bool = False,
    offset: float = APPROACH_OFFSET,
    depth_range=SENSOR_RANGE,
) -> MetricContour:
    """A pixel contour in meters, in the plane the hand plans in, and the approach depth (section 3.1.1).

    Implements eq 3.1, x = (u - cx) z_max / fx, and
    Implements eq 3.2, y = (v - cy) z_max / fy, in the thesis's case below;
    its generalisation intersects each contour pixel's ray with a *planning plane*:

    * Camera at most ``TILT_PLANE_THRESHOLD`` (2 deg) from top-down, or no
      table plane known: the thesis's plane parallel to the image plane, so
      x = (u - cx) z / fx, y = (v - cy) z / fy (eq 3.1-3.2).
    * Steeper: a plane parallel to the table, so that distances are measured
      on the table and the hand can approach along the table's normal
      (section 4.1.4 aligns the hand with the image plane, which only works
      when that plane is parallel to the table). The planning x axis is the
      camera's x axis projected onto the plane, z is the table normal pointing
      away from the camera, y = z cross x. Above ``TILT_WARN`` (20 deg) a
      :class:`PerceptionWarning` says the single top-down view misses much of
      the object's side.

    Where the plane sits (``depth_mode``):

    ``"max"`` (thesis)
        Through the contour pixel farthest from the camera (lowest above the
        table): z = z_max, the largest valid depth on the contour. The outline
        pixels of a segmented object straddle its edge, so z_max is about the
        table's depth right beside the object: robust to noisy and missing
        readings, as the thesis intends, but it measures a tall object's top
        outline as if it lay on the table, overstating its size by about
        height / distance (4 % for 3 cm at 0.7 m).
    ``"plane"``
        Through the object's top: the nearest valid point within or on the
        contour. Better for box-like objects whose seen outline is their top
        face; for rounded ones (a lying bottle) the widest outline is lower
        and ``"max"`` is closer.

    A footprint (``on_table``, :func:`object_footprint`, which
    :func:`segment_depth` returns for a tilted camera) is drawn where the table is, so its plane is the
    table itself, whatever the tilt: exact for any object shape. Without
    tilt that is eq 3.1-3.2 with z the table's depth along the contour's rays
    (their mean), which is what z_max stands for. ``depth_mode`` must then be
    ``"max"``. The approach depth (nearest point on :func:`denoised_depth`,
    see :func:`approach_depth`) is measured on the points whose footprint
    lies within the contour (the object standing there), since a tilted
    camera sees the object's top beside its footprint.

    Parameters
    ----------
    contour_px : (n, 2) float
        Contour (u, v) in pixels, inside the image, e.g. ``Segmentation.contour_px``.
    depth : (H, W) or (H, W, 1) float
        Depth in meters.
    intrinsics : Intrinsics
        Of the depth image.
    depth_mode : {"max", "plane"}
        See above.
    plane : Plane, optional
        The table (e.g. ``Segmentation.plane``); None fits it from ``depth``,
        and when that fails assumes the thesis's parallel planes, with a warning.
    on_table : bool
        The contour is a footprint (``Segmentation.on_table``), see above.
    offset : float
        Added to the nearest depth for ``approach_depth`` (see :func:`approach_depth`), m.
    depth_range : (float, float)
        Valid readings, m; invalid contour pixels are ignored and counted.

    Returns
    -------
    MetricContour

    Raises
    ------
    InputError
        Bad contour (shape, NaN, outside the image), no valid depth on the
        contour, rays that miss the planning plane, a footprint without a
        table plane or with ``depth_mode="plane"``.
    """
    d = as_depth(depth)
    check_intrinsics(intrinsics).check_shape(d.shape, "depth image")
    if plane is not None and not isinstance(plane, Plane):
        raise PerceptionError(f"plane must be a contourgrasp.perception.Plane, got {type(plane).__name__}")
    on_table = validation.flag("on_table", on_table, error=PerceptionError)
    depth_mode = validation.choice("depth_mode", depth_mode, DEPTH_MODES, error=PerceptionError)
    offset = validation.finite("offset", offset, error=PerceptionError)
    if on_table and depth_mode != "max":
        raise PerceptionError("depth_mode 'plane' places the contour at the object's top, but a footprint lies on the table: "
                         "segment without the footprint, or use depth_mode 'max'")
    contour = validation.pixel_contour("contour_px", contour_px, d.shape, error=PerceptionError)
    outline, inside = _rasterize(contour, d.shape)
    valid = valid_depth(d, depth_range)
    on_contour = outline & valid
    if not on_contour.any():
        lo, hi = validation.depth_range("depth_range", depth_range, error=PerceptionError)
        raise PerceptionError(
            f"no valid depth on the contour: all {int(outline.sum())} contour pixels are 0, NaN or outside [{lo}, {hi}] m"
        )
    if plane is None:
        plane = _table_or_none(d, intrinsics, depth_range)
    if on_table and plane is None:
        raise PerceptionError("a footprint contour needs the table plane, and none was found in the depth image")
    tilt = None if plane is None else plane.tilt
    reference = plane if tilt is not None and tilt > TILT_PLANE_THRESHOLD else IMAGE_PLANE
    if tilt is not None and tilt > TILT_WARN:
        warnings.warn(
            f"camera tilted {math.degrees(tilt):.1f} deg from top-down: the contour is planned in the table's plane, "
            f"but one view this oblique hides much of the object's far side",
            PerceptionWarning,
            stacklevel=2,
        )
    rays = intrinsics.rays(contour)
    if on_table:
        rows, cols = _standing_on(d, intrinsics, plane, inside, valid)
        level = reference.height((-plane.offset / (rays @ plane.normal))[:, None] * rays).mean()
    else:
        rows, cols = np.nonzero(inside & valid)
        heights = reference.height(pixel_points(d, intrinsics, rows, cols))
        level = heights[outline[rows, cols]].min() if depth_mode == "max" else heights.max()
    rotation = plane_axes(reference.normal)
    origin, xy = _intersect(rays, reference, float(level), rotation)
    nearest = pixel_points_at(denoised_at(d, valid, rows, cols), intrinsics, rows, cols) @ rotation[:, 2]
    return MetricContour(
        contour_xy=xy,
        R_camera_plane=rotation,
        origin=origin,
        z_max=float(d[on_contour].max()),
        approach_depth=float(nearest.min()) + offset,
        invalid_depth_px=int((outline & ~valid).sum()),
        tilt=tilt,
        frame="camera" if reference is IMAGE_PLANE else "table",
        depth_mode=depth_mode,
        on_table=bool(on_table),
    )


def _standing_on(depth, intrinsics, plane, inside, valid):
    """(rows, cols) of the valid pixels whose footprint lies in ``inside``: the table there and what stands on it.

    Only the above-table regions that overlap ``inside`` are moved onto the
    table: an object seen by a tilted camera overlaps its own footprint (its
    near side reaches down to it), and the rest of the scene (a gripper,
    clutter: ten times the object's pixels on the shared frames) is skipped.
    """
    with np.errstate(invalid="ignore"):
        above = valid & (heights(depth, intrinsics, plane) > PLANE_THRESHOLD)
    rows, cols = np.nonzero(connected_to(above, inside & above))
    keep, u, v = in_image(footprint_pixels(depth, intrinsics, plane, rows, cols), inside.shape)
    keep[keep] = inside[v[keep], u[keep]]
    table_rows, table_cols = np.nonzero(inside & valid & ~above)
    if not keep.any() and not len(table_rows):
        return np.nonzero(inside & valid)
    return np.r_[rows[keep], table_rows], np.r_[cols[keep], table_cols]


def _table_or_none(depth, intrinsics, depth_range):
    try:
        return fit_table_plane(depth, intrinsics, depth_range=depth_range)
    except SegmentationError as err:
        warnings.warn(
            f"{err}: assuming the image plane is parallel to the table (thesis chapter 3)", PerceptionWarning, stacklevel=3
        )
        return None


def _intersect(rays, plane, level, rotation):
    """Planning-frame origin (3,) and (n, 2) coordinates of rays meeting the plane at ``height == level``."""
    along = rays @ plane.normal
    cosine = -along / np.linalg.norm(rays, axis=1)
    if np.any(cosine < MIN_RAY_COSINE):
        raise PerceptionError(
            f"contour rays graze the planning plane (cosine {cosine.min():.3f} < {MIN_RAY_COSINE}): "
            f"the camera is too oblique to the table, or its field of view too wide"
        )
    reach = level - plane.offset
    if reach >= 0:
        raise PerceptionError("the contour's plane is not in front of the camera: the depth does not fit a table below it")
    points = (reach / along)[:, None] * rays
    origin = np.array([0.0, 0.0, reach / plane.normal[2]])
    return origin, (points - origin) @ rotation[:, :2]


def _rasterize(contour, shape):
    """(H, W) bool outline pixels of a closed polygon, and the pixels within or on it."""
    outline = np.zeros(shape, dtype=np.uint8)
    poly = [np.round(contour).astype(np.int32)]
    cv2.polylines(outline, poly, isClosed=True, color=1, thickness=1)
    inside = outline.copy()
    cv2.fillPoly(inside, poly, 1)
    return outline > 0, inside > 0
