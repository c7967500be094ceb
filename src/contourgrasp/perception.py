"""Perception: the object's contour and approach depth from one RGB-D frame (thesis 3.1, 3.1.1).

Every function here works on arrays; reading files is :mod:`contourgrasp.io.camera_file`'s job.

Pipeline
--------
1. Segmentation, one of four methods, each returning a :class:`Segmentation`
   (mask, pixel contour, warnings):

   ``"rgb"`` (:func:`segment_rgb`)
       The thesis's steps (3.1): grayscale, median blur, adaptive threshold,
       closing (dilation then erosion), closed external contours, the largest.
   ``"depth"`` (:func:`segment_depth`)
       A RANSAC plane fit of the table (:func:`fit_table_plane`), then the
       region standing more than ``min_height`` above it; with a tilted
       camera, that region's footprint on the table (:func:`object_footprint`).
   ``"auto"`` (:func:`segment`)
       Depth, plus the flat parts found by colour (:func:`add_flat_parts`) in
       the colour image registered to the depth image (:func:`colour_offset`);
       the RGB steps when depth cannot be used (rule below).
   ``"mask"`` (:func:`segment_from_mask`)
       A binary mask given by the user.

2. :func:`contour_to_metric`: pixels to meters (eq 3.1-3.2), in the table's
   plane when the camera is tilted, and the approach depth (3.1.1).

Conventions
-----------
Camera frame = optical frame: x right, y down, z forward, meters. A pixel is
(u, v) = (column, row), with the centre of the top-left pixel at (0, 0).
Depth is the z coordinate in meters. A depth reading is *valid* when it is
finite and inside ``depth_range``, by default the thesis sensor's range
0.2-1.5 m (section 4.1.2); 0 and NaN mark missing readings.

Readings of ours (where the thesis is silent)
---------------------------------------------
* Which region is the object. The thesis takes the largest contour. Section
  4.1.3 also assumes the object is completely visible, so every method here
  takes the largest region that does *not* touch the image border (for depth
  also: nor the sensor's dead band of missing readings connected to the
  border). On the shared PrimeSense frames the largest contour of the plain
  RGB steps is the mat's edge, which touches the border; the next one is the
  object. When every candidate touches the border the object is refused as
  not completely visible; a second region of at least ``SIMILAR_SIZE`` times
  the chosen one's area gives a warning.
* The ``"auto"`` rule. Depth first: it does not see shadows, printed texture
  or the table's edge. On the shared PrimeSense frames it scores 0.89-0.95 IoU
  against the hand-made masks where the RGB steps score 0.47-0.70, except on
  the can opener (frame 6), lying flat, of which depth sees only the raised
  grip (0.23). So, with a colour image, :func:`add_flat_parts` then grows the
  depth mask by colour: the pixels unlike the table's colour connected to
  it, of which only the parts more than ``HALO_PX`` beyond the depth outline
  and of at least ``min_area_px`` are added (method ``"depth+rgb"``; frame 6:
  0.78). Nearer colour evidence is shadow and the object's side, which the
  depth outline bounds better. (GrabCut seeded the same way, in an earlier
  release, also kept the shaded mat between the can opener's handles: 0.68.)
  The RGB steps are used when there is no depth image, no table plane
  (:class:`SegmentationError` of kind ``"no-plane"``), or nothing of size
  stands above the table (kinds ``"no-object"``, ``"tiny"``: a flat object);
  the segmentation then carries a warning that says why. A region that
  touches the border is refused, not handed to RGB.
* Colour-depth registration. The shared PrimeSense pairs are sold as
  registered, but an object's outline in depth lies 1-6 px above its outline
  in colour (dx 0-1 px; 2 px on the raw bar-clamp frame; on the others part
  of it may be the authors' fill of the depth around the object). So ``"auto"`` first finds that shift where the
  object is (:func:`colour_offset`, edge correlation) and moves the colour
  image onto the depth image (:func:`register_colour`) before it looks for
  flat parts; masks and contours are in depth pixels (the shift is in
  ``Segmentation.colour_offset_px``). Unregistered, the can opener's handles
  land 4 px low: IoU 0.74 instead of 0.78.
* Footprint. With a tilted camera the region seen (depth, plus flat parts)
  is replaced by the object's footprint on the table
  (:func:`object_footprint`): what a hand approaching along the table's
  normal closes on, and nearer to the hand-made masks than the region seen.
  Those masks lie between the colour and the depth outlines (about 2 px
  from each), so 1-2 px is as close as an outline gets to them here.
* Tilted cameras: see :func:`contour_to_metric`.
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass, field, replace
from inspect import Parameter, signature
from typing import Literal

import cv2
import numpy as np
from scipy import ndimage

from .errors import InputError

#: Working range of the thesis's depth sensor (section 4.1.2), meters.
SENSOR_RANGE = (0.2, 1.5)

#: A pixel belongs to the object when it stands this much (m) above the table.
MIN_HEIGHT = 0.01

#: RANSAC: a point within this distance (m) of a plane is one of its inliers.
PLANE_THRESHOLD = 0.005

#: RANSAC: candidate planes drawn.
PLANE_ITERATIONS = 200

#: RANSAC samples every PLANE_STRIDE-th pixel in both directions (all pixels vote for the final inliers).
PLANE_STRIDE = 4

#: RANSAC scores candidate planes on this many of the points, drawn at random (all of them vote for the refit).
PLANE_SAMPLE = 2000

#: A table holds at least this fraction of the valid depth pixels.
MIN_PLANE_FRACTION = 0.2

#: Planes tilted more than this from facing the camera are walls, not tables (rad).
MAX_TABLE_TILT = math.radians(60.0)

#: Above this tilt (rad) the contour is planned in the table's plane rather than the image plane.
TILT_PLANE_THRESHOLD = math.radians(2.0)

#: Above this tilt (rad) a warning says the top-down assumption is stretched.
TILT_WARN = math.radians(20.0)

#: Smallest object, in pixels (about 2 x 2 cm at 0.7 m with a 525 px focal length).
MIN_AREA_PX = 200

#: A second candidate region at least this fraction of the largest's area draws a warning.
SIMILAR_SIZE = 0.5

#: Colour distance (CIELAB on OpenCV's 8-bit scale) from the table's colour that marks a possible object part.
COLOUR_DISTANCE = 50.0

#: Weight of lightness in that distance: shadows darken the table without changing its hue.
LIGHTNESS_WEIGHT = 0.25

#: A pixel darker than this fraction of the table's CIELAB lightness is object whatever its hue: darker
#: than a soft shadow, which would have to block about 80 % of the light (the table's 8-bit colour x 0.48).
SHADOW_LIGHTNESS = 0.5

#: Colour evidence within this distance (px) of the depth mask is shadow or the object's side;
#: only parts farther out are added to the depth mask.
HALO_PX = 8

#: Colour evidence is opened with a disc of this radius (px) to drop thin straps and specks.
EVIDENCE_OPEN_PX = 2

#: Colour evidence is first looked for within this distance (px) beyond the table ring around the depth
#: mask; the whole image is searched only when the evidence reaches that window's edge.
FLAT_WINDOW_PX = 96

#: Largest colour-depth misregistration searched for, pixels in each direction.
MAX_COLOUR_OFFSET_PX = 8

#: The colour-depth registration compares edges over the object's bounding box grown by this, pixels.
REGISTRATION_MARGIN_PX = 20

#: Holes in the depth image up to this many pixels are filled.
MAX_HOLE_PX = 400

#: Tolerance (px) of the polygon simplification of the mask outline.
CONTOUR_EPSILON_PX = 0.75

#: At most this many contour points, so that O(n^2) checks downstream stay cheap.
MAX_CONTOUR_POINTS = 400

#: Offset added to the minimum depth for the approach depth (section 3.1.1), m.
APPROACH_OFFSET = 0.01

#: The minimum depth for the approach is taken after a median filter of this size (px): the minimum of
#: raw readings rides on their noise (about 5 mm nearer than the object's top with the simulated sensor's
#: 2 mm at 0.7 m, 2 mm after the filter) and on single flying pixels; features 2 px wide survive it.
APPROACH_MEDIAN_PX = 3

#: A pixel ray meeting the planning plane at a cosine below this is refused as grazing.
MIN_RAY_COSINE = 0.05

SegmentMethod = Literal["auto", "rgb", "depth"]
SEGMENT_METHODS: tuple[str, ...] = ("auto", "rgb", "depth")
DepthMode = Literal["max", "plane"]
DEPTH_MODES: tuple[str, ...] = ("max", "plane")

#: SegmentationError kinds after which ``"auto"`` falls back from depth to RGB.
_DEPTH_FALLBACK_KINDS = ("no-plane", "no-object", "tiny")


class SegmentationError(InputError):
    """No usable object in the image; ``kind`` says why.

    Kinds: ``"no-plane"`` (no table plane in the depth), ``"no-object"``
    (nothing found), ``"not-visible"`` (the object touches the image border),
    ``"tiny"`` (the object is smaller than ``min_area_px`` or has no interior).
    """

    def __init__(self, kind: str, message: str):
        super().__init__(message)
        self.kind = kind


class PerceptionWarning(UserWarning):
    """A result that is usable but doubtful: several objects, a steep camera, a fallback."""


@dataclass(frozen=True)
class Intrinsics:
    """Pinhole intrinsics of the depth camera (colour registered to it).

    Attributes
    ----------
    fx, fy : float
        Focal lengths in pixels.
    cx, cy : float
        Principal point in pixels, from the centre of the top-left pixel.
    width, height : int
        Image size in pixels.
    """

    fx: float
    fy: float
    cx: float
    cy: float
    width: int
    height: int

    def __post_init__(self):
        for name in ("fx", "fy", "cx", "cy"):
            value = getattr(self, name)
            if isinstance(value, bool) or not isinstance(value, (int, float, np.integer, np.floating)) or not math.isfinite(value):
                raise InputError(f"intrinsics: {name} must be a finite number, got {value!r}")
            object.__setattr__(self, name, float(value))
        for name in ("fx", "fy"):
            if getattr(self, name) <= 0:
                raise InputError(f"intrinsics: {name} must be positive, got {getattr(self, name)}")
        for name in ("width", "height"):
            value = getattr(self, name)
            if isinstance(value, bool) or not isinstance(value, (int, float, np.integer, np.floating)) or value != int(value) or value < 1:
                raise InputError(f"intrinsics: {name} must be a positive whole number of pixels, got {value!r}")
            object.__setattr__(self, name, int(value))

    @property
    def shape(self) -> tuple[int, int]:
        """(height, width), the shape of an image taken with these intrinsics."""
        return (self.height, self.width)

    @property
    def K(self) -> np.ndarray:
        """(3, 3) float: the camera matrix."""
        return np.array([[self.fx, 0.0, self.cx], [0.0, self.fy, self.cy], [0.0, 0.0, 1.0]])

    def check_shape(self, shape, what: str) -> None:
        """Raise :class:`InputError` unless an image of ``shape`` fits these intrinsics."""
        if tuple(shape[:2]) != self.shape:
            raise InputError(
                f"{what} is {shape[1]}x{shape[0]} (width x height) but the intrinsics are for "
                f"{self.width}x{self.height}"
            )

    def rays(self, pixels) -> np.ndarray:
        """(n, 3) float: directions (x/z, y/z, 1) of the rays through (n, 2) pixels (u, v)."""
        uv = np.asarray(pixels, dtype=float).reshape(-1, 2)
        return np.c_[(uv[:, 0] - self.cx) / self.fx, (uv[:, 1] - self.cy) / self.fy, np.ones(len(uv))]

    def project(self, points_camera) -> np.ndarray:
        """(n, 2) float: pixels (u, v) of camera-frame points (n, 3); the inverse of :meth:`rays`."""
        p = np.asarray(points_camera, dtype=float).reshape(-1, 3)
        return np.c_[self.fx * p[:, 0] / p[:, 2] + self.cx, self.fy * p[:, 1] / p[:, 2] + self.cy]


@dataclass(frozen=True, eq=False)
class Plane:
    """A plane n . p + offset = 0 in the camera frame.

    Attributes
    ----------
    normal : (3,) float
        Unit normal pointing toward the camera (negative z component).
    offset : float
        The camera's signed distance to the plane (positive for a plane in
        front of it), m; ``height(p) = normal . p + offset``.
    inliers : (H, W) or (n,) bool
        The points within the fit's threshold; (H, W) for a fit on a depth image.
    """

    normal: np.ndarray
    offset: float
    inliers: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=bool))

    @property
    def tilt(self) -> float:
        """Angle (rad) between the plane's normal and the optical axis: 0 for a top-down camera."""
        return float(math.acos(min(1.0, -float(self.normal[2]))))

    def height(self, points) -> np.ndarray:
        """(...) float: signed height (m) of (..., 3) camera-frame points above the plane."""
        return np.asarray(points, dtype=float) @ self.normal + self.offset


