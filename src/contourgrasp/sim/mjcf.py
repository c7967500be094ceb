"""The simulated scene's MJCF: the table, the objects' bodies and their contact pairs, a bin, a robot arm in view,
and the solver settings (:func:`scene_xml`); :mod:`contourgrasp.sim.scene` compiles and runs it.

Contacts
--------
Object contacts are explicit pairs with the object's own frictions (glove and
table, see :mod:`contourgrasp.sim.objects`; object on object, the mean of their
table frictions; the bin's floor as the table, its walls without rolling
friction); hand geoms collide with the table and the bin by their contact bits
and never with each other. Solver settings follow what
makes grasps hold in MuJoCo: elliptic friction cones, ``impratio``
:data:`IMPRATIO`, the ``implicitfast`` integrator, a 2 ms step.

MuJoCo's friction is a soft constraint: a contact well inside its friction
cone still creeps, at a rate that falls as ``impratio`` (the friction's
impedance over the normal's) rises. Coulomb friction does not creep, and
neither does a real grasp held inside its cones, while a creeping hold lets
a squeezed light object work its way out of the hand. ``impratio`` is chosen
on a squeeze without any planner (:func:`~contourgrasp.sim.measure.squeeze_creep`:
a hold inside the cone must not creep, a load outside it must slide); the
figures, and the bench before and after: ``docs/bench.md``, "The friction's creep".
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .objects import ObjectSpec, Part
from .tendon_hand import HAND_BIT, TABLE_BIT, HandModel

#: Simulation step, s.
TIMESTEP = 0.002
#: Ratio of the friction constraints' impedance to the normal's (elliptic cones): how little a hold creeps
#: (module docstring).
IMPRATIO = 100


def solver_option(impratio: float = IMPRATIO, noslip: int = 0) -> str:
    """The scene's ``<option>`` element (module docstring); ``noslip`` MuJoCo's noslip iterations (0: off)."""
    return (f'<option timestep="{TIMESTEP}" integrator="implicitfast" cone="elliptic" impratio="{impratio:g}" '
            f'noslip_iterations="{noslip}"/>')


#: The scene's solver settings.
SOLVER = solver_option()
#: Rolling friction of objects on the table, m (torque per unit normal force).
ROLLING = 0.0005
#: Height from which the neighbours of a scene of several objects are dropped, m.
DROP_HEIGHT = 0.003
#: Half extents (x, y) of the table top, m.
TABLE_HALF = (0.6, 0.45)


@dataclass(frozen=True)
class Bin:
    """An open box fixed on the table (the bin scene): floor, four walls, all of thickness ``wall``.

    World frame: the floor's top is the plane z = 0 on which the objects rest (the
    table around the bin lies ``floor`` lower), centred on the camera's axis.

    Attributes
    ----------
    inner : (float, float)
        Floor inside the walls, x and y, m.
    height : float
        Of the walls above the floor, m.
    wall, floor : float
        Thickness of the walls and of the floor, m.
    rgba : (4,) float
    """

    inner: tuple[float, float] = (0.40, 0.30)
    height: float = 0.10
    wall: float = 0.005
    floor: float = 0.004
    rgba: tuple[float, float, float, float] = (0.25, 0.40, 0.60, 1.0)

    def geoms(self) -> list[tuple[str, tuple[float, float, float], tuple[float, float, float]]]:
        """(name, half sizes, centre) of the floor ``bin_floor`` and the walls ``bin_wall_0`` ... ``bin_wall_3``."""
        hx, hy, t, h = self.inner[0] / 2, self.inner[1] / 2, self.wall, self.height
        boxes = [("bin_floor", (hx + t, hy + t, self.floor / 2), (0.0, 0.0, -self.floor / 2))]
        for k, sign in enumerate((-1.0, 1.0)):
            boxes.append((f"bin_wall_{k}", (t / 2, hy + t, h / 2), (sign * (hx + t / 2), 0.0, h / 2)))
            boxes.append((f"bin_wall_{k + 2}", (hx, t / 2, h / 2), (0.0, sign * (hy + t / 2), h / 2)))
        return boxes

    def contains(self, xy) -> np.ndarray:
        """(...) bool: whether world points (..., 2) lie over the floor inside the walls."""
        xy = np.asarray(xy, dtype=float)
        return (np.abs(xy[..., 0]) < self.inner[0] / 2) & (np.abs(xy[..., 1]) < self.inner[1] / 2)


#: The robot arm in view (``robot=True``): (type, size, from-to or position, rgba) of static geoms, world frame, m.
#: Its forearm comes down from beyond the image's top border to a parallel gripper whose dark fingers
#: hang 9 cm above the table at (-0.20, 0.20), 12 cm beyond the workspace's corner; seen by every camera of
#: :mod:`contourgrasp.sim.render` up to a 60 deg tilt, and leaving through the image's top border in all of them.
ROBOT_ARM = (
    ("capsule", "0.04", "-0.26 1.0 0.50 -0.20 0.20 0.20", (0.80, 0.80, 0.82, 1.0)),
    ("box", "0.05 0.02 0.02", "-0.20 0.20 0.18", (0.15, 0.15, 0.15, 1.0)),
    ("box", "0.008 0.012 0.035", "-0.235 0.20 0.125", (0.15, 0.15, 0.15, 1.0)),
    ("box", "0.008 0.012 0.035", "-0.165 0.20 0.125", (0.15, 0.15, 0.15, 1.0)),
)


@dataclass(frozen=True)
class Placement:
    """The object's placement on the table before settling: world x, y (m) and yaw (rad) about world z."""

    x: float
    y: float
    yaw: float


