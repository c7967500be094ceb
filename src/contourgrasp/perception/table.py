"""The table: a RANSAC plane through the depth points, and heights above it (thesis 4.1.3's scene).

The camera looks down on a table that fills much of the view (section
4.1.3), so the dominant plane facing the camera is taken to be the table; its
tilt is the camera's deviation from top-down.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace

import cv2
import numpy as np

from .. import validation
from ..errors import PerceptionError, SegmentationError
from ..tolerances import (MAX_TABLE_TILT, UNIT_TOLERANCE, MIN_FLAT_HEIGHT, MIN_PLANE_FRACTION, PLANE_ITERATIONS, PLANE_SAMPLE,
                          PLANE_STRIDE, PLANE_THRESHOLD, SENSOR_RANGE)
from ._frame import memoised
from .camera import Intrinsics, as_depth, check_intrinsics, pixel_points, valid_depth


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

    def __post_init__(self):
        normal = validation.finite_array("plane: normal", self.normal, (3,), error=PerceptionError)
        if abs(float(np.linalg.norm(normal)) - 1.0) > UNIT_TOLERANCE:
            raise PerceptionError(f"plane: normal must be a unit vector, got length {np.linalg.norm(normal):.6g}")
        object.__setattr__(self, "normal", normal)
        object.__setattr__(self, "offset", validation.finite("plane: offset", self.offset, error=PerceptionError))
        inliers = np.asarray(self.inliers)
        if inliers.dtype != bool:
            raise PerceptionError(f"plane: inliers must be a bool array, got dtype {inliers.dtype}")
        object.__setattr__(self, "inliers", inliers)

    @property
    def tilt(self) -> float:
        """Angle (rad) between the plane's normal and the optical axis: 0 for a top-down camera."""
        return float(math.acos(min(1.0, -float(self.normal[2]))))

    def height(self, points) -> np.ndarray:
        """(...) float: signed height (m) of (..., 3) camera-frame points above the plane."""
        return np.asarray(points, dtype=float) @ self.normal + self.offset

    @property
    def key(self) -> tuple:
        """The plane's normal and offset as a hashable tuple: one frame's images above it are kept by it
        (:func:`~contourgrasp.perception.one_frame`)."""
        return (*map(float, self.normal), float(self.offset))


#: The thesis's plane: parallel to the image plane; height = -z.
IMAGE_PLANE = Plane(normal=np.array([0.0, 0.0, -1.0]), offset=0.0)


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
    p = validation.float_array("points", points, error=PerceptionError)
    if p.ndim != 2 or p.shape[1] != 3:
        raise PerceptionError(f"points must be an (n, 3) array, got shape {p.shape}")
    threshold = validation.positive("threshold", threshold, error=PerceptionError)
    iterations = validation.integer("iterations", iterations, 1, error=PerceptionError)
    sample = validation.integer("sample", sample, 3, error=PerceptionError)
    seed = validation.integer("seed", seed, 0, error=PerceptionError)
    max_tilt = validation.finite("max_tilt", max_tilt, error=PerceptionError)
    finite = np.isfinite(p[:, 0]) & np.isfinite(p[:, 1]) & np.isfinite(p[:, 2])  # np.all(axis=1) walks rows: 5x slower
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
    distance = normals @ voters.T  # (candidates, sample): in place, the same arithmetic without two temporaries
    distance += offsets[:, None]
    best = _best_candidate(cloud, normals, offsets, np.abs(distance, out=distance) < threshold, threshold)
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
    Its ``tilt`` is the camera's deviation from top-down (the shared
    PrimeSense frames' are in docs/perception.md).

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
    stride = validation.integer("stride", stride, 1, error=PerceptionError)
    d = as_depth(depth)
    check_intrinsics(intrinsics).check_shape(d.shape, "depth image")
    valid = valid_depth(d, depth_range)
    rows, cols = np.nonzero(valid[::stride, ::stride])
    grid = pixel_points(d, intrinsics, stride * rows, stride * cols)
    plane = fit_plane(grid, threshold=threshold, iterations=iterations, seed=seed)
    inliers = valid & (np.abs(heights(d, intrinsics, plane)) < threshold)
    share = inliers.sum() / max(int(valid.sum()), 1)
    if share < min_fraction:
        raise SegmentationError(
            "no-plane",
            f"no table plane: the best plane holds {share:.0%} of the valid depth pixels (need {min_fraction:.0%})",
        )
    return replace(plane, inliers=inliers)