#: The thesis's plane: parallel to the image plane; height = -z.
_IMAGE_PLANE = Plane(normal=np.array([0.0, 0.0, -1.0]), offset=0.0)


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
        ``MAX_CONTOUR_POINTS`` points; not closed (the first point is not
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


# ---------------------------------------------------------------------------
# Depth images
# ---------------------------------------------------------------------------


def as_depth(depth) -> np.ndarray:
    """(H, W) float: a depth image, squeezing a trailing channel of 1 ((H, W, 1) as stored by gqcnn).

    A float64 image is returned as it is, not copied: nothing in perception
    writes to its depth images.
    """
    d = np.asarray(depth)
    if d.ndim == 3 and d.shape[2] == 1:
        d = d[..., 0]
    if d.ndim != 2 or d.size == 0:
        raise InputError(f"depth image must be an (H, W) array, got shape {d.shape}")
    if not (np.issubdtype(d.dtype, np.number) and not np.issubdtype(d.dtype, np.complexfloating)):
        raise InputError(f"depth image must hold real numbers, got {d.dtype}")
    return d.astype(float, copy=False)


def valid_depth(depth, depth_range=SENSOR_RANGE) -> np.ndarray:
    """(H, W) bool: finite readings inside ``depth_range`` (m)."""
    d = as_depth(depth)
    lo, hi = _check_range(depth_range)
    with np.errstate(invalid="ignore"):
        return np.isfinite(d) & (d >= lo) & (d <= hi)


def backproject(depth, intrinsics: Intrinsics) -> np.ndarray:
    """(H, W, 3) float: camera-frame point of every pixel, NaN where the depth is not finite.

    x = (u - cx) z / fx, y = (v - cy) z / fy (the pixel-wise form of eq 3.1-3.2).
    """
    d = as_depth(depth)
    intrinsics.check_shape(d.shape, "depth image")
    return _points(np.where(np.isfinite(d), d, np.nan), intrinsics, *np.indices(d.shape))


def fill_depth_holes(depth, *, max_hole_px: int = MAX_HOLE_PX) -> tuple[np.ndarray, int]:
    """Fill small holes of a depth image with the nearest reading.

    A hole is a connected (8-neighbour) region of missing readings (0, NaN,
    negative or infinite). Holes of at most ``max_hole_px`` pixels take the
    value of the nearest present reading; larger ones, such as the sensor's
    dead band or a far shadow, are left missing. Nearest-reading fill (rather
    than inpainting) invents no depth that the sensor did not measure, so a
    filled pixel is either table or object, never in between.

    Parameters
    ----------
    depth : (H, W) or (H, W, 1) float
        Depth in meters.
    max_hole_px : int
        Largest hole filled, pixels; 0 fills nothing.

    Returns
    -------
    filled : (H, W) float
        A copy with the small holes filled.
    count : int
        Number of pixels filled.
    """
    d = as_depth(depth)
    max_hole_px = _check_int("max_hole_px", max_hole_px, 0)
    with np.errstate(invalid="ignore"):
        missing = ~np.isfinite(d) | (d <= 0)
    if not missing.any() or missing.all() or max_hole_px == 0:
        return d.copy(), 0
    _, labels, stats, _ = cv2.connectedComponentsWithStats(missing.astype(np.uint8), connectivity=8)
    small = stats[:, cv2.CC_STAT_AREA] <= max_hole_px
    small[0] = False
    if not small.any():
        return d.copy(), 0
    box = _hole_box(stats[small], d.shape)
    fill = small[labels[box]]
    _, (rows, cols) = ndimage.distance_transform_edt(missing[box], return_indices=True)
    out = d.copy()
    out[box][fill] = d[box][rows[fill], cols[fill]]
    return out, int(stats[small, cv2.CC_STAT_AREA].sum())


def _hole_box(stats, shape):
    """Slices of the image holding the nearest readings of the holes in ``stats`` (OpenCV's rows).

    A pixel of a hole at most ``e`` pixels wide and high has a reading within
    ``e`` pixels along its row or its column: the first pixel past the hole
    there is not missing (it would belong to the hole), unless the hole runs
    from edge to edge both ways, and then ``e`` spans the image. So every
    nearest reading lies within the holes' bounding box grown by the largest
    ``e``, and the distance transform need not look farther.
    """
    reach = int(stats[:, [cv2.CC_STAT_WIDTH, cv2.CC_STAT_HEIGHT]].max())
    top = stats[:, cv2.CC_STAT_TOP].min() - reach
    left = stats[:, cv2.CC_STAT_LEFT].min() - reach
    bottom = (stats[:, cv2.CC_STAT_TOP] + stats[:, cv2.CC_STAT_HEIGHT]).max() + reach
    right = (stats[:, cv2.CC_STAT_LEFT] + stats[:, cv2.CC_STAT_WIDTH]).max() + reach
    return np.s_[max(top, 0): min(bottom, shape[0]), max(left, 0): min(right, shape[1])]


# ---------------------------------------------------------------------------
# Table plane
# ---------------------------------------------------------------------------


def fit_plane(
    points,
    *,
    threshold: float = PLANE_THRESHOLD,
    iterations: int = PLANE_ITERATIONS,
    seed: int = 0,
    max_tilt: float = MAX_TABLE_TILT,
    sample: int = PLANE_SAMPLE,
) -> Plane:
    """RANSAC plane through camera-frame points, refined by least squares on its inliers.

    Candidate planes through three random points (drawn from ``seed``, so the
    result is deterministic) are scored by their number of points within
    ``threshold`` among ``sample`` random points; candidates tilted more than
    ``max_tilt`` from facing the camera are skipped; when the best ones lie on
    different surfaces of nearly the same size, they are counted again on all
    points. The best one is refitted (SVD) twice to its inliers among all the
    points. Scoring on a sample rather than on all points costs little
    accuracy: a candidate's share of inliers is estimated to about 1 % (one
    standard deviation with 2000 points), and the refits on all points absorb
    the difference between near-equal candidates of the same surface.

    Parameters
    ----------
    points : (n, 3) float
        Camera-frame points, m; rows with a NaN are ignored.
    threshold : float
        Inlier distance, m.
    iterations : int
        Candidate planes drawn.
    seed : int
        Seed of the random draws.
    max_tilt : float
        Largest angle (rad) between a candidate's normal and the optical axis.
    sample : int
        Points the candidates are scored on (all of them when there are fewer).

    Returns
    -------
    Plane
        Normal toward the camera; ``inliers`` is (n,) bool over the given points.

    Raises
    ------
    SegmentationError
        Kind ``"no-plane"``: fewer than 3 finite points, or no candidate facing the camera.
    """
    p = np.asarray(points, dtype=float)
    if p.ndim != 2 or p.shape[1] != 3:
        raise InputError(f"points must be an (n, 3) array, got shape {p.shape}")
    threshold = _check_positive("threshold", threshold)
    iterations = _check_int("iterations", iterations, 1)
    sample = _check_int("sample", sample, 3)
    finite = np.all(np.isfinite(p), axis=1)
    cloud = p[finite]
    if len(cloud) < 3:
        raise SegmentationError("no-plane", f"no table plane: only {len(cloud)} valid depth points")
    rng = np.random.default_rng(seed)
    normals, offsets = _candidate_planes(cloud, iterations, rng, max_tilt)
    if len(normals) == 0:
        raise SegmentationError(
            "no-plane",
            f"no table plane: no plane through the depth points faces the camera within {math.degrees(max_tilt):.0f} deg",
        )
    voters = cloud[rng.choice(len(cloud), size=sample, replace=False)] if len(cloud) > sample else cloud
    best = _best_candidate(cloud, normals, offsets, np.abs(normals @ voters.T + offsets[:, None]) < threshold, threshold)
    normal, offset = normals[best], offsets[best]
    for _ in range(2):
        inliers = np.abs(cloud @ normal + offset) < threshold
        if np.count_nonzero(inliers) < 3:
            break
        normal, offset = _least_squares_plane(cloud[inliers])
    mask = np.zeros(len(p), dtype=bool)
    mask[finite] = np.abs(cloud @ normal + offset) < threshold
    return Plane(normal=normal, offset=offset, inliers=mask)


def _best_candidate(cloud, normals, offsets, votes, threshold):
    """Index of the candidate plane holding the most points, from the sample's ``votes`` (candidates, sample) bool.

    Candidates whose sampled count is within sampling error of the best one's
    may lie on another surface of nearly the same size (a large flat object
    against the table): one candidate per surface (the best counted of those
    sharing at most half their sampled inliers with the ones before) is
    counted again on all points, and the one holding most of them wins.
    """
    counts = np.count_nonzero(votes, axis=1)
    # By chance alone, two candidates' sampled counts differ with a standard deviation of about
    # sqrt(2 * count); four of them make the margin.
    close = np.flatnonzero(counts >= counts.max() - 4 * math.sqrt(2 * counts.max()))
    surfaces = []
    for i in close[np.argsort(-counts[close], kind="stable")]:
        if all(np.count_nonzero(votes[i] & votes[j]) <= counts[i] / 2 for j in surfaces):
            surfaces.append(i)
    if len(surfaces) == 1:
        return surfaces[0]
    on_all = np.count_nonzero(np.abs(cloud @ normals[surfaces].T + offsets[surfaces]) < threshold, axis=0)
    return surfaces[np.argmax(on_all)]


def _candidate_planes(cloud, iterations, rng, max_tilt):
    a, b, c = (cloud[i] for i in rng.integers(0, len(cloud), size=(3, iterations)))
    normals = np.cross(b - a, c - a)
    length = np.linalg.norm(normals, axis=1)
    keep = length > 1e-12
    normals = normals[keep] / length[keep, None]
    normals *= np.where(normals[:, 2] > 0, -1.0, 1.0)[:, None]
    facing = -normals[:, 2] >= math.cos(max_tilt)
    normals = normals[facing]
    return normals, -np.einsum("ij,ij->i", normals, a[keep][facing])


def _least_squares_plane(points):
    centre = points.mean(axis=0)
    normal = np.linalg.svd(points - centre, full_matrices=False)[2][2]
    if normal[2] > 0:
        normal = -normal
    return normal, float(-normal @ centre)


def fit_table_plane(
    depth,
    intrinsics: Intrinsics,
    *,
    threshold: float = PLANE_THRESHOLD,
    iterations: int = PLANE_ITERATIONS,
    seed: int = 0,
    stride: int = PLANE_STRIDE,
    depth_range=SENSOR_RANGE,
    min_fraction: float = MIN_PLANE_FRACTION,
) -> Plane:
    """The table: the plane holding the most valid depth pixels (RANSAC, :func:`fit_plane`).

    The camera looks down on a table that fills much of the view (section
    4.1.3), so the dominant plane facing the camera is taken to be the table.
    Its ``tilt`` is the camera's deviation from top-down (12.6 deg on the
    shared single-object frames, 3.3 deg on the bar-clamp frame).

    Parameters
    ----------
    depth : (H, W) or (H, W, 1) float
        Depth in meters.
    intrinsics : Intrinsics
        Of the depth image.
    threshold, iterations, seed
        As in :func:`fit_plane`.
    stride : int
        RANSAC scores candidates on every ``stride``-th pixel in both
        directions; the final inliers are over all pixels.
    depth_range : (float, float)
        Valid depth readings, m.
    min_fraction : float
        Smallest share of the valid pixels the plane must hold.

    Returns
    -------
    Plane
        ``inliers`` is (H, W) bool.

    Raises
    ------
    SegmentationError
        Kind ``"no-plane"``, with the reason.
    """
    stride = _check_int("stride", stride, 1)
    d = as_depth(depth)
    intrinsics.check_shape(d.shape, "depth image")
    valid = valid_depth(d, depth_range)
    rows, cols = np.nonzero(valid[::stride, ::stride])
    grid = _points(d, intrinsics, stride * rows, stride * cols)
    plane = fit_plane(grid, threshold=threshold, iterations=iterations, seed=seed)
    inliers = valid & (np.abs(_heights(d, intrinsics, plane)) < threshold)
    share = inliers.sum() / max(int(valid.sum()), 1)
    if share < min_fraction:
        raise SegmentationError(
            "no-plane",
            f"no table plane: the best plane holds {share:.0%} of the valid depth pixels (need {min_fraction:.0%})",
        )
    return replace(plane, inliers=inliers)


def _points(depth, intrinsics, rows, cols) -> np.ndarray:
    """(..., 3) float: camera-frame points of the pixels (rows, cols), index arrays of any one shape (eq 3.1-3.2)."""
    return _points_at(depth[rows, cols], intrinsics, rows, cols)


def _points_at(z, intrinsics, rows, cols) -> np.ndarray:
    """:func:`_points` with the pixels' depths ``z`` given."""
    return np.stack([(cols - intrinsics.cx) * z / intrinsics.fx, (rows - intrinsics.cy) * z / intrinsics.fy, z], axis=-1)


def _heights(depth, intrinsics, plane) -> np.ndarray:
    """(H, W) float: ``plane.height`` of every pixel's point, without building the (H, W, 3) cloud.

    The point of pixel (u, v) is z r with r = ((u - cx) / fx, (v - cy) / fy, 1),
    so its height is z (normal . r) + offset, where normal . r is a column term
    plus a row term. Non-finite depths give non-finite or NaN heights.
    """
    normal = plane.normal
    cols = normal[0] * (np.arange(intrinsics.width) - intrinsics.cx) / intrinsics.fx + normal[2]
    rows = normal[1] * (np.arange(intrinsics.height) - intrinsics.cy) / intrinsics.fy
    with np.errstate(invalid="ignore"):
        return depth * (rows[:, None] + cols) + plane.offset


# ---------------------------------------------------------------------------
# Segmentation
# ---------------------------------------------------------------------------


def segment_rgb(
    rgb,
    *,
    blur: int = 5,
    block_size: int = 11,
    c: float = 2.0,
    close_kernel: int = 5,
    close_iterations: int = 2,
    min_area_px: int = MIN_AREA_PX,
) -> Segmentation:
    """The thesis's RGB segmentation (section 3.1).

    Grayscale; median blur (``blur``, odd, 1 = none); adaptive threshold
    (Gaussian-weighted mean over ``block_size`` pixels minus ``c``, inverted
    so that pixels darker than their surroundings, i.e. edges and dark
    objects, are foreground); closing, i.e. ``close_iterations`` dilations
    then as many erosions with an elliptic ``close_kernel``-pixel element;
    the filled external contours; the largest one not touching the image
    border (module docstring).

    The defaults (11 px blocks, c = 2) find the object on all five shared
    PrimeSense frames, but its outline includes shadows and straps: IoU
    0.47-0.70 against the hand-made masks.

    Parameters
    ----------
    rgb : (H, W, 3) uint8
        Colour image in RGB order, or (H, W) uint8 grayscale.
    blur, block_size, c, close_kernel, close_iterations
        As above.
    min_area_px : int
        Smallest object, pixels.

    Raises
    ------
    SegmentationError
        No closed contour, only contours touching the border, or a tiny one.
    """
    gray = _as_gray(rgb)
    blur = _check_int("blur", blur, 1, odd=True)
    block_size = _check_int("block_size", block_size, 3, odd=True)
    c = _check_finite("c", c)
    close_kernel = _check_int("close_kernel", close_kernel, 1)
    close_iterations = _check_int("close_iterations", close_iterations, 0)
    min_area_px = _check_int("min_area_px", min_area_px, 1)
    if blur > 1:
        gray = cv2.medianBlur(gray, blur)
    binary = cv2.adaptiveThreshold(gray, 255, cv2.ADAPTIVE_THRESH_GAUSSIAN_C, cv2.THRESH_BINARY_INV, block_size, c)
    kernel = cv2.getStructuringElement(cv2.MORPH_ELLIPSE, (close_kernel, close_kernel))
    closed = cv2.erode(cv2.dilate(binary, kernel, iterations=close_iterations), kernel, iterations=close_iterations)
    contours, _ = cv2.findContours(closed, cv2.RETR_EXTERNAL, cv2.CHAIN_APPROX_NONE)
    filled = np.zeros(gray.shape, dtype=np.uint8)
    cv2.drawContours(filled, contours, -1, 1, thickness=cv2.FILLED)
    mask, notes = _pick_object(filled > 0, np.zeros(gray.shape, dtype=bool), min_area_px, "with a closed contour")
    return _segmentation("rgb", mask, notes)


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
    height / depth); the footprint would measure it exactly, but on the
    simulated top-down bench it lowered the default planner from 96 % to 89 %
    and the thesis's from 43 % to 33 % (README, "Perception"), so it is an
    option there (``plan_grasp(footprint=True)``).

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

    Raises
    ------
    SegmentationError
        No table plane, nothing above it, the object touches the border, or it is tiny.
    """
    seen, d = _seen_above_table(depth, intrinsics, min_height=min_height, plane=plane, fill_holes=fill_holes,
                                max_hole_px=max_hole_px, min_area_px=min_area_px, depth_range=depth_range, seed=seed)
    return _with_footprint(seen, d, intrinsics, footprint, min_area_px)


def _seen_above_table(depth, intrinsics, *, min_height, plane, fill_holes, max_hole_px, min_area_px, depth_range, seed):
    """:func:`segment_depth` without the footprint: the region seen above the table, and the hole-filled depth."""
    d = as_depth(depth)
    intrinsics.check_shape(d.shape, "depth image")
    min_height = _check_positive("min_height", min_height)
    min_area_px = _check_int("min_area_px", min_area_px, 1)
    filled = 0
    if fill_holes:
        d, filled = fill_depth_holes(d, max_hole_px=max_hole_px)
    if plane is None:
        plane = fit_table_plane(d, intrinsics, depth_range=depth_range, seed=seed)
    valid = valid_depth(d, depth_range)
    with np.errstate(invalid="ignore"):
        above = valid & (_heights(d, intrinsics, plane) > min_height)
    above = cv2.morphologyEx(above.astype(np.uint8), cv2.MORPH_OPEN, np.ones((3, 3), np.uint8)) > 0
    mask, notes = _pick_object(above, _border_connected(~valid), min_area_px,
                               f"more than {min_height * 1000:.0f} mm above the table")
    return _segmentation("depth", mask, notes, plane=plane, filled_px=filled), d


def _with_footprint(seg, depth, intrinsics, footprint, min_area_px) -> Segmentation:
    """``seg`` moved onto the table (:func:`object_footprint`) when ``footprint``, or when None and the camera is tilted."""
    if footprint is None:
        footprint = seg.plane.tilt > TILT_PLANE_THRESHOLD
    if not footprint:
        return seg
    moved = object_footprint(seg.mask, depth, intrinsics, seg.plane)
    mask, notes = _pick_object(moved, np.zeros_like(moved), min_area_px, "in the object's footprint on the table")
    result = _segmentation(seg.method, mask, notes, plane=seg.plane, filled_px=seg.filled_px, on_table=True,
                           colour_offset_px=seg.colour_offset_px)
    return replace(result, warnings=(*seg.warnings, *result.warnings))


def object_footprint(mask, depth, intrinsics: Intrinsics, plane: Plane) -> np.ndarray:
    """Where the table holds what ``mask`` sees: the object's outline as a top-down view measures it.

    Every valid pixel of ``mask`` is back-projected, moved along the table's
    normal onto the table and projected back into the image
    (the rounded pixels they fall on); the hit pixels are closed with a 5 x 5 disc,
    which joins the samples that the object's steep sides spread apart (holes
    are left to the caller, e.g. :func:`segment_depth`'s object picking).

    A camera that is not top-down sees a tall object's top displaced from its
    base, by height x sin(tilt) / depth x f pixels (8 px for 5 cm at 0.7 m,
    12.7 deg, f = 525 px), and sees its near side as well; a top-down camera
    sees the top enlarged by depth / (depth - height). The footprint undoes
    both: it is where the object stands, the outline a hand approaching along
    the table's normal closes on. On the shared PrimeSense frames it is nearer
    to the hand-made masks than the region seen above the table: IoU
    0.89-0.95 against 0.84-0.92 (frames 0, 2, 4, 8).

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
    rows, cols = np.nonzero(mask & valid_depth(depth))
    seen, u, v = _in_image(_footprint_pixels(depth, intrinsics, plane, rows, cols), mask.shape)
    hit = np.zeros(mask.shape, dtype=np.uint8)
    hit[v[seen], u[seen]] = 1
    return cv2.morphologyEx(hit, cv2.MORPH_CLOSE, _disc(2)) > 0