def scene_xml(obj: ObjectSpec, hand: HandModel, placement: Placement, *, neighbours=(), bin: Bin | None = None,
              robot: bool = False) -> str:
    """The MJCF text of the whole scene.

    The object is body ``object``; ``neighbours``, (ObjectSpec, Placement)
    pairs, are bodies ``neighbour_0``, ... dropped from :data:`DROP_HEIGHT`;
    a ``bin`` is fixed to the world, its floor's top at z = 0 and the table
    that much lower; ``robot`` adds the arm of :data:`ROBOT_ARM` (geoms ``robot_0``, ...).
    """
    assets = []
    names = object_bodies(1 + len(neighbours))
    bodies = [_body_xml("object", obj, placement, assets, z=0.001)]
    bodies += [_body_xml(name, o, p, assets, z=DROP_HEIGHT) for name, (o, p) in zip(names[1:], neighbours)]
    statics = [] if bin is None else [_box_xml(name, size, pos, bin.rgba) for name, size, pos in bin.geoms()]
    statics += _robot_xml() if robot else []
    table_z = -0.02 - (bin.floor if bin is not None else 0.0)
    pairs = _pairs(list(zip(names, [obj, *(o for o, _ in neighbours)])), hand, bin)
    return f"""<mujoco model="contourgrasp-sim">
  <compiler angle="radian" autolimits="true"/>
  {SOLVER}
  <asset>
    {chr(10).join(assets)}
  </asset>
  <worldbody>
    <geom name="table" type="box" size="{TABLE_HALF[0]:g} {TABLE_HALF[1]:g} 0.02" pos="0 0 {table_z:.9g}" rgba="0.86 0.84 0.78 1"
          friction="0.5 0.005 0.0001" contype="{TABLE_BIT}" conaffinity="{HAND_BIT}" group="0"/>
    {(chr(10) + '    ').join(statics + bodies)}
    {hand.body_xml()}
  </worldbody>
  <contact>
    {chr(10).join(pairs)}
  </contact>
  <tendon>
    {hand.tendon_xml()}
  </tendon>
  <actuator>
    {hand.actuator_xml()}
  </actuator>
</mujoco>"""


def object_bodies(count: int) -> tuple[str, ...]:
    """The body names of a scene's ``count`` objects: ``object`` (built as the target), ``neighbour_0``, ..."""
    return ("object", *(f"neighbour_{k}" for k in range(count - 1)))


def _body_xml(name: str, obj: ObjectSpec, placement: Placement, assets: list[str], *, z: float) -> str:
    """A free body of ``obj``'s parts: collision geoms ``<name>_<i>``, drawn meshes ``<name>_visual_<i>``."""
    geoms = []
    collide_group = 3 if obj.visual else 0  # hidden from the camera when a visual mesh stands for it
    volumes = np.array([_volume(p) for p in obj.collision])
    for i, part in enumerate(obj.collision):
        mass = obj.mass * volumes[i] / volumes.sum()
        geoms.append(_geom_xml(f"{name}_{i}", part, assets, group=collide_group, rgba=obj.rgba, mass=mass))
    for i, part in enumerate(obj.visual):
        geoms.append(_geom_xml(f"{name}_visual_{i}", part, assets, group=1, rgba=obj.rgba, mass=0.0))
    quat = (np.cos(placement.yaw / 2), 0.0, 0.0, np.sin(placement.yaw / 2))
    return f"""<body name="{name}" pos="{placement.x:.9g} {placement.y:.9g} {z:g}" quat="{' '.join(f'{q:.9g}' for q in quat)}">
      <freejoint name="{name}"/>
      {chr(10).join(geoms)}
    </body>"""


def _box_xml(name: str, size, pos, rgba) -> str:
    """A fixed box the hand collides with, as with the table."""
    return (f'<geom name="{name}" type="box" size="{" ".join(f"{v:.9g}" for v in size)}" '
            f'pos="{" ".join(f"{v:.9g}" for v in pos)}" rgba="{" ".join(f"{v:.4g}" for v in rgba)}" '
            f'contype="{TABLE_BIT}" conaffinity="{HAND_BIT}" group="0"/>')


