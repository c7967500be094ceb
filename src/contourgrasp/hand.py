"""Hand model: fingertips moving on rays or elliptic arcs in the image plane (thesis 3.3).

Frames
------
The *hand frame* is 2-D, in the image plane: its origin is the hand's reference
point (x_p, y_p) of eq 3.18 and every finger's ``start`` (x_f, y_f) is given in
it. A pose (x, y, yaw) places the hand frame in the camera's image plane (optical
frame, x right, y down): ``p_image = (x, y) + R(yaw) p_hand`` with
``R(yaw) = [[cos, -sin], [sin, cos]]``, a right-handed rotation about the
camera's z axis. Eq 3.19 prints the transpose (a rotation by -yaw); the search
covers every yaw, so only the sign of the reported yaw differs.

Trajectories
------------
Every trajectory is parameterised by ``lam``, the distance travelled along it in
meters, ``0 <= lam <= travel`` (F of eq 3.29):

* :class:`Ray` (eq 3.18): ``start + lam * closing_direction``. The presets store
  ``closing_direction = -m`` of the thesis tables, whose (m_x, m_y) point away
  from the grasp (see the preset files).
* :class:`Arc` (eq 3.20-3.21): ``start + E(phi_off + theta) - E(phi_off)`` with
  ``E(a) = (a_cos cos a, a_sin sin a)`` and ``theta`` the angle whose arc length
  on the ellipse is ``lam`` (the thesis's lambda is this angle; we keep travel a
  distance so that F, D_min and lambda_virt mean the same for every finger).

``virtual_start`` is lambda_virt: the virtual start point of the ratio cost
(eq 3.35-3.37) is the trajectory at ``lam = virtual_start``; positive values lie
ahead along the closing motion (a finger that closes early or fast).

3-D hand (optional)
-------------------
A hand may also carry its bodies: per finger a :class:`FingerChain` and a
:class:`Palm`. They live in the *3-D hand frame*: x and y those of the 2-D hand
frame, in the plane of the palm's underside, and z along the approach, positive
*below* the palm toward the object (the camera's z for a top-down view). Every
finger is a planar two-link chain (proximal, distal) in the vertical plane
through its knuckle that holds its horizontal ``direction``; its closing is the
one-DoF synergy of an underactuated hand,
``q(s) = open_angles + s * (closed_angles - open_angles)`` for closing progress
``s`` in [0, 1]. :func:`chain_tip` and :func:`chain_capsules` are its forward
kinematics; :func:`check_chain` ties it to the 2-D trajectory the planner uses.
A :class:`Hand` without chains (``chains = None``) is a 2-D hand and plans as one.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from functools import cached_property

import numpy as np

from . import tolerances as tol
from . import validation as check
from .contour.polygon import signed_area
from .errors import HandError


@dataclass(frozen=True)
class Ray:
    """Straight closing motion; ``closing_direction`` is normalised on creation (kept when unit to 1e-15).

    Implements eq 3.18: the fingertip after travelling ``lam`` is ``start + lam * closing_direction``
    in the hand frame, placed at the pose (x_p, y_p, phi_p) by :func:`to_image`.

    Raises
    ------
    HandError
        The direction is not a finite, non-zero 2-vector.
    """

    closing_direction: tuple[float, float]

    def __post_init__(self):
        c = check.float_array("closing_direction", self.closing_direction, error=HandError)
        with np.errstate(over="ignore"):
            norm = float(np.linalg.norm(c)) if c.shape == (2,) else np.nan
        if norm == np.inf and np.isfinite(c).all():  # the squares overflowed: scale down first
            c = c / np.abs(c).max()
            norm = float(np.linalg.norm(c))
        if not np.isfinite(norm) or norm < tol.MIN_DIRECTION:
            raise HandError(f"closing_direction must be a non-zero 2-vector, got {self.closing_direction!r}")
        if abs(norm - 1.0) > 1e-15:  # a unit vector is kept as given: normalising twice changes the last bit
            c = c / norm
        object.__setattr__(self, "closing_direction", (float(c[0]), float(c[1])))


@dataclass(frozen=True)
class Arc:
    """Elliptic-arc closing motion: radii ``a_cos``, ``a_sin`` (m), start angle ``phi_off`` (rad).

    Implements eq 3.20 and 3.21: the fingertip moves by ``E(phi_off + theta) - E(phi_off)``
    (:meth:`offset`), the ellipse point less its offset at the start.

    Raises
    ------
    HandError
        A radius that is not positive or above ``tolerances.MAX_HAND_SIZE``, or ``|phi_off|``
        above ``tolerances.MAX_ARC_ANGLE``.
    """

    a_cos: float
    a_sin: float
    phi_off: float

    def __post_init__(self):
        for name in ("a_cos", "a_sin"):
            check.bounded(f"arc {name}", getattr(self, name), tol.MAX_HAND_SIZE, " m", strict=True, error=HandError)
        angle = check.finite("arc phi_off", self.phi_off, error=HandError)
        check.at_most("arc |phi_off|", abs(angle), tol.MAX_ARC_ANGLE, " rad", error=HandError)

    @cached_property
    def _length_table(self) -> tuple[np.ndarray, np.ndarray]:
        theta = np.linspace(-2 * np.pi, 2 * np.pi, 2 * tol.ARC_LENGTH_TABLE + 1)
        a = self.phi_off + theta
        speed = np.hypot(self.a_cos * np.sin(a), self.a_sin * np.cos(a))
        steps = 0.5 * (speed[1:] + speed[:-1]) * np.diff(theta)
        s = np.concatenate([[0.0], np.cumsum(steps)])
        return s - s[tol.ARC_LENGTH_TABLE], theta

    @property
    def perimeter(self) -> float:
        s, _ = self._length_table
        return float((s[-1] - s[0]) / 2)

    def angle(self, lam) -> np.ndarray:
        """Angle travelled on the ellipse after arc length ``lam`` (m); negative lam goes backwards."""
        s, theta = self._length_table
        return np.interp(lam, s, theta)

    def offset(self, lam) -> np.ndarray:
        """(m, 2) float: displacement from the start point after arc length ``lam`` (eq 3.20)."""
        a = self.phi_off + self.angle(np.atleast_1d(lam))
        return np.stack(
            [self.a_cos * (np.cos(a) - np.cos(self.phi_off)), self.a_sin * (np.sin(a) - np.sin(self.phi_off))],
            axis=-1,
        )

    def tangent(self, lam) -> np.ndarray:
        """(m, 2) float: unit direction of motion after arc length ``lam`` (m)."""
        a = self.phi_off + self.angle(np.atleast_1d(lam))
        d = np.stack([-self.a_cos * np.sin(a), self.a_sin * np.cos(a)], axis=-1)
        return d / np.linalg.norm(d, axis=-1, keepdims=True)


@dataclass(frozen=True)
class Finger:
    """One fingertip: where it starts, how it closes, and its gains (Tables 4.3, A.1, A.2).

    Attributes
    ----------
    name : str
    start : (2,) float
        (x_f, y_f): fingertip of the open hand in the hand frame, m.
    trajectory : Ray or Arc
    travel : float
        F: distance from open to fully closed along the trajectory, m.
    virtual_start : float
        lambda_virt, m (see module docstring).
    alpha, beta : float
        Gains on the curvature and ratio costs (eq 3.34).
    required : bool
        A pose is infeasible when this finger misses the object.
    radius : float
        Half the finger's width, m: the fingertip is a disc of this radius
        (used by the planner's finger-thickness check, not by the thesis's).

    Lengths are at most ``tolerances.MAX_HAND_SIZE`` (``|start|``, ``|virtual_start|`` too) and
    gains at most ``tolerances.MAX_GAIN`` in magnitude.

    Raises
    ------
    HandError
        Naming the finger and the attribute that is not a number in range.
    """

    name: str
    start: tuple[float, float]
    trajectory: Ray | Arc
    travel: float
    virtual_start: float = 0.0
    alpha: float = 1.0
    beta: float = 0.0
    required: bool = False
    radius: float = 0.0

    def __post_init__(self):
        if not isinstance(self.name, str):
            raise HandError(f"finger name must be a string, got {self.name!r}")
        what = f"finger {self.name!r}:"
        start = check.float_array(f"{what} start", self.start, error=HandError)
        if start.shape != (2,):
            raise HandError(f"{what} start must be two numbers (x, y), got {self.start!r}")
        for value in start.tolist():
            check.at_most(f"{what} |start|", abs(check.finite(f"{what} start", value, error=HandError)),
                          tol.MAX_HAND_SIZE, " m", error=HandError)
        if not isinstance(self.trajectory, (Ray, Arc)):
            raise HandError(f"{what} trajectory must be a Ray or an Arc, got {type(self.trajectory).__name__}")
        check.bounded(f"{what} radius", self.radius, tol.MAX_HAND_SIZE, " m", error=HandError)
        check.bounded(f"{what} travel", self.travel, tol.MAX_HAND_SIZE, " m", strict=True, error=HandError)
        check.at_most(f"{what} |virtual_start|", abs(check.finite(f"{what} virtual_start", self.virtual_start,
                                                                 error=HandError)), tol.MAX_HAND_SIZE, " m",
                      error=HandError)
        check.at_most(f"{what} |alpha|", abs(check.finite(f"{what} alpha", self.alpha, error=HandError)),
                      tol.MAX_GAIN, error=HandError)
        check.bounded(f"{what} beta", self.beta, tol.MAX_GAIN, error=HandError)
        check.flag(f"{what} required", self.required, error=HandError)
        if isinstance(self.trajectory, Arc) and max(self.travel, abs(self.virtual_start)) >= self.trajectory.perimeter:
            raise HandError(f"finger {self.name!r}: travel and virtual_start must be shorter than the arc's ellipse")
        object.__setattr__(self, "start", (float(self.start[0]), float(self.start[1])))

    def points(self, lam) -> np.ndarray:
        """(m, 2) float: fingertip positions in the hand frame after travelling ``lam`` (m)."""
        lam = np.atleast_1d(np.asarray(lam, dtype=float))
        if isinstance(self.trajectory, Ray):
            offset = lam[:, None] * np.asarray(self.trajectory.closing_direction)
        else:
            offset = self.trajectory.offset(lam)
        return np.asarray(self.start) + offset

    def tangent(self, lam) -> np.ndarray:
        """(m, 2) float: unit direction of motion d points / d lam, hand frame."""
        lam = np.atleast_1d(np.asarray(lam, dtype=float))
        if isinstance(self.trajectory, Ray):
            return np.tile(np.asarray(self.trajectory.closing_direction), (len(lam), 1))
        return self.trajectory.tangent(lam)

    def polyline(self) -> tuple[np.ndarray, np.ndarray]:
        """The trajectory as chords: vertices (k+1, 2) in the hand frame and their lam (k+1,)."""
        chords = 1 if isinstance(self.trajectory, Ray) else tol.ARC_CHORDS
        lam = np.linspace(0.0, self.travel, chords + 1)
        return self.points(lam), lam

    @property
    def end(self) -> np.ndarray:
        """(2,) float: fingertip of the fully closed hand."""
        return self.points(self.travel)[0]

    @property
    def virtual_start_point(self) -> np.ndarray:
        """(2,) float: p_virt, the trajectory at ``lam = virtual_start``.

        Implements eq 3.37 (in the hand frame; :func:`to_image` places it at a pose).
        """
        return self.points(self.virtual_start)[0]



def _unit2(name: str, value) -> tuple[float, float]:
    """``value`` as a unit 2-vector (kept as given when already unit to 1e-15); HandError unless finite, non-zero."""
    c = check.float_array(name, value, error=HandError)
    if c.shape != (2,) or not np.isfinite(c).all():
        raise HandError(f"{name} must be two finite numbers, got {value!r}")
    if abs(float(np.hypot(*c)) - 1.0) <= 1e-15:
        return float(c[0]), float(c[1])
    c = c / max(np.abs(c).max(), np.finfo(float).tiny)
    norm = float(np.linalg.norm(c))
    if norm < tol.MIN_DIRECTION or not np.isfinite(norm):
        raise HandError(f"{name} must be a non-zero 2-vector, got {value!r}")
    return float(c[0] / norm), float(c[1] / norm)


def _pair(name: str, value, limit: float, unit: str, *, positive: bool = False, signed: bool = False
          ) -> tuple[float, float]:
    """``value`` as two finite numbers of magnitude at most ``limit`` (positive, or signed)."""
    c = check.float_array(name, value, error=HandError)
    if c.shape != (2,):
        raise HandError(f"{name} must be two numbers, got {value!r}")
    out = []
    for v in c.tolist():
        if signed:
            check.at_most(f"|{name}|", abs(check.finite(name, v, error=HandError)), limit, unit, error=HandError)
        else:
            check.bounded(name, v, limit, unit, strict=positive, error=HandError)
        out.append(float(v))
    return out[0], out[1]


@dataclass(frozen=True)
class FingerChain:
    """A finger's body: a planar two-link chain hanging below the palm (3-D hand frame, z down).

    The chain lies in the vertical plane through the knuckle that holds the horizontal unit vector
    ``direction``. Joint angles ``q = (q1, q2)``: ``q1`` is the proximal link's angle from the
    approach axis (+z), positive toward ``direction``; ``q2`` the distal link's angle relative to
    the proximal one, positive the same way (flexion). With absolute angles ``a1 = q1`` and
    ``a2 = q1 + q2``::

        joint = knuckle + l1 * (sin(a1) * direction, cos(a1))
        tip   = joint   + l2 * (sin(a2) * direction, cos(a2))

    Closing is one-DoF (the synergy of a one-motor hand): at closing progress ``s`` in [0, 1]
    ``q(s) = open_angles + s * (closed_angles - open_angles)``. This is how the simulated hand's
    tendon closes a free finger: each joint's preloaded spring balances the tendon torque, so both
    joints move linearly in the tendon force between the finger's start and end force, their
    ratio fixed (``contourgrasp.sim.hand_model``); ``s`` is that fraction of the way.

    A finger that leans outward by ``tilt`` when open has ``open_angles = (-tilt, 0)``, and its
    knuckle lies ``(l1 + l2) * sin(tilt)`` inward of its open tip along ``direction``.

    Attributes
    ----------
    knuckle : (2,) float
        The proximal joint's (x, y), m.
    knuckle_depth : float
        The proximal joint's depth below the palm's underside, m (>= 0; a post joins them).
    direction : (2,) float
        Unit horizontal direction of the chain's plane: positive flexion moves the tip along it.
        Normalised on creation.
    links : (2,) float
        Proximal and distal link lengths, m (joint to joint, distal: joint to the tip, the centre
        of the distal link's end cap).
    radius : float
        Radius of the links' capsules (and the post's), m.
    open_angles, closed_angles : (2,) float
        Joint angles (q1, q2) of the open (s = 0) and fully closed (s = 1) finger, rad.

    Raises
    ------
    HandError
        A value that is not a finite number in range (lengths up to ``tolerances.MAX_HAND_SIZE``,
        angles up to ``tolerances.MAX_JOINT_ANGLE`` in magnitude), or a zero direction.
    """

    knuckle: tuple[float, float]
    knuckle_depth: float
    direction: tuple[float, float]
    links: tuple[float, float]
    radius: float
    open_angles: tuple[float, float]
    closed_angles: tuple[float, float]

    def __post_init__(self):
        size = tol.MAX_HAND_SIZE
        object.__setattr__(self, "knuckle", _pair("chain knuckle", self.knuckle, size, " m", signed=True))
        object.__setattr__(self, "knuckle_depth", check.bounded("chain knuckle_depth", self.knuckle_depth, size,
                                                                " m", error=HandError))
        object.__setattr__(self, "direction", _unit2("chain direction", self.direction))
        object.__setattr__(self, "links", _pair("chain links", self.links, size, " m", positive=True))
        object.__setattr__(self, "radius", check.bounded("chain radius", self.radius, size, " m", error=HandError))
        for name in ("open_angles", "closed_angles"):
            object.__setattr__(self, name, _pair(f"chain {name}", getattr(self, name), tol.MAX_JOINT_ANGLE,
                                                 " rad", signed=True))

    @property
    def length(self) -> float:
        """l1 + l2, m."""
        return self.links[0] + self.links[1]


@dataclass(frozen=True)
class Palm:
    """The palm: a plate whose underside is the polygon ``outline`` at z = 0, ``thickness`` above it.

    Attributes
    ----------
    outline : (k, 2) float
        The underside's outline in the hand frame, k >= 3 vertices in either order, m.
    thickness : float
        Extent above the underside (toward negative z), m.

    Raises
    ------
    HandError
        Fewer than 3 vertices, a value that is not finite or beyond ``tolerances.MAX_HAND_SIZE``,
        an outline without area, or a thickness that is not positive.
    """

    outline: tuple[tuple[float, float], ...]
    thickness: float

    def __post_init__(self):
        pts = check.float_array("palm outline", self.outline, error=HandError)
        if pts.ndim != 2 or pts.shape[1] != 2 or len(pts) < 3 or not np.isfinite(pts).all():
            raise HandError(f"palm outline must be at least 3 finite (x, y) points, got {self.outline!r}")
        check.at_most("palm |outline|", float(np.abs(pts).max()), tol.MAX_HAND_SIZE, " m", error=HandError)
        if abs(signed_area(pts)) <= tol.MIN_AREA:
            raise HandError("palm outline has no area")
        check.bounded("palm thickness", self.thickness, tol.MAX_HAND_SIZE, " m", strict=True, error=HandError)
        object.__setattr__(self, "outline", tuple((float(x), float(y)) for x, y in pts))
        object.__setattr__(self, "thickness", float(self.thickness))

    @property
    def points(self) -> np.ndarray:
        """(k, 2) float: the outline."""
        return np.array(self.outline)


def chain_angles(chain: FingerChain, s) -> np.ndarray:
    """Joint angles along the closing synergy ``q(s) = open_angles + s * (closed_angles - open_angles)``.

    Parameters
    ----------
    chain : FingerChain
    s : float or (m,) float
        Closing progress, 0 open, 1 fully closed.

    Returns
    -------
    (m, 2) float
        (q1, q2) per progress, rad.
    """
    s = np.atleast_1d(np.asarray(s, dtype=float))[:, None]
    q_open, q_closed = np.asarray(chain.open_angles), np.asarray(chain.closed_angles)
    return q_open + s * (q_closed - q_open)


def chain_joints(chain: FingerChain, s) -> np.ndarray:
    """Forward kinematics of :class:`FingerChain` in the 3-D hand frame (z down from the palm).

    Parameters
    ----------
    chain : FingerChain
    s : float or (m,) float
        Closing progress in [0, 1].

    Returns
    -------
    (m, 3, 3) float
        Per progress, the knuckle, the middle joint and the tip, each (x, y, z), m.
    """
    q = chain_angles(chain, s)
    a = np.cumsum(q, axis=1)  # absolute angles from +z: (m, 2)
    (l1, l2), d = chain.links, np.asarray(chain.direction)
    step = np.asarray([l1, l2]) * np.sin(a)  # along direction
    down = np.asarray([l1, l2]) * np.cos(a)  # along z
    knuckle = np.array([*chain.knuckle, chain.knuckle_depth])
    links = np.concatenate([step[..., None] * d, down[..., None]], axis=-1)  # (m, 2, 3)
    points = knuckle + np.concatenate([np.zeros((len(q), 1, 3)), np.cumsum(links, axis=1)], axis=1)
    return points


def chain_tip(chain: FingerChain, s) -> np.ndarray:
    """The fingertip (the centre of the distal link's end cap) at closing progress ``s``.

    Parameters
    ----------
    chain : FingerChain
    s : float or (m,) float

    Returns
    -------
    (m, 3) float
        (x, y, z) in the 3-D hand frame, m.
    """
    return chain_joints(chain, s)[:, 2]


def chain_capsules(chain: FingerChain, s) -> np.ndarray:
    """The finger's capsules at closing progress ``s``, each of radius ``chain.radius``.

    Capsules: the post from the palm's underside straight down to the knuckle (of zero length
    when ``knuckle_depth`` is 0), the proximal link (knuckle to middle joint) and the distal link
    (middle joint to tip), as the simulated hand builds them.

    Parameters
    ----------
    chain : FingerChain
    s : float or (m,) float

    Returns
    -------
    (m, 3, 2, 3) float
        Per progress, per capsule (post, proximal, distal), its two end points (x, y, z), m.
    """
    joints = chain_joints(chain, s)
    top = joints[:, 0].copy()
    top[:, 2] = 0.0
    post = np.stack([top, joints[:, 0]], axis=1)
    return np.stack([post, joints[:, :2], joints[:, 1:]], axis=1)


def trajectory_polyline(finger: Finger) -> np.ndarray:
    """(k, 2) float: the finger's 2-D trajectory over its travel as a polyline, hand frame.

    A ray's is its segment; an arc's ``tolerances.CHAIN_ARC_VERTICES`` points along it.
    """
    if isinstance(finger.trajectory, Ray):
        return finger.points([0.0, finger.travel])
    return finger.points(np.linspace(0.0, finger.travel, tol.CHAIN_ARC_VERTICES))


def polyline_distance(points, polyline) -> np.ndarray:
    """Distance of each point to a polyline.

    Parameters
    ----------
    points : (m, 2) float
    polyline : (k, 2) float
        k >= 2 vertices.

    Returns
    -------
    (m,) float
    """
    p, v = np.asarray(points, dtype=float), np.asarray(polyline, dtype=float)
    a, d = v[:-1], np.diff(v, axis=0)  # (k-1, 2)
    rel = p[:, None, :] - a[None]  # (m, k-1, 2)
    t = np.clip(np.einsum("mkj,kj->mk", rel, d) / np.maximum(np.einsum("kj,kj->k", d, d), tol.PARALLEL), 0.0, 1.0)
    return np.linalg.norm(rel - t[..., None] * d, axis=-1).min(axis=1)


def chain_deviation(finger: Finger, chain: FingerChain) -> tuple[float, float, float]:
    """How far a chain's projected tip strays from the finger's 2-D trajectory, m.

    Returns
    -------
    open, closed, path : float
        Distance on the palm plane (x, y) of the open tip (s = 0) from ``finger.start``, of the
        closed tip (s = 1) from ``finger.end``, and the largest distance of the tip at
        ``tolerances.CHAIN_SAMPLES`` progresses evenly in [0, 1] from the trajectory over its
        travel (:func:`trajectory_polyline`).
    """
    tips = chain_tip(chain, np.linspace(0.0, 1.0, tol.CHAIN_SAMPLES))[:, :2]
    return (float(np.linalg.norm(tips[0] - finger.start)), float(np.linalg.norm(tips[-1] - finger.end)),
            float(polyline_distance(tips, trajectory_polyline(finger)).max()))


def check_chain(finger: Finger, chain: FingerChain) -> None:
    """Refuse a chain that does not realise its finger's 2-D trajectory.

    The chain's tip projected on the palm plane (its x, y) must be within
    ``tolerances.CHAIN_TRAJECTORY`` (1 mm) of ``finger.start`` when open (s = 0), of
    ``finger.end`` (the trajectory after ``travel``) when fully closed (s = 1), and of the 2-D
    trajectory over ``[0, travel]`` -- the segment of a ray, the elliptic arc of an arc -- at
    every one of ``tolerances.CHAIN_SAMPLES`` progresses evenly spaced in [0, 1]
    (:func:`chain_deviation`). The chain's radius must be the finger's ``radius``.

    Raises
    ------
    HandError
        Naming the finger and what is off, by how much.
    """
    limit = tol.CHAIN_TRAJECTORY
    what = f"finger {finger.name!r}: 3-D chain"
    if not np.isclose(chain.radius, finger.radius, rtol=0.0, atol=1e-12):
        raise HandError(f"{what} radius {chain.radius:g} m differs from the finger's radius {finger.radius:g} m")
    open_, closed, path = chain_deviation(finger, chain)
    for label, value in (("open tip is", open_), ("closed tip is", closed)):
        if value > limit:
            target = "the finger's start" if label.startswith("open") else "the end of the finger's travel"
            raise HandError(f"{what} {label} {1000 * value:.2f} mm from {target} on the palm plane "
                            f"(at most {1000 * limit:g} mm)")
    if path > limit:
        kind = "ray" if isinstance(finger.trajectory, Ray) else "arc"
        raise HandError(f"{what}: tip path leaves the finger's {kind} by {1000 * path:.2f} mm on the palm plane "
                        f"(at most {1000 * limit:g} mm)")


@dataclass(frozen=True)
class Hand:
    """A hand: its fingers and the feasibility rules for missed fingers.

    Attributes
    ----------
    name : str
    fingers : tuple of Finger
    min_touching : int
        A pose is feasible only when at least this many fingers touch the object.
    miss_penalty : float
        Cost added per finger that closes on air (the ``miss`` part of the cost).
    description : str
    chains : tuple of FingerChain, optional
        The fingers' bodies, one per finger in the order of ``fingers``; None (the default) for a
        2-D hand. Given together with ``palm``.
    palm : Palm, optional

    Raises
    ------
    HandError
        No fingers or more than ``tolerances.MAX_FINGERS``, a finger that is not a :class:`Finger`, names not unique, ``min_touching``
        not in 1..number of fingers, or ``miss_penalty`` not in [0, ``tolerances.MAX_GAIN``];
        chains without a palm or the reverse, not one chain per finger, or a chain that does not
        realise its finger's trajectory (:func:`check_chain`, naming the finger).
    """

    name: str
    fingers: tuple[Finger, ...]
    min_touching: int
    miss_penalty: float = 250.0
    description: str = field(default="", compare=False)
    chains: tuple[FingerChain, ...] | None = None
    palm: Palm | None = None

    def __post_init__(self):
        if not isinstance(self.name, str) or not isinstance(self.description, str):
            raise HandError(f"hand name and description must be strings, got {self.name!r}, {self.description!r}")
        if not isinstance(self.fingers, (tuple, list)) or not all(isinstance(f, Finger) for f in self.fingers):
            raise HandError(f"hand {self.name!r}: fingers must be a sequence of Finger")
        object.__setattr__(self, "fingers", tuple(self.fingers))
        n = len(self.fingers)
        if n == 0:
            raise HandError(f"hand {self.name!r} has no fingers")
        check.at_most(f"hand {self.name!r}: number of fingers", n, tol.MAX_FINGERS, error=HandError)
        if isinstance(self.min_touching, bool) or not isinstance(self.min_touching, (int, np.integer)) or not (
                1 <= self.min_touching <= n):
            raise HandError(f"hand {self.name!r}: min_touching must be in 1..{n}, got {self.min_touching!r}")
        check.bounded(f"hand {self.name!r}: miss_penalty", self.miss_penalty, tol.MAX_GAIN, error=HandError)
        if len({f.name for f in self.fingers}) != n:
            raise HandError(f"hand {self.name!r}: finger names must be unique")
        self._check_body()

    def _check_body(self) -> None:
        if (self.chains is None) != (self.palm is None):
            raise HandError(f"hand {self.name!r}: a 3-D hand needs both a chain for every finger and a palm")
        if self.chains is None:
            return
        if not isinstance(self.palm, Palm):
            raise HandError(f"hand {self.name!r}: palm must be a Palm, got {type(self.palm).__name__}")
        if not isinstance(self.chains, (tuple, list)) or not all(isinstance(c, FingerChain) for c in self.chains):
            raise HandError(f"hand {self.name!r}: chains must be a sequence of FingerChain")
        object.__setattr__(self, "chains", tuple(self.chains))
        if len(self.chains) != len(self.fingers):
            raise HandError(f"hand {self.name!r}: {len(self.chains)} chains for {len(self.fingers)} fingers")
        for finger, chain in zip(self.fingers, self.chains, strict=True):
            check_chain(finger, chain)

    @property
    def is_3d(self) -> bool:
        """True when the hand carries its bodies (chains and palm)."""
        return self.chains is not None

    @property
    def open_tip_depth(self) -> float | None:
        """Depth of the open hand's lowest fingertip (tip centre) below the palm's underside, m; None in 2-D."""
        return None if self.chains is None else max(float(chain_tip(c, 0.0)[0, 2]) for c in self.chains)

    @property
    def closing_tip_depth(self) -> float | None:
        """Deepest any fingertip (tip centre) goes below the palm's underside while closing, m; None in 2-D.

        Sampled at ``tolerances.CHAIN_SAMPLES`` closing progresses: a finger leaning outward swings its
        tip lower on the way in before it rises again.
        """
        if self.chains is None:
            return None
        s = np.linspace(0.0, 1.0, tol.CHAIN_SAMPLES)
        return max(float(chain_tip(c, s)[:, 2].max()) for c in self.chains)

    @property
    def starts(self) -> np.ndarray:
        """(n_fingers, 2) float: open-hand fingertips, hand frame."""
        return np.array([f.start for f in self.fingers])

    @property
    def ends(self) -> np.ndarray:
        """(n_fingers, 2) float: closed-hand fingertips, hand frame."""
        return np.array([f.end for f in self.fingers])

    @property
    def virtual_starts(self) -> np.ndarray:
        """(n_fingers, 2) float: virtual start points p_virt, hand frame."""
        return np.array([f.virtual_start_point for f in self.fingers])

    @property
    def grasp_centre(self) -> np.ndarray:
        """(2,) float: mean of the fully closed fingertips, hand frame."""
        return self.ends.mean(axis=0)

    def segments(self) -> "HandSegments":
        """All fingers' trajectory chords, stacked for vectorised intersection."""
        starts, ends, finger, lam0 = [], [], [], []
        for i, f in enumerate(self.fingers):
            pts, lam = f.polyline()
            starts.append(pts[:-1])
            ends.append(pts[1:])
            finger.append(np.full(len(lam) - 1, i))
            lam0.append(lam[:-1])
        return HandSegments(
            start=np.vstack(starts), end=np.vstack(ends), finger=np.concatenate(finger), lam0=np.concatenate(lam0)
        )


