"""Fitting a model's measured closing with the thesis's trajectories (3.3) and a finger's planar chain.

Pure numpy on the paths :mod:`contourgrasp.handmodels.derive` records (its docstring has the reading of
the model): :func:`fit_finger` fits a projected fingertip path with a ray (eq 3.18) or, when the ray
leaves it by more than ``tolerances.MODEL_FIT_TOLERANCE``, an axis-aligned elliptic arc (eq 3.20,
a least-squares conic); :func:`travelled` reads a path as distances along the fitted trajectory;
:func:`fit_chain` measures a two-hinge finger's :class:`~contourgrasp.hand.FingerChain`,
:func:`sampled_chain` any finger's :class:`~contourgrasp.hand.SampledChain`, and :func:`palm_plate` the
:class:`~contourgrasp.hand.Palm` from the palm geoms' boxes.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from .. import tolerances as tol
from ..errors import HandError
from ..contour.polygon import signed_area
from ..hand import (Arc, Finger, FingerChain, Palm, Ray, SampledChain, check_chain, interpolate_samples,
                    polyline_distance)

#: Default gains of a derived hand's fingers (the five-finger-linear preset's).
ALPHA, BETA = 25.0, 10000.0
#: The eight corners of a unit box, in the order :func:`underside_face` reads a box's corners in (x slowest).
BOX_CORNERS = np.array([[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)], dtype=float)


@dataclass(frozen=True)
class FingerFit:
    """How one fingertip's projected path was fitted.

    Attributes
    ----------
    name : str
    kind : str
        ``"ray"`` or ``"arc"``.
    error : float
        Largest distance of the projected path from the fitted trajectory, m.
    ray_error : float
        That distance for the ray (the first fit tried), m.
    """

    name: str
    kind: str
    error: float
    ray_error: float


def fit_finger(name: str, path, *, radius: float = 0.0) -> tuple[Finger, FingerFit]:
    """The finger whose trajectory fits a projected fingertip path: a ray, else an elliptic arc.

    Parameters
    ----------
    name : str
    path : (k, 2) float
        The fingertip on the palm plane from open (first) to closed (last), hand frame, m.
    radius : float
        The finger's radius, m.

    Returns
    -------
    Finger, FingerFit

    Raises
    ------
    HandError
        Neither fits within ``tolerances.MODEL_FIT_TOLERANCE`` (naming the finger and both errors).
    """
    path = np.asarray(path, dtype=float)
    start, end = path[0], path[-1]
    travel = float(np.linalg.norm(end - start))
    if travel < tol.FINGER_MOVED:
        raise HandError(f"finger {name!r}: its tip moves {1000 * travel:.2f} mm on the palm plane from open to closed "
                        f"(at least {1000 * tol.FINGER_MOVED:g} mm)")
    ray = Finger(name=name, start=tuple(start), trajectory=Ray(tuple((end - start) / travel)), travel=travel,
                 alpha=ALPHA, beta=BETA, radius=radius)
    ray_error = float(polyline_distance(path, [start, end]).max())
    if ray_error <= tol.MODEL_FIT_TOLERANCE:
        return ray, FingerFit(name, "ray", ray_error, ray_error)
    arc, arc_error = _fit_arc(name, path, radius)
    if arc is not None and arc_error <= tol.MODEL_FIT_TOLERANCE:
        return arc, FingerFit(name, "arc", arc_error, ray_error)
    arc_text = f"arc {1000 * arc_error:.2f} mm" if arc is not None else "no arc (the path is no ellipse)"
    raise HandError(f"finger {name!r}: no ray or arc fits its tip path on the palm plane within "
                    f"{1000 * tol.MODEL_FIT_TOLERANCE:g} mm (ray {1000 * ray_error:.2f} mm, {arc_text})")


def _fit_arc(name: str, path: np.ndarray, radius: float) -> tuple[Finger | None, float]:
    """The arc (eq 3.20's axis-aligned ellipse) through a path: a least-squares conic, then the arc on it."""
    mean = path.mean(axis=0)
    scale = float(np.abs(path - mean).max())
    x, y = ((path - mean) / scale).T
    design = np.stack([x * x, y * y, x, y, np.ones_like(x)], axis=1)
    a, b, c, e, f = np.linalg.svd(design)[2][-1]
    if a * b <= 0:
        return None, np.inf
    cx, cy = -c / (2 * a), -e / (2 * b)
    level = a * cx * cx + b * cy * cy - f
    if level / a <= 0:
        return None, np.inf
    a_cos, a_sin = scale * np.sqrt(level / a), scale * np.sqrt(level / b)
    centre = mean + scale * np.array([cx, cy])
    angles = np.unwrap(np.arctan2((path[:, 1] - centre[1]) / a_sin, (path[:, 0] - centre[0]) / a_cos))
    if angles[-1] < angles[0]:  # a clockwise path: the mirrored ellipse, on which it turns counter-clockwise
        a_sin, angles = -a_sin, -angles
    if angles[-1] <= angles[0] or max(a_cos, abs(a_sin)) > tol.MAX_HAND_SIZE:
        return None, np.inf
    try:
        arc = Arc(float(a_cos), float(a_sin), float(angles[0]))
        travel = float(arc.length(angles[-1] - angles[0]))
        finger = Finger(name=name, start=tuple(path[0]), trajectory=arc, travel=travel, alpha=ALPHA, beta=BETA,
                        radius=radius)
    except HandError:
        return None, np.inf
    return finger, float(polyline_distance(path, finger.points(np.linspace(0.0, travel, tol.CHAIN_ARC_VERTICES))).max())


def travelled(finger: Finger, path) -> np.ndarray:
    """(k,) float: distance along the finger's trajectory of each path point's nearest trajectory point, m."""
    lam = np.linspace(0.0, finger.travel, tol.CHAIN_ARC_VERTICES)
    if isinstance(finger.trajectory, Ray):
        return (np.asarray(path) - finger.start) @ np.asarray(finger.trajectory.closing_direction)
    points = finger.points(lam)
    nearest = np.linalg.norm(np.asarray(path)[:, None] - points[None], axis=2).argmin(axis=1)
    return lam[nearest]


def fit_chain(finger: Finger, tips: np.ndarray, joints: np.ndarray) -> tuple[FingerChain | None, str]:
    """A two-link chain of a ray finger with two moving hinges, or None and why not.

    ``tips`` (k, 3): the fingertip, ``joints`` (2, k, 3): the two hinges' positions, hand frame, m, from open
    (first) to closed (last); the chain's open and closed angles are measured in its plane.
    """
    if not isinstance(finger.trajectory, Ray):
        return None, f"finger {finger.name!r}: closes on an arc, which a planar chain cannot follow"
    if len(joints) != 2:
        return None, f"finger {finger.name!r}: {len(joints)} hinge joints between palm and tip; a chain has two"
    knuckle, middle = joints
    direction = np.asarray(finger.trajectory.closing_direction)
    if knuckle[0, 2] < 0:
        return None, f"finger {finger.name!r}: its first joint is {1000 * -knuckle[0, 2]:.1f} mm above the palm's underside"

    def angle(a, b):  # absolute angles (open, closed) from +z, positive toward the closing direction
        v = b[[0, -1]] - a[[0, -1]]
        return np.arctan2(v[:, :2] @ direction, v[:, 2])

    a1, a2 = angle(knuckle, middle), angle(middle, tips)
    links = (float(np.linalg.norm(middle[0] - knuckle[0])), float(np.linalg.norm(tips[0] - middle[0])))
    try:
        chain = FingerChain(knuckle=tuple(knuckle[0, :2]), knuckle_depth=float(knuckle[0, 2]), direction=tuple(direction),
                            links=links, radius=finger.radius, open_angles=(float(a1[0]), float(a2[0] - a1[0])),
                            closed_angles=(float(a1[1]), float(a2[1] - a1[1])))
        check_chain(finger, chain)
    except HandError as err:
        return None, str(err)
    return chain, ""


def sampled_chain(finger: Finger, tips: np.ndarray, joints: np.ndarray) -> tuple[SampledChain | None, str]:
    """The finger's chain as measured, or None and why not (:func:`~contourgrasp.hand.check_chain` refuses it).

    ``tips`` (k, 3): the fingertip, ``joints`` (j, k, 3): its hinges' positions palm side first, hand frame,
    m, from open (first) to closed (last). Every link a capsule of the finger's radius. Resampled at
    ``tolerances.MODEL_CHAIN_SAMPLES`` closing progresses whose tips have moved evenly along their path on the
    palm plane, rounded to a micrometre.
    """
    if len(joints) == 0:
        return None, f"finger {finger.name!r}: no hinge joint between palm and tip"
    points = np.concatenate([np.transpose(joints, (1, 0, 2)), np.asarray(tips)[:, None]], axis=1)  # (k, j + 1, 3)
    if points.shape[1] > tol.MAX_CHAIN_POINTS:
        return None, (f"finger {finger.name!r}: {points.shape[1] - 1} hinge joints between palm and tip "
                      f"(a measured chain has at most {tol.MAX_CHAIN_POINTS - 1})")
    steps = np.linalg.norm(np.diff(np.asarray(tips)[:, :2], axis=0), axis=1)
    progress, first = np.unique(np.r_[0.0, np.cumsum(steps)], return_index=True)  # a still tip's repeats dropped
    at = np.interp(np.linspace(0.0, progress[-1], tol.MODEL_CHAIN_SAMPLES), progress, first.astype(float))
    resampled = np.round(interpolate_samples(points, at), 6)
    try:
        chain = SampledChain(joints=resampled, radius=finger.radius)
        check_chain(finger, chain)
    except HandError as err:
        return None, str(err)
    return chain, ""


def palm_plate(corners: np.ndarray) -> Palm:
    """The palm's plate from its collision geoms' bounding-box corners (8 per geom, hand frame).

    One geom: the box's face toward the object that covers the most of the palm plane
    (:func:`underside_face`) is the underside, tilted as the box is, and the plate is as thick as the
    box above it. Several: their rectangle on the palm plane, its underside as deep as their deepest
    corner (below z = 0 only) -- the palm's lowest point everywhere under it, on the safe side.
    """
    if len(corners) == 8:
        face = underside_face(corners)
        palm = Palm(outline=tuple(map(tuple, face)), thickness=tol.FINGER_MOVED)
        above = float((np.c_[np.ones(8), corners[:, :2]] @ palm.plane - corners[:, 2]).max())
        return replace(palm, thickness=max(above, tol.FINGER_MOVED))
    (x0, y0, z0), (x1, y1, z1) = corners.min(axis=0), corners.max(axis=0)
    depth = max(float(z1), 0.0)
    return Palm(outline=((x0, y0), (x1, y0), (x1, y1), (x0, y1)), thickness=max(depth - float(z0), tol.FINGER_MOVED),
                depths=(depth,) * 4)


def underside_face(box: np.ndarray) -> np.ndarray:
    """(4, 3) float: the corners, in order around it, of the face of a box (its 8 corners in :data:`BOX_CORNERS`'s
    order) that faces the object (outward normal with +z) and covers the most of the palm plane."""
    centre = box.mean(axis=0)
    best, face = -np.inf, None
    for axis in range(3):
        others = [a for a in range(3) if a != axis]
        for side in (0, 1):
            index = [sum(b << (2 - a) for a, b in zip([axis, *others], (side, *pair), strict=True))
                     for pair in ((0, 0), (1, 0), (1, 1), (0, 1))]
            if box[index].mean(axis=0)[2] <= centre[2]:
                continue
            shadow = abs(signed_area(box[index, :2]))
            if shadow > best:
                best, face = shadow, box[index]
    return face