def _robot_xml() -> list[str]:
    """The geoms of :data:`ROBOT_ARM`: seen by the camera (group 0), in contact with nothing."""
    place = {"capsule": "fromto", "box": "pos"}
    return [f'<geom name="robot_{k}" type="{kind}" size="{size}" {place[kind]}="{where}" '
            f'rgba="{" ".join(f"{v:g}" for v in rgba)}" contype="0" conaffinity="0" group="0"/>'
            for k, (kind, size, where, rgba) in enumerate(ROBOT_ARM)]


def _pairs(bodies, hand: HandModel, bin: Bin | None = None) -> list[str]:
    """Contact pairs of the objects' parts ((name, ObjectSpec) per body) with the table, the hand, each other, the bin."""
    pairs = []
    parts = {name: [f"{name}_{i}" for i in range(len(obj.collision))] for name, obj in bodies}
    for name, obj in bodies:
        grip = grip_contact(obj)
        for geom in parts[name]:
            pairs.append(f'<pair geom1="{geom}" geom2="table" {_resting(obj)}/>')
            pairs += [f'<pair geom1="{geom}" geom2="{g}" {grip}/>' for g in hand.geom_names()]
    for k, (name, obj) in enumerate(bodies):
        for other, spec in bodies[k + 1:]:
            mu = (obj.friction_table + spec.friction_table) / 2  # no data for object on object: their mean on the table
            pairs += [f'<pair geom1="{a}" geom2="{b}" condim="3" friction="{mu} {mu}" solref="0.01 1"/>'
                      for a in parts[name] for b in parts[other]]
    for name, obj in bodies if bin is not None else ():
        for box, _, _ in bin.geoms():
            how = _resting(obj) if box == "bin_floor" else \
                f'condim="3" friction="{obj.friction_table} {obj.friction_table}" solref="0.01 1"'
            pairs += [f'<pair geom1="{geom}" geom2="{box}" {how}/>' for geom in parts[name]]
    return pairs


def grip_contact(obj: ObjectSpec) -> str:
    """The contact attributes of ``obj`` against the hand's geoms (a ``<pair>``'s, without the geoms)."""
    # condim 4 with a little torsional friction: fingertip pads resist spinning the object.
    return f'condim="4" friction="{obj.friction_hand} {obj.friction_hand} 0.005 0.0001 0.0001" solref="0.01 1"'


def _resting(obj: ObjectSpec) -> str:
    # condim 6: a little rolling resistance (0.5 mm, c_rr ~ 0.015 for a can) stops a nudged can rolling off.
    return (f'condim="6" friction="{obj.friction_table} {obj.friction_table} 0.005 {ROLLING} {ROLLING}" '
            'solref="0.01 1"')


def _geom_xml(name: str, part: Part, assets: list[str], *, group: int, rgba, mass: float) -> str:
    collide = 'contype="0" conaffinity="0"'  # object contacts are explicit pairs
    common = (f'name="{name}" pos="{" ".join(f"{v:.9g}" for v in part.pos)}" '
              f'quat="{" ".join(f"{v:.9g}" for v in part.quat)}" group="{group}" '
              f'rgba="{" ".join(f"{v:.4g}" for v in rgba)}" mass="{mass:.9g}" {collide}')
    if part.kind != "mesh":
        return f'<geom type="{part.kind}" size="{" ".join(f"{v:.9g}" for v in part.size)}" {common}/>'
    vertices = " ".join(f"{v:.7g}" for v in np.asarray(part.vertices).ravel())
    faces = "" if part.faces is None else f' face="{" ".join(str(int(v)) for v in np.asarray(part.faces).ravel())}"'
    inertia = ' inertia="shell"' if mass == 0 else ""  # drawn-only meshes need not be closed
    assets.append(f'<mesh name="{name}" vertex="{vertices}"{faces}{inertia}/>')
    return f'<geom type="mesh" mesh="{name}" {common}/>'


def _volume(part: Part) -> float:
    """Volume of a collision part (m^3): the convex hull for a mesh."""
    from scipy.spatial import ConvexHull

    s = part.size
    if part.kind == "mesh":
        return float(ConvexHull(np.asarray(part.vertices)).volume)
    return {
        "box": lambda: 8 * s[0] * s[1] * s[2],
        "cylinder": lambda: 2 * np.pi * s[0] ** 2 * s[1],
        "capsule": lambda: 2 * np.pi * s[0] ** 2 * s[1] + 4 / 3 * np.pi * s[0] ** 3,
        "sphere": lambda: 4 / 3 * np.pi * s[0] ** 3,
        "ellipsoid": lambda: 4 / 3 * np.pi * s[0] * s[1] * s[2],
    }[part.kind]()