def heights(depth, intrinsics, plane) -> np.ndarray:
    """(H, W) float: ``plane.height`` of every pixel's point, without building the (H, W, 3) cloud.

    The point of pixel (u, v) is z r with r = ((u - cx) / fx, (v - cy) / fy, 1),
    so its height is z (normal . r) + offset, where normal . r is a column term
    plus a row term. Non-finite depths give non-finite or NaN heights.
    """
    normal = plane.normal

    def compute():
        cols = normal[0] * (np.arange(intrinsics.width) - intrinsics.cx) / intrinsics.fx + normal[2]
        rows = normal[1] * (np.arange(intrinsics.height) - intrinsics.cy) / intrinsics.fy
        with np.errstate(invalid="ignore"):
            return depth * (rows[:, None] + cols) + plane.offset

    return memoised(depth, ("heights", intrinsics, plane.key), compute)


def footprint_pixels(depth, intrinsics: Intrinsics, plane: Plane, rows, cols) -> np.ndarray:
    """(n, 2) float: pixels (u, v) where the points of pixels (rows, cols), moved along the table normal onto the table, are seen."""
    points = pixel_points(depth, intrinsics, rows, cols)
    on_table = points - plane.height(points)[:, None] * plane.normal
    with np.errstate(divide="ignore", invalid="ignore"):
        return intrinsics.project(on_table)


def plane_axes(normal) -> np.ndarray:
    """(3, 3): columns x, y, z of a frame with z = -normal and x along the camera's x projected on the plane.

    The planning frame of a tilted camera (:func:`~contourgrasp.perception.contour_to_metric`) and the
    footprint's grid (:func:`~contourgrasp.perception.object_footprint`)."""
    z = -np.asarray(normal, dtype=float)
    x = np.array([1.0, 0.0, 0.0]) - z[0] * z
    x /= np.linalg.norm(x)
    return np.column_stack([x, np.cross(z, x), z])


def table_points(intrinsics: Intrinsics, plane: Plane, rows, cols) -> np.ndarray:
    """(..., 3) float: where the rays of pixels (rows, cols) meet ``plane``; NaN where they miss it (behind the camera)."""
    rays = intrinsics.rays(np.stack(np.broadcast_arrays(cols, rows), axis=-1)).reshape(*np.shape(rows), 3)
    with np.errstate(divide="ignore", invalid="ignore"):
        reach = -plane.offset / (rays @ plane.normal)
    reach = np.where(reach > 0, reach, np.nan)
    return reach[..., None] * rays


def median_heights(height) -> np.ndarray:
    """(H, W) float32: ``height`` median-filtered over 5 x 5 pixels: the noise cut about fivefold, a part's edge kept."""
    return cv2.medianBlur(np.ascontiguousarray(height, dtype=np.float32), 5)


def above_table_noise(filtered, ring, sigmas: float) -> np.ndarray:
    """(H, W) bool: the pixels of ``filtered`` (:func:`median_heights`) above its median on ``ring`` by more than
    ``sigmas`` times its spread there (the median absolute deviation scaled to a Gaussian's sigma) and
    ``MIN_FLAT_HEIGHT``; ``ring`` (H, W) bool, the table's pixels, holds one at least.

    Examples
    --------
    >>> h = np.zeros((20, 20), np.float32); h[::2, ::2] = 0.001; h[5:15, 8:12] = 0.004
    >>> low = above_table_noise(median_heights(h), h < 0.002, 5.0)
    >>> bool(low[10, 10]), bool(low[2, 2])
    (True, False)
    """
    on_table = filtered[ring]
    level = np.median(on_table)
    spread = 1.4826 * np.median(np.abs(on_table - level))
    return filtered > level + max(sigmas * spread, MIN_FLAT_HEIGHT)
