"""The parts of a MuJoCo hand model that :mod:`contourgrasp.handmodels.derive` reads, by name.

The palm body and the bodies below it, the fingertips (sites or bodies), the synergy's actuators and
the pre-shape's, each finger's hinge joints, and the collision geoms' boxes that give the palm's
underside and the fingertips' radius. A name the model does not have, or one that is not on the
palm's subtree, is a :class:`~contourgrasp.errors.HandFileError` naming the model file (``source``)
and the option (fingertips, actuators, palm): the ``hand-from-model`` command's bad input.
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np

os.environ.setdefault("MUJOCO_GL", "disable")
import mujoco  # noqa: E402

from .. import tolerances as tol  # noqa: E402
from ..errors import HandFileError  # noqa: E402
from .fit import BOX_CORNERS  # noqa: E402
from ..sim.scene import mujoco_warnings  # noqa: E402


def load_model(path) -> mujoco.MjModel:
    """The compiled MuJoCo model of an MJCF file; HandFileError naming the file when it cannot load."""
    path = Path(path)
    if not path.is_file():
        raise HandFileError(f"{path}: no such model file")
    try:
        with mujoco_warnings():
            m = mujoco.MjModel.from_xml_path(str(path))
    except (ValueError, RuntimeError, mujoco.FatalError) as err:
        reason = " ".join(str(err).split())[:300]
        raise HandFileError(f"{path}: cannot load the MuJoCo model ({reason})") from None
    if m.nbody > tol.MAX_MODEL_BODIES:
        raise HandFileError(f"{path}: {m.nbody} bodies, more than a hand model has (at most {tol.MAX_MODEL_BODIES}): "
                            "give the hand's own model")
    return m


def palm_body(m, palm: str | None, fingertips, source: str) -> int:
    """The body named ``palm``, or without a name the deepest body holding every one of ``fingertips``."""
    if palm is not None:
        body = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, palm)
        if body < 0:
            kind = next((label for label, obj in (("a site", mujoco.mjtObj.mjOBJ_SITE), ("a geom", mujoco.mjtObj.mjOBJ_GEOM),
                                                  ("a joint", mujoco.mjtObj.mjOBJ_JOINT))
                         if mujoco.mj_name2id(m, obj, palm) >= 0), "not a name in the model")
            raise HandFileError(f"{source}: palm {palm!r} is not a body ({kind})")
        return body
    paths = []
    for name in fingertips:
        body = fingertip_body(m, name, source)
        path = [body]
        while path[-1] != 0:
            path.append(int(m.body_parentid[path[-1]]))
        paths.append(path[::-1])
    common = 0
    for level in zip(*paths, strict=False):
        if len(set(level)) != 1:
            break
        common = level[0]
    if common == 0:
        raise HandFileError(f"{source}: the fingertips share no body but the world; name the palm body (--palm)")
    return common


def subtree(m, body: int) -> set[int]:
    """``body`` and every body below it."""
    inside = {body}
    for b in range(body + 1, m.nbody):  # MuJoCo numbers bodies depth first: children after parents
        if int(m.body_parentid[b]) in inside:
            inside.add(b)
    return inside


def fingertip_body(m, name: str, source: str) -> int:
    """The body of the site or body called ``name`` (a fingertip)."""
    site = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_SITE, name)
    if site >= 0:
        return int(m.site_bodyid[site])
    body = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_BODY, name)
    if body < 0:
        raise HandFileError(f"{source}: fingertips: no site or body named {name!r} in the model")
    return body


def fingertip(m, name: str, palm_bodies: set[int], source: str) -> tuple[str, int]:
    """The fingertip ``name`` as ("site", id) or ("body", id), refused unless it lies on ``palm_bodies`` (the
    palm's subtree)."""
    body = fingertip_body(m, name, source)
    if body not in palm_bodies:
        raise HandFileError(f"{source}: fingertips: {name!r} is not on a finger of the palm body")
    site = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_SITE, name)
    return ("site", site) if site >= 0 else ("body", body)


def tip_body(m, tip: tuple[str, int]) -> int:
    """The body a fingertip (:func:`fingertip`) lies on."""
    kind, index = tip
    return int(m.site_bodyid[index]) if kind == "site" else index


def tip_point(d, tip: tuple[str, int]) -> np.ndarray:
    """(3,) float: the fingertip's world position in the data ``d``."""
    kind, index = tip
    return d.site_xpos[index].copy() if kind == "site" else d.xpos[index].copy()


def finger_bodies(m, palm: int, tips) -> tuple[tuple[str, int], ...]:
    """Each body below the palm that lies on a finger (toward its tip, or below such a body), with the finger."""
    owner = {}
    for i, tip in enumerate(tips):
        body = tip_body(m, tip)
        while body != palm:
            owner.setdefault(body, i)
            body = int(m.body_parentid[body])
    for b in range(palm + 1, m.nbody):  # depth first: a parent before its children
        parent = int(m.body_parentid[b])
        if b not in owner and parent in owner:
            owner[b] = owner[parent]
    return tuple((m.body(b).name, i) for b, i in sorted(owner.items()))


