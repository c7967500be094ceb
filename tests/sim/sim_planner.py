"""Test helpers for the simulation: a minimal depth-threshold planner and the shared-data path.

(A plain module, not a conftest: ``tests/conftest.py`` is imported as ``conftest`` by other tests.)

The planner is a stand-in for the project's perception, kept deliberately
simple: object = pixels well above the table, largest contour, pixels to meters
with eq 3.1-3.2 at the largest depth found on the contour, grasp synthesis, and
the approach depth of section 3.1.1 (smallest depth inside the contour + 1 cm).
"""

from pathlib import Path

import cv2
import numpy as np
import pytest

import contourgrasp
from contourgrasp.sim import pose_matrix

#: Pixels this much (m) nearer than the table belong to the object.
ABOVE_TABLE = 0.008
SHARED_DATA = Path(__file__).resolve().parents[2].parent / "shared" / "data"


def object_mask(depth: np.ndarray) -> np.ndarray:
    """(H, W) uint8: 255 where the depth is well above the table.

    The table is the far end of the valid depths (90th percentile: robust to noise, and the
    table need not fill most of the picture).
    """
    valid = depth > 0
    table = float(np.percentile(depth[valid], 90))
    mask = (valid & (depth < table - ABOVE_TABLE)).astype(np.uint8) * 255
    return cv2.morphologyEx(mask, cv2.MORPH_CLOSE, np.ones((5, 5), np.uint8))


def largest_contour(mask: np.ndarray) -> np.ndarray:
    """(n, 2) int: pixel outline (u, v) of the largest blob; NoFeasibleGrasp when there is none."""
    contours, _ = cv2.findContours(mask, cv2.RETR_EXTERNAL, cv2.CHAIN_APPROX_NONE)
    if not contours:
        raise contourgrasp.NoFeasibleGrasp("no object above the table")
    return max(contours, key=cv2.contourArea)[:, 0, :]


def depth_planner(rgb, depth, intrinsics, *, hand="five-finger-linear", xy_step=0.02):
    """``planner(rgb, depth, intrinsics) -> (T_camera_hand, approach_depth)`` from the depth image alone."""
    pixels = largest_contour(object_mask(depth))
    on_contour = depth[pixels[:, 1], pixels[:, 0]]
    z_max = float(on_contour[on_contour > 0].max())  # 3.1: the largest depth on the contour
    xy = np.c_[(pixels[:, 0] - intrinsics.cx) / intrinsics.fx, (pixels[:, 1] - intrinsics.cy) / intrinsics.fy] * z_max
    inside = np.zeros(depth.shape, np.uint8)
    cv2.drawContours(inside, [pixels[:, None, :]], -1, 255, thickness=cv2.FILLED)
    approach = float(depth[(inside > 0) & (depth > 0)].min()) + 0.01  # 3.1.1
    plan = contourgrasp.synthesize(xy, hand, xy_step=xy_step)
    x, y, yaw = plan.pose
    return pose_matrix(x, y, yaw, approach), approach


def require_shared_data() -> Path:
    """``<repo>/../shared/data``, or skip the test when it is absent."""
    if not SHARED_DATA.is_dir():
        pytest.skip(f"shared test data not found at {SHARED_DATA}")
    return SHARED_DATA
