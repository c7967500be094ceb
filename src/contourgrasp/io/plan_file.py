"""Plan JSON (schema in README.md, "Output") and atomic writing of output files."""

from __future__ import annotations

import contextlib
import json
import math
import os
import shutil
import stat
import tempfile
from dataclasses import asdict
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from ..errors import OutputError

if TYPE_CHECKING:  # the plan's type only: importing synthesis loads numba
    from ..synthesis import GraspPlan


def _pose(pose) -> dict:
    x, y, yaw = (float(v) for v in pose)
    return {"x": x, "y": y, "yaw": yaw}


def _xy(point) -> list[float]:
    return [float(v) for v in np.asarray(point)]


def plan_to_dict(plan: GraspPlan) -> dict:
    """The JSON-ready dictionary of a plan (all values SI: m, rad; times in ms)."""
    from .._version import __version__

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
            "outline_grown_by": plan.grown,
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
        "min_touching": plan.hand.min_touching,
        "descent": descent_summary(plan.descent),
        "timing_ms": dict(plan.timing_ms),
        "notes": list(plan.notes),
    }


def descent_summary(check) -> dict | None:
    """The plan file's entry of a plan's one-pose :class:`~contourgrasp.synthesis.DescentCheck`, None for None.

    ``{tip_height, margin, clearance: {body: m}, least_clearance, blocking}``: the grasp height it was
    checked at, and each finger's post, proximal and distal link's and the palm's least clearance
    over the height map on the way down (m; null for a body over no cell).
    """
    if check is None:
        return None
    clearance = [float(c) if math.isfinite(c) else None for c in check.clearance[0]]
    return {
        "tip_height": float(check.tip_height[0]),
        "margin": check.margin,
        "clearance": dict(zip(check.bodies, clearance)),
        "least_clearance": float(check.clearance[0].min()),
        "blocking": None if check.blocking[0] < 0 else check.bodies[int(check.blocking[0])],
    }


def height_map_summary(heights) -> dict | None:
    """The plan file's summary of a :class:`~contourgrasp.perception.HeightMap` (not its array), None for None.

    ``{cell, shape: [ny, nx], origin: [x, y], extent: [x_min, x_max, y_min, y_max], object_max_height,
    obstacle_max_height}``, in m and the planning frame; ``object_max_height`` is null when no
    object cell was seen.
    """
    if heights is None:
        return None
    top = heights.max_height
    return {
        "cell": heights.cell,
        "shape": list(heights.shape),
        "origin": [float(v) for v in heights.origin],
        "extent": list(heights.extent),
        "object_max_height": None if math.isnan(top) else top,
        "obstacle_max_height": heights.obstacle_max_height,
    }


def candidate_to_dict(candidate) -> dict:
    """The plan file's entry of a :class:`~contourgrasp.perception.Candidate` (not its mask or outline).

    ``{label, area_px, height (m), extent: [length, width] (m), centroid_px: [u, v], in_view, touching,
    bbox: [x, y, w, h]}``.
    """
    return {
        "label": candidate.label,
        "area_px": candidate.area_px,
        "height": candidate.height,
        "extent": [float(v) for v in candidate.extent],
        "centroid_px": [float(v) for v in candidate.centroid_px],
        "in_view": bool(candidate.in_view),
        "touching": bool(candidate.touching),
        "bbox": [int(v) for v in candidate.bbox],
    }


def support_to_dict(support) -> dict | None:
    """The plan file's entry of a :class:`~contourgrasp.perception.Support`, None for None.

    ``{normal: [x, y, z], offset (m: the camera's distance to the plane), tilt (rad), inliers (pixels),
    planes_considered, reason}``, in the camera frame.
    """
    if support is None:
        return None
    plane = support.plane
    return {
        "normal": [float(v) for v in plane.normal],
        "offset": float(plane.offset),
        "tilt": plane.tilt,
        "inliers": int(np.count_nonzero(plane.inliers)),
        "planes_considered": len(support.planes),
        "reason": support.reason,
    }


