"""A MuJoCo hand model as the simulated hand: mounted on the scene's floating base, closed by one synergy.

The bench's own hand is built from a hand file (:mod:`contourgrasp.sim.tendon_hand`). A hand
model is simulated as itself instead: :func:`mount_model` derives its hand file
(:func:`~contourgrasp.handmodels.derive.derive_hand`) and returns a :class:`MountedHand`, which the
scene takes where it takes a :class:`~contourgrasp.sim.tendon_hand.HandModel`. The model's palm
body is attached (MjSpec) inside the scene's ``palm`` body -- the 3-D hand frame of the derived
file, on the same x, y, z, yaw base and servos -- at the pose the derivation measured, so the
planner's hand frame and the simulated one coincide. The closing control ``c`` in [0, 1] of a
trial drives every synergy actuator to ``open + c (closed - open)``, the synergy of the derivation;
held actuators keep their pre-shape. As in the bench's own hand: every body is gravity-compensated,
hand geoms touch the table by contact bits and the object by explicit pairs, never each other, and
the camera does not see them (geom group 2). Collision geoms are renamed ``<finger>_<k>`` (``palm_<k>``
for the palm's), which is how a trial tells which finger touches.
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np

from ..sim.tendon_hand import HAND_BIT, TABLE_BIT, HandDesign, base_servos_xml, base_xml
from .derive import Derivation, derive_hand, model_spec
from .lookup import load_model, subtree
from ..sim.scene import mujoco

#: Prefix of the mounted model's names in the scene.
PREFIX = "hand/"


@dataclass(frozen=True, eq=False)
class MountedHand:
    """A hand model on the scene's floating base (module docstring); the scene's ``hand``.

    Attributes
    ----------
    path : str
        The MJCF file.
    derivation : Derivation
        Its hand file (``hand``) and how it is mounted and closed (``mount``).
    design : HandDesign
        Only the base servos' gains are used.
    """

    path: str
    derivation: Derivation
    design: HandDesign = HandDesign()

    @property
    def hand(self):
        return self.derivation.hand

    @property
    def fingers(self):
        return self.hand.fingers

    @property
    def finger_names(self) -> tuple[str, ...]:
        return tuple(f.name for f in self.fingers)

    @property
    def tip_depth(self) -> float:
        return self.derivation.mount.tip_depth

    @property
    def palm_depth(self) -> float:
        return self.derivation.mount.palm_depth

    @property
    def open_tip_depth(self) -> float | None:
        """The derived hand file's open-tip depth (None for a 2-D file: no planned grasp height to execute)."""
        return self.hand.open_tip_depth

    @cached_property
    def _geom_plan(self) -> tuple[tuple[int, str], ...]:
        """(index in the model's geoms, name in the scene) of every collision geom mounted: on the palm's subtree (a
        forearm or a wrist above it stays out)."""
        finger_of = dict(self.derivation.mount.finger_bodies)
        m = _named_geoms(self.path).compile()
        mounted = subtree(m, m.body(self.derivation.mount.palm).id)
        counts, plan = {}, []
        for g in sorted(range(m.ngeom), key=lambda g: int(m.geom(g).name.removeprefix("geom"))):
            if not (m.geom_contype[g] or m.geom_conaffinity[g]) or int(m.geom_bodyid[g]) not in mounted:
                continue
            finger = finger_of.get(m.body(m.geom_bodyid[g]).name)
            owner = "palm" if finger is None else self.fingers[finger].name
            plan.append((int(m.geom(g).name.removeprefix("geom")), f"{owner}_{counts.setdefault(owner, 0)}"))
            counts[owner] += 1
        return tuple(plan)

    def geom_names(self) -> tuple[str, ...]:
        """Names of every collision geom of the hand in the scene (for contact pairs)."""
        return tuple(name for _, name in self._geom_plan)

    def body_xml(self) -> str:
        """The base and an empty ``palm`` body (the hand frame), which :meth:`mount` fills."""
        return "\n".join([*base_xml(self.design), '    <site name="hand_origin" pos="0 0 0" size="0.004"/>', "  </body>",
                          "</body>"])

    def tendon_xml(self) -> str:
        return ""

    def actuator_xml(self) -> str:
        return base_servos_xml(self.design)

    def mount(self, spec) -> None:
        """Attach the model's palm subtree inside the scene spec's ``palm`` body (module docstring)."""
        child = _named_geoms(self.path)
        new_names = dict(self._geom_plan)
        for i, geom in enumerate(child.geoms):
            geom.group = 2
            if i in new_names:
                geom.contype, geom.conaffinity = HAND_BIT, TABLE_BIT
        for body in child.bodies:
            body.gravcomp = 1.0
        mount = self.derivation.mount
        palm = child.body(mount.palm)
        palm.pos, palm.quat = [0.0, 0.0, 0.0], [1.0, 0.0, 0.0, 0.0]
        quat = np.empty(4)
        mujoco.mju_mat2Quat(quat, np.asarray(mount.rotation, dtype=float).ravel())
        frame = spec.body("palm").add_frame(pos=list(mount.position), quat=quat.tolist())
        frame.attach_body(palm, PREFIX, "")
        renamed = {f"{PREFIX}geom{i}": name for i, name in new_names.items()}
        for geom in spec.geoms:
            if geom.name in renamed:
                geom.name = renamed[geom.name]

    def synergy(self, model) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The synergy's actuator ids in the compiled scene and their open and closed controls."""
        mount = self.derivation.mount
        ids = np.array([model.actuator(PREFIX + name).id for name in mount.actuators])
        return ids, np.asarray(mount.open_controls), np.asarray(mount.closed_controls)

    def held(self, model) -> list[tuple[int, float]]:
        """The held actuators' ids in the compiled scene and their controls."""
        return [(model.actuator(PREFIX + name).id, value) for name, value in self.derivation.mount.held]


def _named_geoms(path: str):
    """The model's spec with its geoms named ``geom<i>`` in their order (unique; renamed once mounted)."""
    load_model(path)  # its checks, naming the file, before the spec is read
    child = mujoco.MjSpec.from_file(path)
    for i, geom in enumerate(child.geoms):
        geom.name = f"geom{i}"
    return child


def mount_model(model, *, fingertips=None, actuators=None, palm=None, approach=None,
                design: HandDesign = HandDesign()) -> MountedHand:
    """Derive a hand model's hand file and mount it for the simulation.

    Parameters
    ----------
    model : str or Path
        A bundled model's name (:data:`~contourgrasp.handmodels.derive.MODELS`) or an MJCF file.
    fingertips, actuators, palm, approach
        As :func:`~contourgrasp.handmodels.derive.derive_hand`.
    design : HandDesign
        The base servos' gains.

    Raises
    ------
    HandFileError, HandError, SimulationError
        As :func:`~contourgrasp.handmodels.derive.derive_hand`.
    """
    derivation = derive_hand(model, fingertips=fingertips, actuators=actuators, palm=palm, approach=approach)
    return MountedHand(path=model_spec(model, fingertips=fingertips).path, derivation=derivation, design=design)
