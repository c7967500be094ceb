"""The support surface: the plane the objects rest on, a table or a bin's floor.

The plane with most pixels (:func:`~contourgrasp.perception.fit_table_plane`)
is the table when one object stands on an empty table, but not in a bin
photo: there the conveyor or floor around the bin can hold more pixels than
the bin's floor, and everything in the bin, walls included, stands on it as
one region. So :func:`find_support` also looks for up to
``SUPPORT_PLANES - 1`` further planes parallel to the dominant one (each fitted
by RANSAC to the pixels no plane found so far holds, within
``SUPPORT_PARALLEL`` of its normal, at least ``MIN_SUPPORT_FRACTION`` of the
valid pixels, and at least ``MIN_HEIGHT`` from every other), and takes the
**highest** of them on which a wholly visible candidate stands: a region
(:func:`~contourgrasp.perception.find_candidates`) at least
``SUPPORT_RING_FRACTION`` of whose valid neighbours (a ``SUPPORT_RING_PX`` ring
around it) lie on that plane. A bin's floor lies above the conveyor and
holds the objects in the bin; a table below a mat, or the floor beyond the
table, holds nothing wholly in view. When no plane holds a candidate the
dominant plane is the support, as before.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from .. import validation
from ..errors import PerceptionError, SegmentationError
from ..tolerances import (MIN_AREA_PX, MIN_HEIGHT, MIN_SUPPORT_FRACTION, PLANE_STRIDE, PLANE_THRESHOLD,
                          SENSOR_RANGE, SUPPORT_PARALLEL, SUPPORT_PLANES, SUPPORT_RING_FRACTION, SUPPORT_RING_PX)
from ._pixels import dilate
from .camera import Intrinsics, as_depth, check_intrinsics, pixel_points, valid_depth
from .candidates import Candidate, find_candidates
from .table import Plane, fit_plane, fit_table_plane, heights


@dataclass(frozen=True, eq=False)
class Support:
    """The support surface found in a depth image, and what stands on it.

    Attributes
    ----------
    plane : Plane
        The support surface; ``inliers`` (H, W) bool.
    candidates : tuple of Candidate
        Every region standing on it (:func:`find_candidates`), largest first.
    reason : str
        How it was chosen, one line.
    planes : tuple of Plane
        Every plane considered, the dominant one first.
    """

    plane: Plane
    candidates: tuple[Candidate, ...]
    reason: str
    planes: tuple[Plane, ...]


def find_support(depth, intrinsics: Intrinsics, *, min_height: float = MIN_HEIGHT, min_area_px: int = MIN_AREA_PX,
                 depth_range=SENSOR_RANGE, seed: int = 0) -> Support:
    """The plane the objects rest on, and the candidates standing on it (method in the module docstring).

    Parameters
    ----------
    depth : (H, W) or (H, W, 1) float
        Depth in meters, small holes already filled if wanted.
    intrinsics : Intrinsics
        Of the depth image.
    min_height, min_area_px, depth_range
        As in :func:`find_candidates`.
    seed : int
        RANSAC seed.

    Returns
    -------
    Support

    Raises
    ------
    SegmentationError
        Kind ``"no-plane"``: no dominant plane (:func:`fit_table_plane`).
    """
    d = as_depth(depth)
    check_intrinsics(intrinsics).check_shape(d.shape, "depth image")
    seed = validation.integer("seed", seed, 0, error=PerceptionError)
    dominant = fit_table_plane(d, intrinsics, depth_range=depth_range, seed=seed)
    planes = (dominant, *_parallel_planes(d, intrinsics, dominant, depth_range, seed, min_height))
    options = {"min_height": min_height, "min_area_px": min_area_px, "depth_range": depth_range}
    valid = valid_depth(d, depth_range)
    found = {}
    for plane in sorted(planes, key=lambda p: p.offset):  # nearest the camera (highest) first
        found[id(plane)] = find_candidates(d, intrinsics, plane, **options)
        held = [c for c in found[id(plane)] if c.in_view and _stands_on(c, plane, valid)]
        if held:
            return Support(plane, found[id(plane)], _reason(plane, dominant, len(held), len(planes)), planes)
    return Support(dominant, found[id(dominant)],
                   "the dominant plane (most pixels): no plane holds a wholly visible candidate", planes)


def _reason(plane: Plane, dominant: Plane, held: int, planes: int) -> str:
    """Why ``plane`` is the support, one line."""
    what = (f"the dominant plane (most pixels: {int(dominant.inliers.sum())})" if plane is dominant else
            f"a plane {1000 * (dominant.offset - plane.offset):.0f} mm above the dominant one "
            f"(which has most pixels: {int(dominant.inliers.sum())}) and parallel to it")
    among = f"; the highest such of the {planes} parallel planes found" if planes > 1 else ""
    return f"{what}: {held} wholly visible candidate(s) stand on it{among}"


def _stands_on(candidate: Candidate, plane: Plane, valid) -> bool:
    """Whether at least ``SUPPORT_RING_FRACTION`` of the valid pixels around ``candidate`` lie on ``plane``."""
    ring = dilate(candidate.mask, SUPPORT_RING_PX) & ~candidate.mask & valid
    count = int(ring.sum())
    return count > 0 and int((ring & plane.inliers).sum()) >= SUPPORT_RING_FRACTION * count


def _parallel_planes(depth, intrinsics, dominant: Plane, depth_range, seed, min_height) -> list[Plane]:
    """Up to ``SUPPORT_PLANES - 1`` further planes parallel to ``dominant`` (module docstring), (H, W) inliers."""
    valid = valid_depth(depth, depth_range)
    taken = dominant.inliers.copy()
    found: list[Plane] = []
    total = max(int(valid.sum()), 1)
    for _ in range(2 * SUPPORT_PLANES):  # a plane that is not parallel (a wall) takes a try too
        if len(found) == SUPPORT_PLANES - 1:
            break
        rest = valid & ~taken
        rows, cols = np.nonzero(rest[::PLANE_STRIDE, ::PLANE_STRIDE])
        if len(rows) < 3 or rest.sum() < MIN_SUPPORT_FRACTION * total:
            break
        try:
            plane = fit_plane(pixel_points(depth, intrinsics, PLANE_STRIDE * rows, PLANE_STRIDE * cols), seed=seed)
        except SegmentationError:
            break
        near = np.abs(heights(depth, intrinsics, plane)) < PLANE_THRESHOLD
        inliers = rest & near
        if inliers.sum() < MIN_SUPPORT_FRACTION * total:
            break
        taken |= inliers
        angle = math.acos(min(1.0, float(plane.normal @ dominant.normal)))
        apart = all(abs(plane.offset - other.offset) >= min_height for other in (dominant, *found))
        if angle <= SUPPORT_PARALLEL and apart:
            found.append(replace(plane, inliers=valid & near))
    return found
