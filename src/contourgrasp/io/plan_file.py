"""Plan JSON (schema in README.md, "Output") and atomic writing of output files."""

from __future__ import annotations

import contextlib
import json
import os
import tempfile
from pathlib import Path

import numpy as np

from ..errors import InputError
from ..synthesis import Cost, GraspPlan


def _pose(pose) -> dict:
    x, y, yaw = (float(v) for v in pose)
    return {"x": x, "y": y, "yaw": yaw}


def _cost(cost: Cost) -> dict:
    return {"total": cost.total, "curvature": cost.curvature, "ratio": cost.ratio, "miss": cost.miss}


def _xy(point) -> list[float]:
    return [float(v) for v in np.asarray(point)]


def plan_to_dict(plan: GraspPlan) -> dict:
    """The JSON-ready dictionary of a plan (all values SI: m, rad; times in ms)."""
    from .. import __version__

    return {
        "contourgrasp_version": __version__,
        "hand": plan.hand.name,
        "pose": _pose(plan.pose),
        "cost": _cost(plan.cost),
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
        "alternatives": [{"pose": _pose(a.pose), "cost": _cost(a.cost)} for a in plan.alternatives],
        "timing_ms": dict(plan.timing_ms),
    }


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
