"""Plan JSON (schema in README.md, "Output") and atomic writing of output files."""

from __future__ import annotations

import contextlib
import json
import os
import tempfile
from dataclasses import asdict
from pathlib import Path

import numpy as np

from ..errors import InputError
from ..synthesis import GraspPlan


def _pose(pose) -> dict:
    x, y, yaw = (float(v) for v in pose)
    return {"x": x, "y": y, "yaw": yaw}


def _xy(point) -> list[float]:
    return [float(v) for v in np.asarray(point)]


def plan_to_dict(plan: GraspPlan) -> dict:
    """The JSON-ready dictionary of a plan (all values SI: m, rad; times in ms)."""
    from .. import __version__

    return {
        "contourgrasp_version": __version__,
        "hand": plan.hand.name,
        "pose": _pose(plan.pose),
        "cost": asdict(plan.cost),
        "curvature_mode": plan.curvature_mode,
        "fingers": [
            {
                "name": f.name,
                "grasp_point": _xy(f.grasp_point),
                "t": f.t,
                "lambda": f.lam,
                "curvature": f.curvature,
                "concave": bool(f.concave),
                "distance": f.distance,
                "start": _xy(f.start),
                "virtual_start": _xy(f.virtual_start),
                "missed": bool(f.missed),
                "gap": f.gap,
            }
            for f in plan.fingers
        ],
        "efd": {
            "harmonics": plan.efd.harmonics,
            "A0": plan.efd.A0,
            "C0": plan.efd.C0,
            "T": plan.efd.T,
            "coefficients": plan.efd.coefficients.tolist(),
        },
        "grid": {
            "xy_step": plan.grid.xy_step,
            "yaw_step": plan.grid.yaw_step,
            "d_max": list(plan.grid.d_max),
            "d_min": plan.grid.d_min,
            "size": plan.grid_size,
            "feasible": plan.feasible_poses,
        },
        "safeguards": asdict(plan.safeguards),
        "quality": asdict(plan.quality),
        "alternatives": [{"pose": _pose(a.pose), "cost": asdict(a.cost)} for a in plan.alternatives],
        "refinement": None if plan.refinement is None else {
            "grid_pose": _pose(plan.refinement.grid_pose), "grid_cost": plan.refinement.grid_cost,
            "cost": plan.refinement.cost, "gain": plan.refinement.gain},
        "timing_ms": dict(plan.timing_ms),
    }


def image_plan_to_dict(result) -> dict:
    """``plan_to_dict`` of the planar plan plus the camera, segmentation and 6-DoF poses of an ImageGraspPlan."""
    data = plan_to_dict(result.plan)
    cam, seg, metric = result.camera, result.segmentation, result.metric
    data["camera"] = {"fx": cam.fx, "fy": cam.fy, "cx": cam.cx, "cy": cam.cy, "width": cam.width, "height": cam.height}
    data["segmentation"] = {
        "method": seg.method,
        "area_px": int(seg.area_px),
        "contour_px": np.asarray(seg.contour_px).tolist(),
        "invalid_depth_px": metric.invalid_depth_px,
        "filled_depth_px": result.filled_depth_px,
        "colour_offset_px": None if seg.colour_offset_px is None else list(seg.colour_offset_px),
        "warnings": list(seg.warnings),
    }
    data["planning_frame"] = {
        "frame": metric.frame,
        "depth_mode": metric.depth_mode,
        "on_table": metric.on_table,
        "tilt": metric.tilt,
        "z_max": metric.z_max,
        "R_camera_plane": metric.R_camera_plane.tolist(),
        "origin": metric.origin.tolist(),
    }
    data["approach_depth"] = metric.approach_depth
    data["T_camera_hand"] = result.T_camera_hand.tolist()
    data["quaternion_xyzw"] = result.quaternion_xyzw.tolist()
    data["T_camera_pregrasp"] = result.T_camera_pregrasp.tolist()
    if result.T_base_hand is not None:
        data["T_base_hand"] = result.T_base_hand.tolist()
    return data


@contextlib.contextmanager
def atomic_outputs(*paths):
    """Yield temporary paths beside ``paths``; move them into place only if the block succeeds.

    ``None`` entries are passed through as ``None``. On any exception every
    temporary file is removed and no output file is created or changed.
    """
    temps = []
    try:
        for path in paths:
            if path is None:
                temps.append(None)
                continue
            path = Path(path)
            if not path.parent.is_dir():
                raise InputError(f"{path}: cannot write, directory {path.parent} does not exist")
            fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=path.suffix, dir=path.parent or ".")
            os.close(fd)
            temps.append(Path(tmp))
        yield temps
        mode = 0o666 & ~_umask()  # mkstemp makes 0600 files; outputs get the usual permissions
        for tmp, path in zip(temps, paths):
            if tmp is not None:
                os.chmod(tmp, mode)
                os.replace(tmp, path)
    finally:
        for tmp in temps:
            if tmp is not None and tmp.exists():
                tmp.unlink()


def _umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask


def write_json(data: dict, path) -> None:
    """Write ``data`` as indented JSON to ``path`` (a temporary path from :func:`atomic_outputs`)."""
    Path(path).write_text(json.dumps(data, indent=2) + "\n", encoding="utf-8")