def _in_image(uv, shape):
    """Which of the (n, 2) float pixels round to a pixel of an image of ``shape``, and their columns and rows."""
    seen = np.isfinite(uv).all(axis=1)
    u, v = np.zeros(len(uv), dtype=int), np.zeros(len(uv), dtype=int)
    u[seen], v[seen] = np.rint(uv[seen]).astype(int).T
    seen &= (u >= 0) & (u < shape[1]) & (v >= 0) & (v < shape[0])
    return seen, u, v


def _footprint_pixels(depth, intrinsics: Intrinsics, plane: Plane, rows, cols) -> np.ndarray:
    """(n, 2) float: pixels (u, v) where the points of pixels (rows, cols), moved along the table normal onto the table, are seen."""
    points = _points(depth, intrinsics, rows, cols)
    on_table = points - plane.height(points)[:, None] * plane.normal
    with np.errstate(divide="ignore", invalid="ignore"):
        return intrinsics.project(on_table)


def add_flat_parts(
    rgb,
    seg: Segmentation,
    *,
    colour_distance: float = COLOUR_DISTANCE,
    lightness_weight: float = LIGHTNESS_WEIGHT,
    shadow_lightness: float = SHADOW_LIGHTNESS,
    halo_px: int = HALO_PX,
    min_area_px: int = MIN_AREA_PX,
) -> Segmentation:
    """Add to a depth segmentation the parts of the object too flat for depth to see.

    1. Colour evidence: the pixels whose colour is more than
       ``colour_distance`` from the table's, or whose lightness is below
       ``shadow_lightness`` times the table's, opened with a 5 x 5 element to
       drop thin straps and specks, and connected to the depth mask. The
       table's colour is the median CIELAB colour of the table-plane inliers
       ``halo_px`` to ``4 * halo_px`` pixels around the depth mask; the
       distance weighs lightness by ``lightness_weight``, because a shadow on
       the table changes its lightness far more than its hue. A dark grey
       part on a light grey table differs in lightness only, hence the second
       test: no soft shadow is that dark.
    2. Flat parts: the colour evidence farther than ``halo_px`` from the depth
       mask, in pieces of at least ``min_area_px``. Nearer evidence is the
       band of shadow and the object's side seen by a tilted camera, which
       the depth outline already bounds better, and is ignored.
    3. The flat parts (with the colour evidence within ``halo_px`` of them,
       which joins them to the rest) are added to the depth mask, and the
       object is picked again as in the other methods (largest region not
       touching the image border, holes filled).

    Without flat parts the depth segmentation is returned unchanged.

    :func:`segment` calls this on the region seen above the table
    (``segment_depth(footprint=False)``) with the colour image registered to
    the depth image (:func:`register_colour`), and takes the footprint of the
    result afterwards.

    Parameters
    ----------
    rgb : (H, W, 3) uint8
        Colour image in RGB order, registered to the depth image, or (H, W) uint8 grayscale.
    seg : Segmentation
        From :func:`segment_depth` (it needs the table ``plane``), best without the footprint.
    colour_distance : float
        Euclidean distance in OpenCV's 8-bit CIELAB (L scaled to 0-255), after
        the lightness is multiplied by ``lightness_weight``.
    lightness_weight : float
        Weight of the lightness difference, 0-1.
    shadow_lightness : float
        Fraction of the table's lightness below which a pixel is object, 0-1 (0: no such test).
    halo_px : int
        As above, pixels.
    min_area_px : int
        Smallest flat part and smallest object, pixels.

    Returns
    -------
    Segmentation
        Method ``"depth+rgb"`` when flat parts were added, else ``seg``.

    Raises
    ------
    SegmentationError
        Kind ``"not-visible"`` when the grown object touches the image border.
    """
    image = _as_rgb(rgb)
    _check_same_size(image.shape, seg.mask.shape, "rgb image", "mask")
    colour_distance = _check_positive("colour_distance", colour_distance)
    lightness_weight = _check_fraction("lightness_weight", lightness_weight)
    shadow_lightness = _check_fraction("shadow_lightness", shadow_lightness)
    halo_px = _check_int("halo_px", halo_px, 1)
    min_area_px = _check_int("min_area_px", min_area_px, 1)
    if seg.plane is None or seg.plane.inliers.shape != seg.mask.shape:
        raise InputError("add_flat_parts needs a depth segmentation with its table plane")
    halo = _dilate(seg.mask, halo_px)
    unlike = _unlike_table(image, seg.mask, halo, seg.plane.inliers, colour_distance, lightness_weight,
                           shadow_lightness, halo_px)
    _, labels, stats, _ = cv2.connectedComponentsWithStats((unlike & ~halo).astype(np.uint8), connectivity=8)
    large = stats[:, cv2.CC_STAT_AREA] >= min_area_px
    large[0] = False
    flat = large[labels]
    if not flat.any():
        return seg
    grown = seg.mask | (unlike & _dilate(flat, halo_px))
    mask, notes = _pick_object(grown, np.zeros(grown.shape, dtype=bool), min_area_px, "in the depth and colour masks")
    result = _segmentation("depth+rgb", mask, notes, plane=seg.plane, filled_px=seg.filled_px, on_table=seg.on_table)
    return replace(result, warnings=(*seg.warnings, *result.warnings))