def moving_path(m, tip: tuple[str, int], palm: int) -> list[int]:
    """Hinge joints from the palm to the fingertip's body, palm side first."""
    joints, body = [], tip_body(m, tip)
    while body != palm:
        adr, count = int(m.body_jntadr[body]), int(m.body_jntnum[body])
        joints = [j for j in range(adr, adr + count) if m.jnt_type[j] == mujoco.mjtJoint.mjJNT_HINGE] + joints
        body = int(m.body_parentid[body])
    return joints


def actuators(m, names, palm_bodies: set[int], source: str) -> np.ndarray:
    """The ids of the actuators ``names`` (None or ["all"]: every one on ``palm_bodies``), each on the hand and with a
    control range."""

    def on_hand(a: int) -> bool:
        kind, target = int(m.actuator_trntype[a]), int(m.actuator_trnid[a, 0])
        if kind in (mujoco.mjtTrn.mjTRN_JOINT, mujoco.mjtTrn.mjTRN_JOINTINPARENT):
            return int(m.jnt_bodyid[target]) in palm_bodies
        return True  # tendons, sites, bodies: taken as the hand's

    if names is None or list(names) == ["all"]:
        chosen = [a for a in range(m.nu) if on_hand(a)]
        if not chosen:
            raise HandFileError(f"{source}: actuators: the model has no actuator on the palm's subtree")
    else:
        chosen = []
        for name in names:
            a = mujoco.mj_name2id(m, mujoco.mjtObj.mjOBJ_ACTUATOR, name)
            if a < 0:
                known = ", ".join(m.actuator(i).name for i in range(m.nu)) or "none"
                raise HandFileError(f"{source}: actuators: no actuator named {name!r} (the model's: {known})")
            if not on_hand(a):
                raise HandFileError(f"{source}: actuators: {name!r} drives a joint outside the palm's subtree")
            chosen.append(a)
    for a in chosen:
        lo, hi = m.actuator_ctrlrange[a]
        if not m.actuator_ctrllimited[a] or not lo < hi:
            raise HandFileError(f"{source}: actuators: {m.actuator(a).name!r} has no control range (ctrlrange): "
                                "the synergy drives each actuator from the low end of its range to the high end")
    return np.array(chosen, dtype=int)


def held_controls(m, hold, palm_bodies: set[int], source: str) -> list[tuple[int, float]]:
    """The actuators of ``hold`` ((name, fraction) pairs) held still at that fraction of their control range (a
    pre-shape), as (id, control)."""
    held = []
    for name, fraction in hold:
        a = actuators(m, (name,), palm_bodies, source)[0]
        lo, hi = m.actuator_ctrlrange[a]
        held.append((int(a), float(lo + fraction * (hi - lo))))
    return held


def freeze(m, d, joints) -> None:
    """Hold the joints outside the palm's subtree at their reference position, at rest."""
    for j in joints:
        q, v = int(m.jnt_qposadr[j]), int(m.jnt_dofadr[j])
        nq, nv = {mujoco.mjtJoint.mjJNT_FREE: (7, 6), mujoco.mjtJoint.mjJNT_BALL: (4, 3)}.get(int(m.jnt_type[j]), (1, 1))
        d.qpos[q:q + nq] = m.qpos0[q:q + nq]
        d.qvel[v:v + nv] = 0.0


def local_corners(m, g: int) -> np.ndarray:
    """(8, 3) float: the corners of geom ``g``'s bounding box in its own frame."""
    return m.geom_aabb[g, :3] + BOX_CORNERS * m.geom_aabb[g, 3:]


def geom_corners(m, d, geoms, origin: np.ndarray, rotation: np.ndarray) -> np.ndarray:
    """(8 g, 3) float: the corners of each geom's local bounding box, in the frame (origin, rotation)."""
    return np.concatenate([(local_corners(m, g) @ d.geom_xmat[g].reshape(3, 3).T + d.geom_xpos[g] - origin) @ rotation
                           for g in geoms])


def palm_geoms(m, d, palm: int, palm_bodies: set[int], axes: np.ndarray, collides: np.ndarray) -> np.ndarray | None:
    """Corners of the palm's own collision geoms (bodies welded to it), hand axes, palm origin; None if none."""
    weld = int(m.body_weldid[palm])
    geoms = [g for g in range(m.ngeom) if int(m.geom_bodyid[g]) in palm_bodies
             and int(m.body_weldid[m.geom_bodyid[g]]) == weld and collides[g]]
    if not geoms:
        return None
    rotation = d.xmat[palm].reshape(3, 3)
    return geom_corners(m, d, geoms, d.xpos[palm], rotation) @ axes.T


def tip_radius(m, tip: tuple[str, int], collides: np.ndarray) -> float:
    """Half the smallest extent of the fingertip body's collision geoms, in that body's frame; 0 without any."""
    body = tip_body(m, tip)
    geoms = [g for g in range(m.ngeom) if int(m.geom_bodyid[g]) == body and collides[g]]
    if not geoms:
        return 0.0
    corners = []
    for g in geoms:
        rotation = np.empty(9)
        mujoco.mju_quat2Mat(rotation, m.geom_quat[g])
        corners.append(local_corners(m, g) @ rotation.reshape(3, 3).T + m.geom_pos[g])
    points = np.concatenate(corners)
    return float(np.ptp(points, axis=0).min() / 2)
