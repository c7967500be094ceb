"""Shared scenes of the perception tests: ray-cast tables and objects of known geometry, the real frames."""

from __future__ import annotations

import math
import os
from pathlib import Path

import numpy as np
import pytest

from contourgrasp.perception import Intrinsics

H, W, F = 480, 640, 525.0
CAMERA = Intrinsics(fx=F, fy=F, cx=(W - 1) / 2, cy=(H - 1) / 2, width=W, height=H)
TABLE_RGB = np.array([150, 230, 60], dtype=np.uint8)
OBJECT_RGB = np.array([40, 50, 140], dtype=np.uint8)


def render(*, tilt_deg=0.0, distance=0.7, radius=0.04, height=0.03, centre=(0.0, 0.0), kind="cylinder", camera=CAMERA):
    """Ray-cast a table tilted about the camera's x axis with one object standing on it.

    ``kind``: "cylinder" (radius, height), "disc" (a wall-less disc floating at
    ``height``, whose outline is exactly a circle in its plane), "box"
    (half-sizes radius x radius, height), or "none". ``centre`` is the object's
    (x, y) on the table, from where the optical axis meets it, along the
    planning frame's axes (x = camera x, y toward the image bottom). Returns
    depth, rgb, the true object mask and the table normal (toward the camera).
    """
    o, d, up = _rays_in_object_frame(tilt_deg, distance, centre, camera)
    with np.errstate(divide="ignore", invalid="ignore"):
        table = -o[2] / d[..., 2]
        hit = _object_hit(o, d, kind, radius, height)
    depth = np.where(hit < table, hit, table)
    mask = hit < table
    rgb = np.where(mask[..., None], OBJECT_RGB, TABLE_RGB).astype(np.uint8)
    return depth, rgb, mask, up


def render_footprint(*, tilt_deg=0.0, distance=0.7, radius=0.04, centre=(0.0, 0.0), kind="cylinder", camera=CAMERA):
    """(H, W) bool: the pixels that see the table within the object's base, as :func:`render` places it."""
    o, d, _ = _rays_in_object_frame(tilt_deg, distance, centre, camera)
    table = -o[2] / d[..., 2]
    x, y = o[0] + table * d[..., 0], o[1] + table * d[..., 1]
    if kind == "box":
        return (np.abs(x) <= radius) & (np.abs(y) <= radius)
    return x**2 + y**2 <= radius**2


def _rays_in_object_frame(tilt_deg, distance, centre, camera):
    """Camera origin (3,) and pixel rays (H, W, 3) in a frame on the table at the object's centre, z up; the table normal."""
    t = math.radians(tilt_deg)
    up = np.array([0.0, -math.sin(t), -math.cos(t)])
    axes = np.column_stack([[1.0, 0.0, 0.0], np.cross([1.0, 0.0, 0.0], up), up])
    base = np.array([0.0, 0.0, distance / math.cos(t)]) + axes[:, :2] @ np.asarray(centre, dtype=float)
    v, u = np.indices(camera.shape, dtype=float)
    rays = np.stack([(u - camera.cx) / camera.fx, (v - camera.cy) / camera.fy, np.ones_like(u)], axis=-1)
    return -base @ axes, rays @ axes, up


def _object_hit(o, d, kind, radius, height):
    none = np.full(d.shape[:2], np.inf)
    if kind == "none":
        return none
    top = (height - o[2]) / d[..., 2]
    px, py = o[0] + top * d[..., 0], o[1] + top * d[..., 1]
    if kind == "box":
        cap = np.where((np.abs(px) <= radius) & (np.abs(py) <= radius), top, np.inf)
        slabs = [(-radius - o[i]) / d[..., i] for i in range(2)] + [(radius - o[i]) / d[..., i] for i in range(2)]
        enter = np.maximum(np.minimum(slabs[0], slabs[2]), np.minimum(slabs[1], slabs[3]))
        leave = np.minimum(np.maximum(slabs[0], slabs[2]), np.maximum(slabs[1], slabs[3]))
        z = o[2] + enter * d[..., 2]
        side = np.where((enter <= leave) & (z >= 0) & (z <= height), enter, np.inf)
        return np.minimum(cap, side)
    cap = np.where(px**2 + py**2 <= radius**2, top, np.inf)
    if kind == "disc":
        return cap
    a = d[..., 0] ** 2 + d[..., 1] ** 2
    b = 2 * (o[0] * d[..., 0] + o[1] * d[..., 1])
    disc = b**2 - 4 * a * (o[0] ** 2 + o[1] ** 2 - radius**2)
    enter = (-b - np.sqrt(np.maximum(disc, 0))) / (2 * a)
    z = o[2] + enter * d[..., 2]
    side = np.where((disc >= 0) & (z >= 0) & (z <= height), enter, np.inf)
    return np.minimum(cap, side)


def iou(a, b) -> float:
    return float((a & b).sum() / max((a | b).sum(), 1))


def extents(xy) -> np.ndarray:
    return np.ptp(np.asarray(xy), axis=0)


def with_flat_part(rgb, truth, colour=(230, 230, 230)):
    """The scene with a flat plate (table height, another colour) joined to the object's right side."""
    rows, cols = np.nonzero(truth)
    plate = np.zeros_like(truth)
    plate[rows.min() + 5: rows.max() - 5, cols.max() - 2: cols.max() + 60] = True
    painted = rgb.copy()
    painted[plate & ~truth] = colour
    return painted, truth | plate


def with_plate(rgb, truth, length):
    """The scene with a light plate 30 px wide reaching ``length`` px to the right of the object."""
    rows, cols = np.nonzero(truth)
    plate = np.zeros_like(truth)
    plate[rows.min() + 5: rows.min() + 35, cols.max() - 2: cols.max() + length] = True
    painted = rgb.copy()
    painted[plate & ~truth] = (230, 230, 230)
    return painted, truth | plate


def shifted(rgb, dx, dy):
    """The colour image as a sensor misregistered by (dx, dy) would give it: pixel (u, v) shows what depth sees at (u + dx, v + dy)."""
    return np.roll(rgb, (-dy, -dx), axis=(0, 1))


def shared_data() -> Path:
    return Path(os.environ.get("CONTOURGRASP_SHARED_DATA", Path(__file__).resolve().parents[3] / "shared" / "data"))


SINGLE = shared_data() / "rgbd" / "gqcnn_primesense_single_object"


BAR_CLAMP = shared_data() / "rgbd" / "gqcnn_primesense_overhead_bar_clamp"


needs_data = pytest.mark.skipif(
    not SINGLE.is_dir(), reason=f"real RGB-D frames not found at {SINGLE} (set CONTOURGRASP_SHARED_DATA)"
)


#: Footprint (short, long side, m) of each object, from shared/data/README.md.
FOOTPRINTS = {0: (0.063, 0.19), 2: (0.066, 0.14), 4: (0.068, 0.085), 8: (0.074, 0.106)}


#: The floor: no frame below this IoU with the default method.
TARGET_WORST_IOU = 0.75


def load_frame(index):
    from contourgrasp.io.camera_file import read_intrinsics, read_mask, read_rgb

    return (
        read_rgb(SINGLE / f"color_{index}.png"),
        np.load(SINGLE / f"depth_{index}.npy"),
        read_intrinsics(SINGLE / "primesense.intr"),
        read_mask(SINGLE / f"segmask_{index}.png"),
    )