def _unlike_table(image, depth_mask, halo, table, colour_distance, lightness_weight, shadow_lightness, halo_px):
    """(H, W) bool: pixels of a colour unlike the table's, opened, connected to ``depth_mask`` (without it).

    ``halo`` is the depth mask dilated by ``halo_px``. The work is done in a
    window ``FLAT_WINDOW_PX`` beyond the table ring around the depth mask (a
    fraction of the frame), and again on the whole image only when the
    evidence found comes within reach of the opening of the window's edges
    inside the image, where it could continue: the result is the whole
    image's either way.
    """
    window = _grown_box(depth_mask, 4 * halo_px + FLAT_WINDOW_PX)
    options = (colour_distance, lightness_weight, shadow_lightness, halo_px)
    found = _unlike_in(image[window], depth_mask[window], halo[window], table[window], *options)
    if _reaches_inner_edge(found, window, depth_mask.shape, 2 * EVIDENCE_OPEN_PX + 1):
        return _unlike_in(image, depth_mask, halo, table, *options)
    unlike = np.zeros(depth_mask.shape, dtype=bool)
    unlike[window] = found
    return unlike


def _unlike_in(image, depth_mask, halo, table, colour_distance, lightness_weight, shadow_lightness, halo_px):
    """:func:`_unlike_table` on the given arrays (the whole image or a window holding the table ring)."""
    lab = cv2.cvtColor(np.ascontiguousarray(image), cv2.COLOR_RGB2LAB)
    ring = _dilate(depth_mask, 4 * halo_px) & ~halo & table
    if not ring.any():
        return np.zeros(depth_mask.shape, dtype=bool)
    # Squared distance per channel by table look-up, summed: 8-bit values less a median (a multiple
    # of 0.5) square to multiples of 0.25 below 2^16, which float32 and their sum hold exactly.
    table_lab = np.median(lab[ring], axis=0)
    squares = (np.arange(256.0)[:, None] - table_lab) ** 2
    per_channel = cv2.LUT(lab, squares.astype(np.float32)[None])
    unlike = cv2.transform(per_channel, np.array([[lightness_weight ** 2, 1.0, 1.0]])) > np.float64(colour_distance) ** 2
    unlike |= lab[..., 0] < shadow_lightness * table_lab[0]
    return _connected_to(_open(unlike, EVIDENCE_OPEN_PX) | depth_mask, depth_mask) & ~depth_mask


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

    A "registered" PrimeSense pair is not registered to the pixel: on the
    shared frames the depth outline lies 1-6 px above the colour outline
    (this finds dy = -1 to -6, dx = 0 or 1); the object's edges are used
    because the registration error of such sensors changes with depth.

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
    image = _as_rgb(rgb)
    d = as_depth(depth)
    _check_same_size(image.shape, d.shape, "rgb image", "depth image")
    _check_same_size(np.shape(mask), d.shape, "mask", "depth image")
    r = _check_int("max_offset_px", max_offset_px, 0)
    m = np.asarray(mask, dtype=bool)
    if not m.any():
        raise InputError("colour_offset needs a mask with at least one object pixel")
    rows, cols = _grown_box(m, REGISTRATION_MARGIN_PX)
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
    image = _as_rgb(rgb)
    dx, dy = offset
    shift = np.array([[1.0, 0.0, dx], [0.0, 1.0, dy]])
    return cv2.warpAffine(image, shift, image.shape[1::-1], flags=cv2.INTER_NEAREST, borderMode=cv2.BORDER_REPLICATE)


