"""Finger trajectories in the hand's 2-D frame: rays and elliptic arcs (thesis 3.3), and the frame's pose.

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
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np

from .. import tolerances as tol
from .. import validation as check
from ..errors import HandError


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
    (:meth:`offset`), the ellipse point less its offset at the start. The thesis's arcs turn
    counter-clockwise (theta grows); a negative ``a_sin`` mirrors the ellipse about the hand
    frame's x axis, so the arc turns clockwise: the mirror image of a counter-clockwise finger, as
    a right hand's fingers are of a left hand's (``hand-from-model`` fits either).

    Raises
    ------
    HandError
        ``a_cos`` not positive, ``a_sin`` zero, either's magnitude above ``tolerances.MAX_HAND_SIZE``,
        or ``|phi_off|`` above ``tolerances.MAX_ARC_ANGLE``.
    """

    a_cos: float
    a_sin: float
    phi_off: float

    def __post_init__(self):
        check.bounded("arc a_cos", self.a_cos, tol.MAX_HAND_SIZE, " m", strict=True, error=HandError)
        a_sin = check.finite("arc a_sin", self.a_sin, error=HandError)
        check.bounded("arc |a_sin|", abs(a_sin), tol.MAX_HAND_SIZE, " m", strict=True, error=HandError)
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

    def length(self, theta) -> np.ndarray:
        """Arc length (m) after travelling the angle ``theta`` (rad) on the ellipse: the inverse of :meth:`angle`."""
        s, table = self._length_table
        return np.interp(theta, table, s)

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