def approach_to_dict(result) -> dict:
    """The approach of an ImageGraspPlan: its name, elevation and azimuth (rad, in the planning frame), its direction
    in the camera frame, and for a side or tilted approach the approach frame's rotation and origin in the camera
    frame (``pose`` and ``grasp_height`` are then in that frame)."""
    approach = result.approach
    data = {"kind": approach.kind, "description": approach.describe(),
            "elevation": approach.elevation, "azimuth": approach.azimuth,
            "direction_camera": result.T_camera_hand[:3, 2].tolist()}
    if result.view is not None:
        data["R_camera_view"], data["origin_camera"] = result.frame.R_camera_plane.tolist(), result.frame.origin.tolist()
    return data


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
    data["support_surface"] = support_to_dict(result.support)
    data["objects"] = [candidate_to_dict(c) for c in result.candidates]
    data["target"] = {"label": None if result.target is None else result.target.label, "reason": result.target_reason}
    data["approach_depth"] = metric.approach_depth
    data["approach"] = approach_to_dict(result)
    data["height_map"] = height_map_summary(result.height_map)
    data["grasp_height"] = result.grasp_height
    data["T_camera_hand"] = result.T_camera_hand.tolist()
    data["quaternion_xyzw"] = result.quaternion_xyzw.tolist()
    data["T_camera_pregrasp"] = result.T_camera_pregrasp.tolist()
    if result.T_base_hand is not None:
        data["T_base_hand"] = result.T_base_hand.tolist()
    return data


@contextlib.contextmanager
def atomic_outputs(*paths, inputs=()):
    """Yield temporary paths beside ``paths``; move them into place only if the block succeeds, all or none.

    Every target is checked before anything is written: not a directory, its
    folder exists and is writable, no target given twice, none equal to one of
    ``inputs`` (the files the outputs are computed from). Then the block writes
    the temporary files, and they are renamed over their targets; if a rename
    fails, the targets already replaced get their old content back. An existing
    output keeps its permissions; a new one gets the usual ``0666 & ~umask``.
    A symbolic link is followed: its target is replaced and the link kept. An
    output that exists and is not a regular file (``/dev/null``, ``/dev/stdout``,
    a FIFO) is written through, after the regular ones, never replaced.

    Parameters
    ----------
    *paths : str, Path or None
        Output files; ``None`` entries are passed through as ``None``.
    inputs : iterable of str or Path
        Files that must not be overwritten (``None`` entries and names that are
        not files, such as ``example:can``, are ignored).

    Raises
    ------
    OutputError
        A target that cannot be written; or, raised from the block, an
        ``OSError`` on one of the temporary files, re-raised naming its target.

    Examples
    --------
    >>> import tempfile, pathlib
    >>> folder = pathlib.Path(tempfile.mkdtemp())
    >>> with atomic_outputs(folder / "a.txt", None) as (a, none):
    ...     _ = a.write_text("done")
    >>> (folder / "a.txt").read_text(), none
    ('done', None)
    """
    targets = [None if p is None else _destination(Path(p)) for p in paths]
    _check_targets(targets, inputs)
    temps = []
    try:
        temps = [None if path is None else _temporary(path) for path in targets]
        try:
            yield temps
        except OSError as err:
            named = {str(t): p for t, p in zip(temps, targets) if t is not None}
            if str(err.filename) in named:
                raise OutputError(f"cannot write {named[str(err.filename)]}: {err.strerror}") from None
            raise
        _replace_all([(t, p) for t, p in zip(temps, targets) if t is not None and not _is_stream(p)])
        for tmp, path in zip(temps, targets):
            if tmp is not None and _is_stream(path):
                _write_through(tmp, path)
    finally:
        for tmp in temps:
            if tmp is not None and tmp.exists():
                tmp.unlink()


def _destination(path: Path) -> Path:
    """Where an output goes: the regular file a symbolic link leads to (the link is kept), else the path itself
    (a link to a device or a pipe, as /dev/stdout is, is written through as it is)."""
    return path.resolve() if path.is_symlink() and not _is_stream(path) else path


def _is_stream(path: Path) -> bool:
    """An existing output that is not a regular file (a device such as /dev/null, a FIFO, a terminal): written
    through once every output is ready, never renamed over."""
    return path.exists() and not path.is_file() and not path.is_dir()


def _write_through(tmp: Path, path: Path) -> None:
    try:
        with open(tmp, "rb") as source, open(path, "wb") as target:
            shutil.copyfileobj(source, target)
    except OSError as err:
        raise OutputError(f"cannot write {path}: {err.strerror or err}") from None