def _gradient_magnitude(image):
    return cv2.magnitude(cv2.Sobel(image, cv2.CV_32F, 1, 0), cv2.Sobel(image, cv2.CV_32F, 0, 1))


def _connected_to(region, mask):
    """(H, W) bool: the 8-connected parts of ``region`` that hold a pixel of ``mask`` (a subset of it)."""
    count, labels = cv2.connectedComponents(region.astype(np.uint8), connectivity=8)
    keep = np.zeros(count, dtype=bool)
    keep[labels[mask]] = True
    return keep[labels]


def _disc(radius):
    return cv2.getStructuringElement(cv2.MORPH_ELLIPSE, (2 * radius + 1, 2 * radius + 1))


def _dilate(mask, radius):
    return _morph(cv2.MORPH_DILATE, mask, radius)


def _open(mask, radius):
    return _morph(cv2.MORPH_OPEN, mask, radius)


def _morph(operation, mask, radius):
    """(H, W) bool: ``mask`` dilated or opened by a disc, as OpenCV does it on the whole image.

    The operation runs on the mask's bounding box grown by ``radius`` only: the
    result is empty farther out, and within the box every disc around a mask
    pixel is inside it (or beyond the image's edge, as on the whole image).
    """
    out = np.zeros(mask.shape, dtype=bool)
    if mask.any():
        box = _grown_box(mask, radius)
        out[box] = cv2.morphologyEx(mask[box].astype(np.uint8), operation, _disc(radius)) > 0
    return out


