"""A physical, underactuated hand built from a 2-D hand preset (thesis 4.1.2, Table 4.3).

The qbHand of the experiments has one motor; a tendon runs through every
flexion joint, so a finger that touches the object stops while the others keep
closing, and all of them then squeeze with the tendon's force. This module
builds that idea as MuJoCo XML from a :class:`~contourgrasp.hand.Hand` whose
fingers close on rays.

Geometry (one truth: the hand file)
-----------------------------------
The preset's 2-D hand frame (origin at the reference point) is the plane of the
palm's underside, parallel to the image plane; the 3-D hand frame adds z along
the camera's z (down, toward the table). The hand file's 3-D part
(:class:`~contourgrasp.hand.FingerChain` per finger and
:class:`~contourgrasp.hand.Palm`) is what is built: every finger a planar chain
of two capsules (proximal, distal) hanging from its knuckle, a post from the
palm down to the knuckle when it hangs below it, both hinges perpendicular to
the chain's vertical plane, the open pose's joint angles and the closed pose's
as joint ranges; the palm a box (its outline must be an axis-aligned rectangle).
The fingertip is the centre of the distal link's end cap.

A hand without chains (a 2-D hand file) is given chains first by
:func:`derive_body` with a :class:`ChainRule` -- the rule that produced the
presets' chains (``tools/derive_hand_chains.py``): fingers ``min_length`` long
or ``length_per_travel`` times their travel, whichever is longer; both joints
flexing together in free space (distal = ``distal_ratio`` x proximal), their
ranges solved so that the fully closed finger ends exactly ``travel`` along the
ray; the open finger leaning outward by the tilt that makes the tip's height vary
least over its closing (it swings through the vertical, like a pendulum through
its lowest point: a tip that rose as it closed -- 5 cm for a thumb hanging
straight down -- would pass over flat objects such as the stones); knuckles at
depths that bring every fingertip's lowest point to the same depth; the palm the
knuckles' bounding box grown by ``palm_margin``. Radii are the fingers'
``radius`` of the hand file.

Actuation
---------
One motor pulls a fixed tendon with force ``f = phi * max_tendon_force``
(``phi`` in [0, 1] is the control). Joint j of a finger sees the torque
``c_j * f`` (``c_j`` its moment arm) against a preloaded spring. The springs are
set so that, in free space, a finger starts moving at ``phi = start`` and is
fully closed at ``phi = end`` (its :class:`FingerTiming`); beyond, the joint limit
holds it. A blocked finger pushes with the excess torque, up to
``c_j * max_tendon_force``. Timing ``"thesis"`` reproduces chapter 5's
observation: the thumb starts first and is fastest, ring and little follow,
index and middle start last but faster and catch up with ring and little at
about two thirds of their travel. ``"uniform"``: all fingers start and finish
together. The thumb (the ``required`` fingers of a preset) gets
``thumb_strength`` times the moment arms: it opposes four fingers.

Every finger joint has an armature (reflected motor inertia): without it the
light links overshoot their joint limits.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np
from scipy.optimize import brentq, minimize_scalar

from ..errors import HandError, SimulationError
from ..hand import FingerChain, Hand, Palm, Ray, chain_tip

#: Contact bits (contype/conaffinity): the table collides with hand and object,
#: the hand and the object with the table only; hand-object contacts are explicit pairs.
TABLE_BIT, OBJECT_BIT, HAND_BIT = 1, 2, 4


@dataclass(frozen=True)
class FingerTiming:
    """When a finger closes in free space, as fractions of the full tendon force.

    Attributes
    ----------
    start : float
        Tendon-force fraction at which the finger starts to move.
    end : float
        Fraction at which it reaches its fully closed pose (``start < end <= 1``).
    """

    start: float
    end: float

    def __post_init__(self):
        if not 0 <= self.start < self.end <= 1:
            raise SimulationError(f"finger timing needs 0 <= start < end <= 1, got {self.start}, {self.end}")


#: Closing schedules by name; fingers not listed close as ``"default"``.
TIMINGS = {
    "uniform": {"default": FingerTiming(0.05, 0.5)},
    "thesis": {
        "thumb": FingerTiming(0.0, 0.35),
        "ring": FingerTiming(0.08, 0.55),
        "little": FingerTiming(0.08, 0.55),
        "index": FingerTiming(0.16, 0.5),
        "middle": FingerTiming(0.16, 0.5),
        "default": FingerTiming(0.05, 0.5),
    },
}


@dataclass(frozen=True)
class HandDesign:
    """Physical parameters of the simulated hand (SI units).

    The hand's geometry (links, radii, knuckles, palm) is not here: it is the hand file's
    (:class:`~contourgrasp.hand.FingerChain`, :class:`~contourgrasp.hand.Palm`). Defaults: a
    0.5 kg hand, a grip of roughly 10 N per finger and 20-30 N at the thumb (the qbHand's
    datasheet gives ~60 N of grasp force in total). ``wrist``: the base also tilts and rolls
    (:func:`base_xml`), as a side or tilted approach needs; off, the base is the thesis's x, y, z, yaw.
    """

    finger_density: float = 900.0
    palm_mass: float = 0.40
    max_tendon_force: float = 100.0
    moment_arms: tuple[float, float] = (0.008, 0.005)
    thumb_strength: float = 2.5
    joint_damping: float = 0.05
    armature: float = 5e-4
    limit_solref: tuple[float, float] = (0.004, 1.0)
    limit_solimp: tuple[float, float, float] = (0.95, 0.99, 0.001)
    base_kp: tuple[float, float] = (4000.0, 200.0)
    base_kv: tuple[float, float] = (250.0, 20.0)
    wrist: bool = False


@dataclass(frozen=True)
class ChainRule:
    """How :func:`derive_body` gives a 2-D hand its bodies (the presets' chains came from it).

    Defaults: fingers about human size (a qbHand finger is ~0.1 m long, ~18 mm wide).

    Attributes
    ----------
    min_length, length_per_travel : float
        A finger is ``max(min_length, length_per_travel * travel)`` long, m.
    proximal_fraction : float
        The proximal link's share of that length.
    distal_ratio : float
        Distal joint range / proximal joint range (the synergy's coupling).
    palm_margin : float
        The palm is the knuckles' bounding box grown by this on every side, m.
    palm_thickness : float
        m.
    """

    min_length: float = 0.10
    length_per_travel: float = 1.35
    proximal_fraction: float = 0.55
    distal_ratio: float = 1.0
    palm_margin: float = 0.02
    palm_thickness: float = 0.025


@dataclass(frozen=True)
class FingerModel:
    """One simulated finger: its chain (from the hand file) and its actuation.

    Attributes
    ----------
    name : str
    start : (2,) float
        Open fingertip, hand frame (the preset's start).
    travel : float
    chain : FingerChain
        Knuckle, links, radius, open and closed joint angles (hand frame, z down).
    moment_arms : (2,) float
    timing : FingerTiming
    """

    name: str
    start: tuple[float, float]
    travel: float
    chain: FingerChain
    moment_arms: tuple[float, float]
    timing: FingerTiming

    @property
    def direction(self) -> tuple[float, float]:
        """(2,) float: unit horizontal direction of the chain's plane (the closing direction)."""
        return self.chain.direction

    @property
    def lengths(self) -> tuple[float, float]:
        """Proximal and distal link lengths, m."""
        return self.chain.links

    @property
    def radius(self) -> float:
        return self.chain.radius

    @property
    def tilt(self) -> float:
        """Outward lean of the open proximal link from the vertical, rad (``-open_angles[0]``)."""
        return -self.chain.open_angles[0]

    @property
    def knuckle(self) -> np.ndarray:
        """(2,) float: the knuckle's position in the hand frame."""
        return np.asarray(self.chain.knuckle)

    @property
    def knuckle_depth(self) -> float:
        """Depth of the knuckle below the palm's underside, m."""
        return self.chain.knuckle_depth

    @property
    def q_max(self) -> tuple[float, float]:
        """Joint ranges [0, q_max] from the open pose, rad."""
        (o1, o2), (c1, c2) = self.chain.open_angles, self.chain.closed_angles
        return c1 - o1, c2 - o2

    def tip(self, u) -> tuple[np.ndarray, np.ndarray]:
        """Free-space fingertip at closing fraction ``u`` in [0, 1]: advance along the ray, depth below the knuckle."""
        tip = chain_tip(self.chain, u)
        return (tip[:, :2] - self.start) @ np.asarray(self.direction), tip[:, 2] - self.knuckle_depth


@dataclass(frozen=True)
class HandModel:
    """The simulated hand: its fingers and MJCF fragments for the scene.

    Attributes
    ----------
    hand : Hand
        The 3-D hand it realises (the preset's, or its :func:`derive_body` for a 2-D one).
    design : HandDesign
    fingers : tuple of FingerModel
    tip_depth : float
        Depth of the open fingertips below the palm's underside, m.
    palm_box : (2, 2) float
        Palm plate extent in the hand frame, ``[[x_min, y_min], [x_max, y_max]]``.
    """

    hand: Hand
    design: HandDesign
    fingers: tuple[FingerModel, ...]
    tip_depth: float
    palm_box: tuple[tuple[float, float], tuple[float, float]]

    #: Nothing of this hand's palm lies below its underside, z = 0 (a mounted model's palm may: ``MountedHand``).
    palm_depth = 0.0

    @property
    def open_tip_depth(self) -> float:
        """Depth of the open hand's lowest fingertip centre below the palm's underside, m."""
        return self.hand.open_tip_depth

    @property
    def finger_names(self) -> tuple[str, ...]:
        return tuple(f.name for f in self.fingers)

    def geom_names(self) -> tuple[str, ...]:
        """Names of every hand geom (for contact pairs)."""
        links = [f"{f.name}_{k}" for f in self.fingers for k in ("proximal", "distal")]
        posts = [f"{f.name}_post" for f in self.fingers if f.knuckle_depth > 0]
        return ("palm", *posts, *links)

    def body_xml(self) -> str:
        """The ``<body>`` of the hand on its x, y, z, yaw base, for the world body."""
        d = self.design
        (x0, y0), (x1, y1) = self.palm_box
        t = self.hand.palm.thickness
        contact = f'contype="{HAND_BIT}" conaffinity="{TABLE_BIT}" group="2"'
        lines = [
            *base_xml(d),
            f'    <geom name="palm" type="box" size="{_f((x1 - x0) / 2)} {_f((y1 - y0) / 2)} {_f(t / 2)}" '
            f'pos="{_f((x0 + x1) / 2)} {_f((y0 + y1) / 2)} {_f(-t / 2)}" mass="{_f(d.palm_mass)}" '
            f'rgba="0.25 0.25 0.28 1" {contact}/>',
            '    <site name="hand_origin" pos="0 0 0" size="0.004"/>',
        ]
        for f in self.fingers:
            lines += ["    " + line for line in self._finger_xml(f, contact)]
        lines += ["  </body>", "</body>"]
        return "\n".join(lines)

    def _finger_xml(self, f: FingerModel, contact: str) -> list[str]:
        axis = f"{_f(-f.direction[1])} {_f(f.direction[0])} 0"  # z x direction: positive flexion moves the tip ahead
        rgba = 'rgba="0.9 0.85 0.75 1"'
        density = f'density="{_f(self.design.finger_density)}"'
        lines = []
        if f.knuckle_depth > 0:
            kx, ky = f.knuckle
            lines.append(f'<geom name="{f.name}_post" type="capsule" fromto="{_f(kx)} {_f(ky)} 0 '
                         f'{_f(kx)} {_f(ky)} {_f(f.knuckle_depth)}" size="{_f(f.radius)}" '
                         f'mass="0.01" {rgba} {contact}/>')
        l1, l2 = f.lengths
        (kx, ky), (dx, dy) = f.knuckle, f.direction
        lean = -f.tilt / 2  # the open finger is the vertical turned by -tilt about its hinge axis
        quat = f"{_f(np.cos(lean))} {_f(-dy * np.sin(lean))} {_f(dx * np.sin(lean))} 0"
        lines += [
            f'<body name="{f.name}_proximal" pos="{_f(kx)} {_f(ky)} {_f(f.knuckle_depth)}" quat="{quat}" '
            'gravcomp="1">',
            f'  <joint name="{f.name}_1" {self._joint_attrs(f, 0, axis)}/>',
            f'  <geom name="{f.name}_proximal" type="capsule" fromto="0 0 0 0 0 {_f(l1)}" size="{_f(f.radius)}" '
            f'{density} {rgba} {contact}/>',
            f'  <body name="{f.name}_distal" pos="0 0 {_f(l1)}"{_bend(f.chain.open_angles[1], dx, dy)} '
            'gravcomp="1">',
            f'    <joint name="{f.name}_2" {self._joint_attrs(f, 1, axis)}/>',
            f'    <geom name="{f.name}_distal" type="capsule" fromto="0 0 0 0 0 {_f(l2)}" size="{_f(f.radius)}" '
            f'{density} {rgba} {contact}/>',
            f'    <site name="{f.name}_tip" pos="0 0 {_f(l2)}" size="0.003"/>',
            "  </body>",
            "</body>",
        ]
        return lines

    def _joint_attrs(self, f: FingerModel, j: int, axis: str) -> str:
        # Free-space equilibrium: c f = k (q - q_ref); moving from phi = start to end over [0, q_max].
        c, q_max = f.moment_arms[j], f.q_max[j]
        f_max = self.design.max_tendon_force
        stiffness = c * f_max * (f.timing.end - f.timing.start) / q_max
        springref = -c * f_max * f.timing.start / stiffness
        d = self.design
        return (f'type="hinge" axis="{axis}" range="0 {_f(q_max)}" limited="true" stiffness="{_f(stiffness)}" '
                f'springref="{_f(springref)}" damping="{_f(d.joint_damping)}" armature="{_f(d.armature)}" '
                f'solreflimit="{_join(d.limit_solref)}" solimplimit="{_join(d.limit_solimp)}"')

    def tendon_xml(self) -> str:
        """The fixed tendon through every flexion joint."""
        joints = [f'    <joint joint="{f.name}_{j + 1}" coef="{_f(f.moment_arms[j])}"/>'
                  for f in self.fingers for j in range(2)]
        return "\n".join(['<fixed name="flexion">', *joints, "</fixed>"])

    def actuator_xml(self) -> str:
        """The tendon motor (control: force fraction in [0, 1]) and the base's position servos."""
        return "\n".join([
            f'<motor name="flexion" tendon="flexion" gear="{_f(self.design.max_tendon_force)}" ctrlrange="0 1"/>',
            base_servos_xml(self.design),
        ])


#: The base's joints: the x, y, z slides and the yaw hinge, and with a wrist (:attr:`HandDesign.wrist`) the tilt and
#: roll hinges.
BASE_JOINTS = ("hand_x", "hand_y", "hand_z", "hand_yaw")
WRIST_JOINTS = ("hand_tilt", "hand_roll")

#: The tilt and roll servos' gains, as multiples of the yaw servo's.
TILT_SERVO_GAIN = 10.0


def base_xml(design: HandDesign) -> tuple[str, ...]:
    """The opening lines of a hand's body: the x, y, z, yaw base (and the tilt and roll wrist of ``design.wrist``),
    and the palm body in the hand frame (x, -y, -z of the world at yaw 0), left open for the palm's contents and
    two closing tags.

    Tilt turns the approach axis away from the world's -z about the yawed y axis; roll turns the hand about its
    approach axis (:func:`contourgrasp.sim.scene.base_angles`); at tilt 0 roll and yaw share an axis, and the two
    hinges' armature keeps the mass matrix regular there.
    """
    wrist = (
        '  <joint name="hand_tilt" type="hinge" axis="0 1 0" damping="1" armature="0.01"/>',
        '  <joint name="hand_roll" type="hinge" axis="0 0 -1" damping="1" armature="0.01"/>',
    ) if design.wrist else ()
    return (
        '<body name="hand_base" gravcomp="1">',
        '  <joint name="hand_x" type="slide" axis="1 0 0" damping="20"/>',
        '  <joint name="hand_y" type="slide" axis="0 1 0" damping="20"/>',
        '  <joint name="hand_z" type="slide" axis="0 0 1" damping="20"/>',
        '  <joint name="hand_yaw" type="hinge" axis="0 0 -1" damping="1"/>',
        *wrist,
        '  <body name="palm" quat="0 1 0 0" gravcomp="1">',
    )


def base_servos_xml(design: HandDesign) -> str:
    """The position servos of the hand's base joints (x, y, z, yaw; tilt and roll with a wrist)."""
    (kp_lin, kp_yaw), (kv_lin, kv_yaw) = design.base_kp, design.base_kv
    servo = '<position name="{0}" joint="{0}" kp="{1}" kv="{2}" ctrlrange="-10 10"/>'
    stiff = TILT_SERVO_GAIN
    wrist = [servo.format(j, _f(stiff * kp_yaw), _f(stiff * kv_yaw)) for j in WRIST_JOINTS] if design.wrist else []
    return "\n".join([*(servo.format(j, _f(kp_lin), _f(kv_lin)) for j in ("hand_x", "hand_y", "hand_z")),
                      servo.format("hand_yaw", _f(kp_yaw), _f(kv_yaw)), *wrist])


def build_hand(hand: Hand, *, design: HandDesign = HandDesign(), timing: str = "thesis") -> HandModel:
    """The simulated hand of a hand whose fingers close on rays: its file's chains and palm.

    A 2-D hand (no chains) gets them from :func:`derive_body` first.

    Raises
    ------
    SimulationError
        A finger closes on an arc, an unknown ``timing``, a travel no finger of the
        :class:`ChainRule` can reach, a measured chain (:class:`~contourgrasp.hand.SampledChain`), a
        finger of radius 0, a joint whose closed angle is not beyond its open one, or a palm that is
        not an axis-aligned rectangle at z = 0.
    """
    if timing not in TIMINGS:
        raise SimulationError(f"unknown finger timing {timing!r}; choose one of {', '.join(TIMINGS)}")
    schedule = TIMINGS[timing]
    for finger in hand.fingers:
        if not isinstance(finger.trajectory, Ray):
            raise SimulationError(f"hand {hand.name!r}: finger {finger.name!r} closes on an arc; "
                             "the simulated hand realises straight (ray) trajectories only")
    if not hand.is_3d:
        hand = derive_body(hand)
    fingers = []
    for finger, chain in zip(hand.fingers, hand.chains, strict=True):
        what = f"hand {hand.name!r}: finger {finger.name!r}"
        if not isinstance(chain, FingerChain):
            raise SimulationError(f"{what} has a measured chain (joints): the simulated hand is built from planar "
                                  "chains; simulate the hand's own model instead (bench --hand-model)")
        if chain.radius <= 0:
            raise SimulationError(f"{what} has radius 0: the simulated finger needs a thickness")
        if not all(c > o for o, c in zip(chain.open_angles, chain.closed_angles, strict=True)):
            raise SimulationError(f"{what}: every closed joint angle must exceed the open one (hinges flex one way)")
        strength = design.thumb_strength if finger.required else 1.0
        fingers.append(FingerModel(name=finger.name, start=finger.start, travel=finger.travel, chain=chain,
                                   moment_arms=(strength * design.moment_arms[0], strength * design.moment_arms[1]),
                                   timing=schedule.get(finger.name, schedule["default"])))
    return HandModel(hand=hand, design=design, fingers=tuple(fingers), tip_depth=hand.closing_tip_depth,
                     palm_box=_palm_box(hand))


#: Closing progresses at which the fingertips' lowest point (the hand's tip depth) is looked for.
REACH_SAMPLES = 201


def _palm_box(hand: Hand) -> tuple[tuple[float, float], tuple[float, float]]:
    """The palm outline's extent; SimulationError unless the outline is that box (an axis-aligned rectangle)."""
    pts = hand.palm.points
    lo, hi = pts.min(axis=0), pts.max(axis=0)
    corners = {(x, y) for x in (lo[0], hi[0]) for y in (lo[1], hi[1])}
    if len(pts) != 4 or {tuple(p) for p in pts.tolist()} != corners or hand.palm.depths is not None:
        raise SimulationError(f"hand {hand.name!r}: the simulated palm is a box; its outline must be an "
                              "axis-aligned rectangle (4 corners) at z = 0")
    return (float(lo[0]), float(lo[1])), (float(hi[0]), float(hi[1]))


def derive_body(hand: Hand, rule: ChainRule = ChainRule()) -> Hand:
    """``hand`` with chains and a palm derived by ``rule`` from its 2-D fingers (module docstring).

    Radii are the fingers' ``radius``. This is how the presets' chains were made
    (``tools/derive_hand_chains.py``).

    Raises
    ------
    SimulationError
        A finger on an arc, or a travel beyond the reach of the rule's finger.
    """
    derived = []
    for finger in hand.fingers:
        if not isinstance(finger.trajectory, Ray):
            raise SimulationError(f"hand {hand.name!r}: finger {finger.name!r} closes on an arc; "
                                  "chains are derived for straight (ray) trajectories only")
        length = max(rule.min_length, rule.length_per_travel * finger.travel)
        l1, l2 = rule.proximal_fraction * length, (1 - rule.proximal_fraction) * length
        tilt, q1 = _flattest_swing(l1, l2, rule.distal_ratio, finger.travel, finger.name)
        reach = float(_tip(l1, l2, tilt, q1, rule.distal_ratio, np.linspace(0.0, 1.0, REACH_SAMPLES))[1].max())
        direction = np.asarray(finger.trajectory.closing_direction)
        derived.append((finger, l1, l2, tilt, q1, reach, np.asarray(finger.start) + (l1 + l2) * np.sin(tilt) * direction))
    tip_depth = max(d[5] for d in derived)
    chains = tuple(FingerChain(knuckle=tuple(knuckle), knuckle_depth=tip_depth - reach,
                               direction=finger.trajectory.closing_direction, links=(l1, l2), radius=finger.radius,
                               open_angles=(-tilt, 0.0), closed_angles=(-tilt + q1, rule.distal_ratio * q1))
                   for finger, l1, l2, tilt, q1, reach, knuckle in derived)
    knuckles = np.array([c.knuckle for c in chains])
    (x0, y0), (x1, y1) = knuckles.min(axis=0) - rule.palm_margin, knuckles.max(axis=0) + rule.palm_margin
    palm = Palm(outline=((x0, y0), (x1, y0), (x1, y1), (x0, y1)), thickness=rule.palm_thickness)
    try:
        return replace(hand, chains=chains, palm=palm)
    except HandError as err:  # the rule's chain strays from the ray: a bug here, not the user's
        raise SimulationError(f"hand {hand.name!r}: derived chains do not follow the fingers' rays ({err})") from None


def _bend(angle: float, dx: float, dy: float) -> str:
    """The quat attribute of a distal body bent by ``angle`` about the hinge axis; nothing when straight."""
    if angle == 0:
        return ""
    half = angle / 2
    return f' quat="{_f(np.cos(half))} {_f(-dy * np.sin(half))} {_f(dx * np.sin(half))} 0"'


def _tip(l1, l2, tilt, q1_max, ratio, u):
    """Advance along the ray and depth below the knuckle of a tip whose joints flex u * (q1_max, ratio * q1_max)."""
    a1 = -tilt + u * q1_max
    a2 = -tilt + u * (1 + ratio) * q1_max  # absolute angle of the distal link from the vertical
    advance = l1 * (np.sin(a1) - np.sin(-tilt)) + l2 * (np.sin(a2) - np.sin(-tilt))
    return advance, l1 * np.cos(a1) + l2 * np.cos(a2)


def _closing_angle(l1, l2, tilt, ratio, travel) -> float | None:
    """Proximal range q1_max that advances the tip by ``travel`` without the distal link passing horizontal."""
    q_top = (np.pi / 2 + tilt) / (1 + ratio)
    if _tip(l1, l2, tilt, q_top, ratio, 1.0)[0] < travel:
        return None
    return float(brentq(lambda q: _tip(l1, l2, tilt, q, ratio, 1.0)[0] - travel, 0.0, q_top, xtol=1e-12))


def _flattest_swing(l1, l2, ratio, travel, name) -> tuple[float, float]:
    """Open-finger tilt and proximal range whose tip path varies least in height."""
    u = np.linspace(0.0, 1.0, 101)

    def height_range(tilt):
        q1 = _closing_angle(l1, l2, tilt, ratio, travel)
        return np.inf if q1 is None else float(np.ptp(_tip(l1, l2, tilt, q1, ratio, u)[1]))

    best = minimize_scalar(height_range, bounds=(0.0, np.pi / 4), method="bounded", options={"xatol": 1e-6})
    q1 = _closing_angle(l1, l2, best.x, ratio, travel)
    if q1 is None:
        raise SimulationError(f"finger {name!r}: travel {travel} m is beyond the reach of a {l1 + l2:.3f} m finger")
    return float(best.x), q1


def _f(value: float) -> str:
    return f"{float(value):.9g}"


def _join(values) -> str:
    return " ".join(_f(v) for v in values)