def _check_targets(targets, inputs) -> None:
    """Refuse, before anything is written, every output that could not be written or would clobber an input."""
    seen = {}
    protected = {_key(Path(p)): Path(p) for p in inputs if p is not None and Path(p).is_file()}
    for path in (p for p in targets if p is not None):
        key = _key(path)
        if key in seen:
            also = "" if str(seen[key]) == str(path) else f" (also as {seen[key]})"
            raise OutputError(f"{path}: given twice as an output{also}")
        if key in protected:
            raise OutputError(f"{path}: the output would overwrite the input file {protected[key]}")
        seen[key] = path
        if path.is_dir():
            raise OutputError(f"{path}: cannot write, it is a directory")
        if _is_stream(path):
            if not os.access(path, os.W_OK):
                raise OutputError(f"{path}: cannot write, no permission")
            continue
        if not path.parent.is_dir():
            raise OutputError(f"{path}: cannot write, directory {path.parent} does not exist")
        if not os.access(path.parent, os.W_OK | os.X_OK):
            raise OutputError(f"{path}: cannot write, directory {path.parent} is not writable")


def _key(path: Path) -> str:
    """One name per file: the resolved path (symbolic links followed, ``..`` removed)."""
    return os.path.normcase(str(path.resolve()))


def _temporary(path: Path) -> Path:
    """An empty file to write ``path``'s content to: beside it (renamed over it after), or for a stream in the
    temporary folder (never a new file in /dev)."""
    try:
        fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=path.suffix,
                                   dir=None if _is_stream(path) else path.parent)
    except OSError as err:
        raise OutputError(f"cannot write {path}: {err.strerror}") from None
    os.close(fd)
    return Path(tmp)


def _replace_all(pairs) -> None:
    """Rename every (temporary, target) pair; on a failure put back the targets already replaced."""
    backups, done = {}, []
    try:
        for tmp, path in pairs:
            os.chmod(tmp, _mode(path))
            if path.exists():
                backups[path] = _backup(path, tmp)
            os.replace(tmp, path)
            done.append(path)
    except OSError as err:
        for path in reversed(done):
            if path in backups:
                os.replace(backups.pop(path), path)
            else:
                path.unlink(missing_ok=True)
        failed = pairs[len(done)][1]
        raise OutputError(f"cannot write {failed}: {err.strerror}; no output was changed") from None
    finally:
        for backup in backups.values():
            backup.unlink(missing_ok=True)


def _mode(path: Path) -> int:
    """The permissions an output gets: the existing file's, else 0666 less the umask (mkstemp makes 0600)."""
    try:
        return stat.S_IMODE(path.stat().st_mode)
    except FileNotFoundError:
        return 0o666 & ~_umask()


def _backup(path: Path, tmp: Path) -> Path:
    """A hard link to (or, where links are not supported, a copy of) the file about to be replaced."""
    backup = tmp.with_name(tmp.name + ".old")
    try:
        os.link(path, backup)
    except OSError:
        shutil.copy2(path, backup)
    return backup


def _umask() -> int:
    mask = os.umask(0)
    os.umask(mask)
    return mask


def write_json(data, path) -> None:
    """Write ``data`` as indented JSON to ``path`` (a temporary path from :func:`atomic_outputs`).

    Raises
    ------
    OutputError
        ``data`` holds a NaN or an infinity, which JSON cannot represent.
    """
    field = _non_finite(data)
    if field is not None:
        raise OutputError(f"the JSON output cannot hold {field[0]} = {field[1]} (JSON has no NaN or infinity)")
    Path(path).write_text(json.dumps(data, indent=2, allow_nan=False) + "\n", encoding="utf-8")


def _non_finite(data, where: str = "") -> tuple[str, float] | None:
    """(field, value) of the first NaN or infinite number in nested dicts and lists, or None."""
    if isinstance(data, float):
        return None if math.isfinite(data) else (where or "value", data)
    items = data.items() if isinstance(data, dict) else enumerate(data) if isinstance(data, (list, tuple)) else ()
    for key, value in items:
        found = _non_finite(value, f"{where}.{key}" if isinstance(key, str) else f"{where}[{key}]")
        if found is not None:
            return found[0].lstrip("."), found[1]
    return None