def _grown_box(mask, margin):
    """(rows, cols) slices of ``mask``'s bounding box grown by ``margin`` px, within the image; ``mask`` is not empty."""
    return _pixel_box(np.flatnonzero(mask.any(axis=1)), np.flatnonzero(mask.any(axis=0)), margin, mask.shape)


def _pixel_box(rows, cols, margin, shape):
    """(rows, cols) slices of the bounding box of the pixels (rows, cols), not empty, grown by ``margin`` px,
    within an image of ``shape``."""
    return (slice(max(rows.min() - margin, 0), min(rows.max() + margin + 1, shape[0])),
            slice(max(cols.min() - margin, 0), min(cols.max() + margin + 1, shape[1])))


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
        image (:func:`colour_offset`, :func:`register_colour`) before it is
        moved onto the table; :func:`segment_rgb` when there is no depth, or
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
    method = _check_choice("method", method, SEGMENT_METHODS)
    rgb_options = _check_options("rgb_options", rgb_options, segment_rgb)
    depth_options = _check_options("depth_options", depth_options, segment_depth)
    colour_options = _check_options("colour_options", colour_options, add_flat_parts)
    offset = None if colour_offset_px is None else _check_offset(colour_offset_px)
    if depth is not None and intrinsics is None:
        raise InputError("a depth image needs intrinsics")
    have_depth = depth is not None
    if rgb is not None and depth is not None:
        _check_same_size(np.shape(rgb), as_depth(depth).shape)
    if method == "rgb" or (method == "auto" and not have_depth):
        if rgb is None:
            raise InputError(f"method {method!r} needs an RGB image" + ("" if method == "rgb" else " or a depth image with intrinsics"))
        return segment_rgb(rgb, **rgb_options)
    if not have_depth:
        raise InputError("method 'depth' needs a depth image and intrinsics")
    if method == "depth" or rgb is None:
        return segment_depth(depth, intrinsics, **depth_options)
    seen_options = {**_defaults(segment_depth), **depth_options}
    footprint = seen_options.pop("footprint")
    try:
        seen, d = _seen_above_table(depth, intrinsics, **seen_options)
    except SegmentationError as err:
        if err.kind not in _DEPTH_FALLBACK_KINDS:
            raise
        note = f"depth segmentation failed ({err}); used the RGB method instead"
    else:
        if offset is None:
            offset = colour_offset(rgb, d, seen.mask)
        grown = add_flat_parts(register_colour(rgb, offset), seen, **colour_options)
        return _with_footprint(replace(grown, colour_offset_px=offset), d, intrinsics, footprint,
                               seen_options["min_area_px"])
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
        raise InputError(f"mask must be an (H, W) array, got shape {m.shape}")
    if not (m.dtype == bool or np.issubdtype(m.dtype, np.number)):
        raise InputError(f"mask must hold booleans or numbers, got {m.dtype}")
    min_area_px = _check_int("min_area_px", min_area_px, 1)
    with np.errstate(invalid="ignore"):
        region = np.nan_to_num(m.astype(float)) != 0
    picked, notes = _pick_object(region, np.zeros(m.shape, dtype=bool), min_area_px, "in the mask")
    return _segmentation("mask", picked, notes)


