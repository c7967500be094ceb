"""The hand's 3-D body: each finger a chain of capsules below the palm, and the palm's plate.

A hand may carry its bodies: per finger a :class:`FingerChain` (a planar two-link chain, as our
presets' fingers are) or a :class:`SampledChain` (any chain, as measured on a hand model), and a
:class:`Palm`. They live in the *3-D hand frame*: x and y those of the 2-D hand
frame (:mod:`contourgrasp.hand.trajectory`), in the plane of the palm's underside, and z along the
approach, positive *below* the palm toward the object (the camera's z for a top-down view). Every
finger is a planar two-link chain (proximal, distal) in the vertical plane
through its knuckle that holds its horizontal ``direction``; its closing is the
one-DoF synergy of an underactuated hand,
``q(s) = open_angles + s * (closed_angles - open_angles)`` for closing progress
``s`` in [0, 1]. A finger whose joints do not turn in one plane (a curling finger of a model hand,
an opposed thumb with four hinges) is a :class:`SampledChain` instead: its joints' positions
measured at closing progresses evenly spaced in [0, 1], a chain of straight links between them,
linearly interpolated between samples. :func:`chain_joints`, :func:`chain_tip` and
:func:`chain_capsules` are the forward kinematics of either; :func:`check_chain` ties a chain to the
2-D trajectory the planner uses.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np

from .. import tolerances as tol
from .. import validation as check
from ..contour.polygon import signed_area
from ..errors import HandError
from .trajectory import (
    Finger,
    Ray,
    _pair,
    _unit2,
    polyline_distance,
    trajectory_polyline,
)


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
    ratio fixed (``contourgrasp.sim.tendon_hand``); ``s`` is that fraction of the way.

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
class SampledChain:
    """A finger's body as measured along its closing: its joints at evenly spaced closing progresses.

    Sample ``k`` of ``m`` is the finger at closing progress ``s = k / (m - 1)``: its joints from the
    palm to the tip -- the first hinge (the knuckle), the further hinges, and last the fingertip (the
    centre of its end cap) -- in the 3-D hand frame (z down from the palm's underside). The body is a
    post from the palm's underside straight down to the knuckle and a straight link between each two
    consecutive points, all capsules of ``radius``; between samples every point moves linearly.

    Attributes
    ----------
    joints : (m, j, 3) float
        m >= 2 samples (at most ``tolerances.MAX_CHAIN_SAMPLES``) of j >= 2 points (at most
        ``tolerances.MAX_CHAIN_POINTS``), m.
    radius : float
        Radius of the capsules, m.

    Raises
    ------
    HandError
        A shape out of those bounds, a value that is not finite or beyond ``tolerances.MAX_HAND_SIZE``.

    Examples
    --------
    >>> chain = SampledChain(joints=[[[0, 0, 0.01], [0, 0, 0.06]], [[0, 0, 0.01], [0.02, 0, 0.055]]], radius=0.008)
    >>> chain_tip(chain, 0.5).round(4).tolist()
    [[0.01, 0.0, 0.0575]]
    """

    joints: tuple[tuple[tuple[float, float, float], ...], ...]
    radius: float

    def __post_init__(self):
        points = check.float_array("chain joints", self.joints, error=HandError)
        if points.ndim != 3 or points.shape[2] != 3 or not (2 <= points.shape[0] <= tol.MAX_CHAIN_SAMPLES) or not (
                2 <= points.shape[1] <= tol.MAX_CHAIN_POINTS):
            raise HandError(f"chain joints must be 2..{tol.MAX_CHAIN_SAMPLES} samples of 2..{tol.MAX_CHAIN_POINTS} "
                            f"(x, y, z) points, got shape {points.shape}")
        if not np.isfinite(points).all():
            raise HandError("chain joints must be finite numbers")
        check.at_most("chain |joints|", float(np.abs(points).max()), tol.MAX_HAND_SIZE, " m", error=HandError)
        object.__setattr__(self, "joints", tuple(tuple(tuple(float(v) for v in p) for p in sample) for sample in points))
        object.__setattr__(self, "radius", check.bounded("chain radius", self.radius, tol.MAX_HAND_SIZE, " m",
                                                         error=HandError))

    @property
    def points(self) -> np.ndarray:
        """(m, j, 3) float: :attr:`joints`."""
        return np.array(self.joints)


@dataclass(frozen=True)
class Palm:
    """The palm: a plate whose underside is the planar polygon ``outline``, ``thickness`` above it.

    The underside lies at z = 0 (the palm plane) unless ``depths`` tilts or lowers it: a hand model's
    palm read :data:`~contourgrasp.handmodels.derive.LEVEL` is tilted, and part of it lies below the
    shallowest knuckle, where z = 0 is.

    Attributes
    ----------
    outline : (k, 2) float
        The underside's outline in the hand frame, projected on the palm plane, k >= 3 vertices in
        either order, m.
    thickness : float
        Extent above the underside (toward negative z), m.
    depths : (k,) float or None
        Each vertex's z (its depth below the palm plane), m; the vertices must lie on one plane
        (within ``tolerances.PALM_PLANARITY``). None: all 0. Given with the outline as (x, y, z)
        vertices too.

    Raises
    ------
    HandError
        Fewer than 3 vertices, a value that is not finite or beyond ``tolerances.MAX_HAND_SIZE``,
        an outline without area, vertices off one plane, or a thickness that is not positive.

    Examples
    --------
    >>> Palm(outline=((0, 0, 0.01), (0.1, 0, 0.03), (0.1, 0.1, 0.04), (0, 0.1, 0.02)), thickness=0.02).plane.round(3)
    array([0.01, 0.2 , 0.1 ])
    """

    outline: tuple[tuple[float, float], ...]
    thickness: float
    depths: tuple[float, ...] | None = None

    def __post_init__(self):
        pts = check.float_array("palm outline", self.outline, error=HandError)
        if pts.ndim != 2 or pts.shape[1] not in (2, 3) or len(pts) < 3 or not np.isfinite(pts).all():
            raise HandError(f"palm outline must be at least 3 finite (x, y) or (x, y, z) points, got {self.outline!r}")
        depths = pts[:, 2] if pts.shape[1] == 3 else self.depths
        if depths is not None:
            if pts.shape[1] == 3 and self.depths is not None:
                raise HandError("palm depths given twice: in the outline's (x, y, z) vertices and as depths")
            depths = check.float_array("palm depths", depths, error=HandError)
            if depths.shape != (len(pts),) or not np.isfinite(depths).all():
                raise HandError(f"palm depths must be one finite number per outline vertex ({len(pts)}), "
                                f"got {self.depths!r}")
            check.at_most("palm |depths|", float(np.abs(depths).max()), tol.MAX_HAND_SIZE, " m", error=HandError)
        pts = pts[:, :2]
        check.at_most("palm |outline|", float(np.abs(pts).max()), tol.MAX_HAND_SIZE, " m", error=HandError)
        if abs(signed_area(pts)) <= tol.MIN_AREA:
            raise HandError("palm outline has no area")
        check.bounded("palm thickness", self.thickness, tol.MAX_HAND_SIZE, " m", strict=True, error=HandError)
        object.__setattr__(self, "outline", tuple((float(x), float(y)) for x, y in pts))
        object.__setattr__(self, "thickness", float(self.thickness))
        object.__setattr__(self, "depths", None if depths is None or not depths.any() else tuple(map(float, depths)))
        if self.depths is not None:
            off = float(np.abs(np.c_[np.ones(len(pts)), pts] @ self.plane - np.asarray(self.depths)).max())
            if off > tol.PALM_PLANARITY:
                raise HandError(f"palm outline's vertices are {1000 * off:.2f} mm off one plane "
                                f"(at most {1000 * tol.PALM_PLANARITY:g} mm)")

    @property
    def points(self) -> np.ndarray:
        """(k, 2) float: the outline."""
        return np.array(self.outline)

    @functools.cached_property
    def plane(self) -> np.ndarray:
        """(3,) float: (a, b, c) with the underside's z = a + b x + c y (least squares through the vertices)."""
        if self.depths is None:
            return np.zeros(3)
        design = np.c_[np.ones(len(self.outline)), self.points]
        return np.linalg.lstsq(design, np.asarray(self.depths), rcond=None)[0]


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


def chain_joints(chain: FingerChain | SampledChain, s) -> np.ndarray:
    """Forward kinematics of a chain in the 3-D hand frame (z down from the palm).

    Parameters
    ----------
    chain : FingerChain or SampledChain
    s : float or (m,) float
        Closing progress in [0, 1] (clipped to it for a :class:`SampledChain`).

    Returns
    -------
    (m, j, 3) float
        Per progress, the chain's points from the knuckle to the tip, each (x, y, z), m: a
        :class:`FingerChain`'s knuckle, middle joint and tip (j = 3), a :class:`SampledChain`'s
        joints interpolated between its samples.
    """
    if isinstance(chain, SampledChain):
        return _sampled_joints(chain, s)
    q = chain_angles(chain, s)
    a = np.cumsum(q, axis=1)  # absolute angles from +z: (m, 2)
    (l1, l2), d = chain.links, np.asarray(chain.direction)
    step = np.asarray([l1, l2]) * np.sin(a)  # along direction
    down = np.asarray([l1, l2]) * np.cos(a)  # along z
    knuckle = np.array([*chain.knuckle, chain.knuckle_depth])
    links = np.concatenate([step[..., None] * d, down[..., None]], axis=-1)  # (m, 2, 3)
    points = knuckle + np.concatenate([np.zeros((len(q), 1, 3)), np.cumsum(links, axis=1)], axis=1)
    return points


def _sampled_joints(chain: SampledChain, s) -> np.ndarray:
    samples = _samples(chain)
    return interpolate_samples(samples, np.clip(np.atleast_1d(np.asarray(s, dtype=float)), 0.0, 1.0)
                               * (len(samples) - 1))


def interpolate_samples(samples: np.ndarray, at: np.ndarray) -> np.ndarray:
    """(n, j, 3) float: points moving linearly between consecutive ``samples`` (m >= 2, j, 3) at fractional
    sample indices ``at`` (n,) in [0, m - 1] -- how a :class:`SampledChain` moves between its samples."""
    k = np.minimum(np.floor(at).astype(int), len(samples) - 2)
    w = (at - k)[:, None, None]
    return (1.0 - w) * samples[k] + w * samples[k + 1]


@functools.lru_cache(maxsize=64)
def _samples(chain: SampledChain) -> np.ndarray:
    """A sampled chain's joints as an array, built once: the search asks for them per batch of poses."""
    return chain.points


def chain_tip(chain: FingerChain | SampledChain, s) -> np.ndarray:
    """The fingertip (the centre of the distal link's end cap) at closing progress ``s``.

    Parameters
    ----------
    chain : FingerChain or SampledChain
    s : float or (m,) float

    Returns
    -------
    (m, 3) float
        (x, y, z) in the 3-D hand frame, m.
    """
    return chain_joints(chain, s)[:, -1]


def chain_capsules(chain: FingerChain | SampledChain, s) -> np.ndarray:
    """The finger's capsules at closing progress ``s``, each of radius ``chain.radius``.

    Capsules: the post from the palm's underside straight down to the knuckle (of zero length
    when the knuckle is at z = 0), then a link between each two consecutive points of
    :func:`chain_joints` -- a :class:`FingerChain`'s proximal (knuckle to middle joint) and distal
    (middle joint to tip) links, as the simulated hand builds them.

    Parameters
    ----------
    chain : FingerChain or SampledChain
    s : float or (m,) float

    Returns
    -------
    (m, j, 2, 3) float
        Per progress, per capsule (post, then the links palm side first), its two end points (x, y, z), m.
    """
    joints = chain_joints(chain, s)
    top = joints[:, 0].copy()
    top[:, 2] = 0.0
    post = np.stack([top, joints[:, 0]], axis=1)
    return np.concatenate([post[:, None], np.stack([joints[:, :-1], joints[:, 1:]], axis=2)], axis=1)


def chain_plane(chain: FingerChain | SampledChain) -> tuple[np.ndarray, np.ndarray]:
    """The vertical plane a finger closes in: its knuckle's (x, y) and a horizontal unit direction it closes along.

    A :class:`FingerChain`'s own ``knuckle`` and ``direction``; a :class:`SampledChain`'s open knuckle and the
    direction of its tip's motion from open to closed (from the knuckle to the open tip where the tip ends
    where it began). A measured chain need not lie in one plane: this is a plane to draw it in.

    Returns
    -------
    knuckle, direction : (2,) float
    """
    if isinstance(chain, FingerChain):
        return np.asarray(chain.knuckle), np.asarray(chain.direction)
    open_, closed = chain_joints(chain, [0.0, 1.0])
    knuckle = open_[0, :2]
    for towards in (closed[-1, :2] - open_[-1, :2], open_[-1, :2] - knuckle):
        if np.linalg.norm(towards) > tol.FINGER_MOVED:
            return knuckle, towards / np.linalg.norm(towards)
    return knuckle, np.array([1.0, 0.0])


def link_names(chain: FingerChain | SampledChain) -> tuple[str, ...]:
    """Names of :func:`chain_capsules`'s capsules: "post", then "proximal", ("middle",) "distal", or "link k"."""
    links = chain_joints(chain, 0.0).shape[1] - 1
    names = {1: ("distal",), 2: ("proximal", "distal"), 3: ("proximal", "middle", "distal")}
    return ("post",) + names.get(links, tuple(f"link {k + 1}" for k in range(links)))


def chain_deviation(finger: Finger, chain: FingerChain | SampledChain) -> tuple[float, float, float]:
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


def check_chain(finger: Finger, chain: FingerChain | SampledChain) -> None:
    """Refuse a chain that does not realise its finger's 2-D trajectory.

    The chain's tip projected on the palm plane (its x, y) must be within
    ``tolerances.CHAIN_TRAJECTORY`` (1 mm) of ``finger.start`` when open (s = 0), of
    ``finger.end`` (the trajectory after ``travel``) when fully closed (s = 1), and of the 2-D
    trajectory over ``[0, travel]`` -- the segment of a ray, the elliptic arc of an arc -- at
    every one of ``tolerances.CHAIN_SAMPLES`` progresses evenly spaced in [0, 1]
    (:func:`chain_deviation`). A :class:`SampledChain` is held to ``tolerances.MODEL_FIT_TOLERANCE``
    (3 mm) instead: it is a hand model's finger as measured, and its trajectory a ray or arc fitted
    to that same path within that tolerance (:mod:`contourgrasp.handmodels.fit`), so the measured
    finger is refused only where the fit would be. The chain's radius must be the finger's ``radius``.

    Raises
    ------
    HandError
        Naming the finger and what is off, by how much.
    """
    limit = tol.MODEL_FIT_TOLERANCE if isinstance(chain, SampledChain) else tol.CHAIN_TRAJECTORY
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