@dataclass(frozen=True, eq=False)
class HandSegments:
    """Trajectory chords of all fingers, hand frame.

    Attributes
    ----------
    start, end : (s, 2) float
    finger : (s,) int
        Index of the finger each chord belongs to; chords of a finger are in closing order.
    lam0 : (s,) float
        Distance travelled at each chord's start, m.
    """

    start: np.ndarray
    end: np.ndarray
    finger: np.ndarray
    lam0: np.ndarray

    @property
    def length(self) -> np.ndarray:
        return np.linalg.norm(self.end - self.start, axis=1)


def rotation(yaw) -> np.ndarray:
    """(..., 2, 2) float: R(yaw) = [[cos, -sin], [sin, cos]], hand frame -> image plane.

    Implements eq 3.19, transposed: the thesis prints R(phi_p) = [[cos, sin], [-sin, cos]], a
    rotation by -phi_p; this is the right-handed rotation by yaw (module docstring), so only the
    sign of the reported yaw differs.

    Examples
    --------
    >>> rotation(np.pi / 2).round(12) @ [1.0, 0.0]
    array([0., 1.])
    """
    c, s = np.cos(yaw), np.sin(yaw)
    return np.stack([np.stack([c, -s], -1), np.stack([s, c], -1)], -2)


def to_image(points_hand, pose) -> np.ndarray:
    """Hand-frame points placed at a pose (x, y, yaw) in the image plane.

    Parameters
    ----------
    points_hand : (m, 2) float
    pose : (3,) float

    Returns
    -------
    (m, 2) float
    """
    x, y, yaw = pose
    return np.asarray(points_hand, dtype=float) @ rotation(yaw).T + np.array([x, y])