def _pick_object(candidates, outside, min_area_px, where):
    """The largest candidate region touching neither the image border nor ``outside``, holes filled; the warnings."""
    count, labels, stats, _ = cv2.connectedComponentsWithStats(candidates.astype(np.uint8), connectivity=8)
    count -= 1
    if count == 0:
        raise SegmentationError("no-object", f"no object found: no region {where}")
    areas = stats[:, cv2.CC_STAT_AREA]
    beyond = np.pad(outside, 1, constant_values=True).astype(np.uint8)
    near = cv2.dilate(beyond, np.ones((3, 3), np.uint8))[1:-1, 1:-1] > 0
    touching = np.zeros(count + 1, dtype=bool)
    touching[labels[near]] = True
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


def _fill_holes(region):
    """(H, W) bool: ``region`` with its holes filled, for a region that does not touch the image border.

    Filled on the region's bounding box grown by one pixel: that frame is
    background connected to the image border, so the holes are the same.
    """
    rows, cols = np.flatnonzero(region.any(axis=1)), np.flatnonzero(region.any(axis=0))
    box = np.s_[rows[0] - 1: rows[-1] + 2, cols[0] - 1: cols[-1] + 2]
    out = np.zeros(region.shape, dtype=bool)
    out[box] = ndimage.binary_fill_holes(region[box])
    return out


def _segmentation(method, mask, notes, *, plane=None, filled_px=0, on_table=False, colour_offset_px=None) -> Segmentation:
    contour = mask_contour(mask)
    for note in notes:
        warnings.warn(note, PerceptionWarning, stacklevel=3)
    return Segmentation(method, mask, contour, int(mask.sum()), tuple(notes), plane, filled_px, on_table,
                        colour_offset_px)


def mask_contour(mask) -> np.ndarray:
    """(n, 2) float: outer outline (u, v) of a one-region mask, simplified (see :class:`Segmentation`).

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
    if len(poly) > MAX_CONTOUR_POINTS:
        poly = poly[np.linspace(0, len(poly), MAX_CONTOUR_POINTS, endpoint=False).astype(int)]
    if len(poly) < 3 or cv2.contourArea(poly.astype(np.float32)) <= 0:
        raise SegmentationError("tiny", f"the object's outline has no interior ({len(outline)} pixels in a line)")
    return poly


def _border_connected(missing) -> np.ndarray:
    """(H, W) bool: the pixels of ``missing`` connected (8-neighbour) to the image border."""
    _, labels = cv2.connectedComponents(np.pad(missing, 1, constant_values=True).astype(np.uint8), connectivity=8)
    return (labels == labels[0, 0])[1:-1, 1:-1]


# ---------------------------------------------------------------------------
# Metric contour and approach depth
# ---------------------------------------------------------------------------


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
    _check_same_size(m.shape, d.shape, "mask", "depth image")
    offset = _check_finite("offset", offset)
    valid = valid_depth(d, depth_range)
    if not (m & valid).any():
        lo, hi = _check_range(depth_range)
        raise InputError(f"no valid depth inside the object: all {int(m.sum())} pixels are 0, NaN or outside [{lo}, {hi}] m")
    return float(_denoised_at(d, valid, *np.nonzero(m & valid)).min()) + offset


def denoised_depth(depth, valid) -> np.ndarray:
    """(H, W) float: the valid readings median-filtered over ``APPROACH_MEDIAN_PX`` pixels, for nearest points.

    Invalid readings count as infinitely far, so they never make a pixel
    nearer; a pixel whose window is mostly invalid keeps its own reading.

    Parameters
    ----------
    depth : (H, W) float
        Depth in meters.
    valid : (H, W) bool
        The valid readings (:func:`valid_depth`).

    Examples
    --------
    >>> depth = np.full((5, 5), 0.7); depth[2, 2] = 0.5   # a flying pixel
    >>> round(float(denoised_depth(depth, depth > 0).min()), 6)
    0.7
    """
    smooth = cv2.medianBlur(np.where(valid, depth, np.inf).astype(np.float32), APPROACH_MEDIAN_PX)
    return np.where(np.isfinite(smooth), smooth, depth)


def _denoised_at(depth, valid, rows, cols) -> np.ndarray:
    """(n,) float: :func:`denoised_depth` at the pixels (rows, cols), not empty.

    The filter runs on their bounding box grown by its reach only: inside the box every window is
    the whole image's, and where the box meets the image's edge it is that edge.
    """
    box = _pixel_box(rows, cols, APPROACH_MEDIAN_PX // 2, depth.shape)
    return denoised_depth(depth[box], valid[box])[rows - box[0].start, cols - box[1].start]


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
    """A pixel contour in meters, in the plane the hand plans in (eq 3.1-3.2, section 3.1.1).

    Each contour pixel's ray is intersected with a *planning plane*:

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
    intrinsics.check_shape(d.shape, "depth image")
    depth_mode = _check_choice("depth_mode", depth_mode, DEPTH_MODES)
    offset = _check_finite("offset", offset)
    if on_table and depth_mode != "max":
        raise InputError("depth_mode 'plane' places the contour at the object's top, but a footprint lies on the table: "
                         "segment without the footprint, or use depth_mode 'max'")
    contour = _check_contour_px(contour_px, d.shape)
    outline, inside = _rasterize(contour, d.shape)
    valid = valid_depth(d, depth_range)
    on_contour = outline & valid
    if not on_contour.any():
        lo, hi = _check_range(depth_range)
        raise InputError(
            f"no valid depth on the contour: all {int(outline.sum())} contour pixels are 0, NaN or outside [{lo}, {hi}] m"
        )
    if plane is None:
        plane = _table_or_none(d, intrinsics, depth_range)
    if on_table and plane is None:
        raise InputError("a footprint contour needs the table plane, and none was found in the depth image")
    tilt = None if plane is None else plane.tilt
    reference = plane if tilt is not None and tilt > TILT_PLANE_THRESHOLD else _IMAGE_PLANE
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
        heights = reference.height(_points(d, intrinsics, rows, cols))
        level = heights[outline[rows, cols]].min() if depth_mode == "max" else heights.max()
    rotation = _plane_frame(reference.normal)
    origin, xy = _intersect(rays, reference, float(level), rotation)
    nearest = _points_at(_denoised_at(d, valid, rows, cols), intrinsics, rows, cols) @ rotation[:, 2]
    return MetricContour(
        contour_xy=xy,
        R_camera_plane=rotation,
        origin=origin,
        z_max=float(d[on_contour].max()),
        approach_depth=float(nearest.min()) + offset,
        invalid_depth_px=int((outline & ~valid).sum()),
        tilt=tilt,
        frame="camera" if reference is _IMAGE_PLANE else "table",
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
        above = valid & (_heights(depth, intrinsics, plane) > PLANE_THRESHOLD)
    rows, cols = np.nonzero(_connected_to(above, inside & above))
    keep, u, v = _in_image(_footprint_pixels(depth, intrinsics, plane, rows, cols), inside.shape)
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


def _plane_frame(normal) -> np.ndarray:
    """(3, 3): columns x, y, z of a frame with z = -normal and x along the camera's x projected on the plane."""
    z = -np.asarray(normal, dtype=float)
    x = np.array([1.0, 0.0, 0.0]) - z[0] * z
    x /= np.linalg.norm(x)
    return np.column_stack([x, np.cross(z, x), z])


def _intersect(rays, plane, level, rotation):
    """Planning-frame origin (3,) and (n, 2) coordinates of rays meeting the plane at ``height == level``."""
    along = rays @ plane.normal
    cosine = -along / np.linalg.norm(rays, axis=1)
    if np.any(cosine < MIN_RAY_COSINE):
        raise InputError(
            f"contour rays graze the planning plane (cosine {cosine.min():.3f} < {MIN_RAY_COSINE}): "
            f"the camera is too oblique to the table, or its field of view too wide"
        )
    reach = level - plane.offset
    if reach >= 0:
        raise InputError("the contour's plane is not in front of the camera: the depth does not fit a table below it")
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


# ---------------------------------------------------------------------------
# Argument checks
# ---------------------------------------------------------------------------


def _as_rgb(rgb) -> np.ndarray:
    img = _check_image(rgb)
    return cv2.cvtColor(img, cv2.COLOR_GRAY2RGB) if img.ndim == 2 else img


def _as_gray(rgb) -> np.ndarray:
    img = _check_image(rgb)
    return img if img.ndim == 2 else cv2.cvtColor(img, cv2.COLOR_RGB2GRAY)


def _check_image(rgb) -> np.ndarray:
    img = np.asarray(rgb)
    if img.dtype != np.uint8:
        raise InputError(f"rgb image must be 8-bit (uint8), got {img.dtype}")
    if (img.ndim == 2 or (img.ndim == 3 and img.shape[2] == 3)) and img.size:
        return np.ascontiguousarray(img)
    raise InputError(f"rgb image must be (H, W, 3) or (H, W), got shape {img.shape}")


def _check_contour_px(contour_px, shape) -> np.ndarray:
    pts = np.asarray(contour_px, dtype=float)
    if pts.ndim != 2 or pts.shape[1] != 2 or len(pts) < 3:
        raise InputError(f"contour_px must be an (n, 2) array of at least 3 pixels (u, v), got shape {pts.shape}")
    if not np.all(np.isfinite(pts)):
        raise InputError(f"contour_px point {int(np.flatnonzero(~np.all(np.isfinite(pts), axis=1))[0])} is not finite")
    outside = (pts[:, 0] < -0.5) | (pts[:, 0] > shape[1] - 0.5) | (pts[:, 1] < -0.5) | (pts[:, 1] > shape[0] - 0.5)
    if outside.any():
        i = int(np.flatnonzero(outside)[0])
        raise InputError(f"contour_px point {i} {tuple(pts[i])} is outside the {shape[1]}x{shape[0]} image")
    return pts


def _check_same_size(shape_a, shape_b, name_a="rgb image", name_b="depth image"):
    if tuple(shape_a[:2]) != tuple(shape_b[:2]):
        raise InputError(
            f"{name_a} is {shape_a[1]}x{shape_a[0]} but {name_b} is {shape_b[1]}x{shape_b[0]} (width x height)"
        )


def _check_options(name, options, function) -> dict:
    if options is None:
        return {}
    if not isinstance(options, dict):
        raise InputError(f"{name} must be a dict of keyword options, got {type(options).__name__}")
    allowed = list(_defaults(function))
    unknown = sorted(set(options) - set(allowed))
    if unknown:
        raise InputError(f"{name}: unknown option {unknown[0]!r}; choose from {', '.join(allowed)}")
    return dict(options)


def _defaults(function) -> dict:
    """The keyword-only options of ``function`` with their defaults."""
    return {p.name: p.default for p in signature(function).parameters.values() if p.kind is Parameter.KEYWORD_ONLY}


def _check_offset(offset) -> tuple[int, int]:
    values = np.asarray(offset, dtype=object)
    if values.shape != (2,) or not all(isinstance(v, (int, np.integer)) and not isinstance(v, bool) for v in values):
        raise InputError(f"colour_offset_px must be two integers (dx, dy), got {offset!r}")
    return int(values[0]), int(values[1])


def _check_choice(name, value, choices) -> str:
    if value not in choices:
        raise InputError(f"{name} must be one of {', '.join(map(repr, choices))}, got {value!r}")
    return value


def _check_int(name, value, minimum, odd=False) -> int:
    if isinstance(value, bool) or not isinstance(value, (int, np.integer)) or value < minimum:
        raise InputError(f"{name} must be an integer >= {minimum}, got {value!r}")
    if odd and value % 2 == 0:
        raise InputError(f"{name} must be odd, got {value}")
    return int(value)


def _check_finite(name, value) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float, np.integer, np.floating)) or not math.isfinite(value):
        raise InputError(f"{name} must be a finite number, got {value!r}")
    return float(value)


def _check_fraction(name, value) -> float:
    value = _check_finite(name, value)
    if not 0.0 <= value <= 1.0:
        raise InputError(f"{name} must be in [0, 1], got {value}")
    return value


def _check_positive(name, value) -> float:
    if _check_finite(name, value) <= 0:
        raise InputError(f"{name} must be positive, got {value!r}")
    return float(value)


def _check_range(depth_range) -> tuple[float, float]:
    try:
        lo, hi = (_check_finite("depth_range", v) for v in depth_range)
    except (TypeError, ValueError):
        raise InputError(f"depth_range must be two numbers (near, far) in meters, got {depth_range!r}") from None
    if not 0 <= lo < hi:
        raise InputError(f"depth_range must satisfy 0 <= near < far, got ({lo}, {hi})")
    return lo, hi
