"""The simulated workspace of thesis 4.1.3: a table, one object, a camera looking straight down, the hand.

Frames
------
World: z up, the table top is the plane z = 0, the camera hangs above the world
origin. Camera optical frame (the README's convention): x right, y down, z
forward, i.e. ``R_world_camera = diag(1, -1, -1)`` at ``(0, 0, height)``: the
image plane is parallel to the table (the thesis's restriction) and a point on
the table has depth ``height``.

The object is placed with its resting face down at a random position inside
:class:`Workspace` and a random yaw (both from the seed), then left to settle
for :data:`SETTLE_TIME`, and longer while anything still moves (:meth:`Scene.settle`),
before anything looks at it: an object whose resting face is an unstable stand (the YCB
Windex bottle's, with its mesh's uniform density) falls over first, and the
picture shows it where it lies.

A scene may also hold neighbours (bodies ``neighbour_0``, ...) and a
:class:`~contourgrasp.sim.mjcf.Bin`, whose floor's top is then the plane z = 0 and the table that much
lower; :mod:`contourgrasp.sim.clutter` arranges and builds such scenes, and
:attr:`Scene.view` is their tilted camera. With ``robot=True`` a robot arm
(:data:`~contourgrasp.sim.mjcf.ROBOT_ARM`) is parked beside the workspace, in every camera's view: it
is seen and never touched (it has no contacts), as a robot's own arm and gripper
are in the picture of a camera that watches its table. The scene's MJCF, its contacts and its solver
settings: :mod:`contourgrasp.sim.mjcf`.
"""

from __future__ import annotations

import contextlib
import copy
import math
import os
from dataclasses import dataclass

import numpy as np

os.environ.setdefault("MUJOCO_GL", "disable")  # we only ray-cast; never load an OpenGL backend
import mujoco  # noqa: E402

from ..errors import SimulationError  # noqa: E402
from ..hand import Hand  # noqa: E402
from ..perception import Intrinsics  # noqa: E402
from ..io.hand_file import load_hand  # noqa: E402
from ..tolerances import HOLD_SPEED, NEIGHBOUR_LIFT, SENSOR_RANGE  # noqa: E402
from .mjcf import TABLE_HALF, Bin, Placement, object_bodies, scene_xml  # noqa: E402
from .tendon_hand import BASE_JOINTS, WRIST_JOINTS, HandDesign, HandModel, build_hand  # noqa: E402
from .objects import ObjectSpec, object_spec  # noqa: E402

#: Time the object is left to settle on the table before the picture, s.
SETTLE_TIME = 0.4
#: A scene is at rest when nothing in it moves faster than ``REST_SPEED`` (m/s; a turn at ``REST_RADIUS`` m from
#: the body's origin); it is checked every ``REST_CHECK`` s and settles for at most ``MAX_SETTLE_TIME`` s.
REST_SPEED = 0.01
REST_RADIUS = 0.1
REST_CHECK = 0.1
MAX_SETTLE_TIME = 3.0
#: Height of the parked hand, far above the camera (m).
PARK_HEIGHT = 2.0
#: Rotation from the camera optical frame to the world frame.
R_WORLD_CAMERA = np.diag([1.0, -1.0, -1.0])
#: Where :meth:`Scene.remove` parks an object (world x, y, z, m; the next one a metre farther along x), far from
#: the table and every camera's view, and the damping (N s/m) of its free joint that holds it there.
REMOVED_AT, REMOVED_DAMPING = (10.0, 10.0, -5.0), 1e6
#: Seconds the hand closes on nothing for :meth:`Scene.free_closure`, and at most how much longer it may take to
#: be still (the Inspire's fingers take about 5 s).
FREE_CLOSURE_TIME, FREE_CLOSURE_WAIT = 1.5, 10.0
#: At most this long (s) :meth:`Scene.hand_reading` waits for the fingers to be still.
READ_WAIT = 5.0


#: The simulated camera: an Intel RealSense SR300 depth stream at 640 x 480 as librealsense reports it
#: (fx = fy = 472.95 px, principal point (310.21, 245.26), ~68 x 54 degrees). Colour is rendered
#: registered to depth, as the thesis uses both in one pixel grid.
SR300 = Intrinsics(fx=472.95, fy=472.95, cx=310.21, cy=245.26, width=640, height=480)


@dataclass(frozen=True)
class Camera:
    """A camera looking straight down from ``height`` m above the table at the world origin.

    Attributes
    ----------
    height : float
        Of the optical centre above the table, m.
    intrinsics : contourgrasp.perception.Intrinsics
        Default :data:`SR300`.
    depth_range : (float, float)
        Readings outside this range are missing (0), m; default the thesis's sensor range 0.2-1.5 m (4.1.2).
    """

    height: float = 0.65
    intrinsics: Intrinsics = SR300
    depth_range: tuple[float, float] = SENSOR_RANGE

    @property
    def position(self) -> np.ndarray:
        """(3,) float: optical centre, world frame."""
        return np.array([0.0, 0.0, self.height])

    def to_world(self, points) -> np.ndarray:
        """(..., 3) float: camera-frame points in the world frame."""
        return np.asarray(points, dtype=float) @ R_WORLD_CAMERA.T + self.position

    def from_world(self, points) -> np.ndarray:
        """(..., 3) float: world points in the camera frame."""
        return (np.asarray(points, dtype=float) - self.position) @ R_WORLD_CAMERA


@dataclass(frozen=True)
class Workspace:
    """Where the object may be put: a rectangle on the table around the camera's axis, m (world x, y)."""

    half_x: float = 0.12
    half_y: float = 0.08


@dataclass(frozen=True, eq=False)
class HandReading:
    """What a real hand and its wrist report: the finger joints (its encoders) and the load it carries.

    Attributes
    ----------
    joints : (j,) float
        Every joint below the palm, rad (m for a slide).
    load : float
        The force the hand's base holds up along the world's vertical, N: a wrist force-torque sensor's
        reading (the simulated hand's own weight is compensated, so what it holds weighs on it).
    """

    joints: np.ndarray
    load: float


class Scene:
    """A MuJoCo model and state of table, object, hand and camera (mutable: it is simulated).

    Attributes
    ----------
    model : mujoco.MjModel
    data : mujoco.MjData
    object : ObjectSpec
        The object to grasp (the target), body ``object``.
    hand : HandModel
    camera : Camera
        The top-down reference camera: its frame is the one grasps are executed in.
    placement : Placement
    kind : str
        ``"single"``, ``"clutter"`` or ``"bin"`` (:mod:`contourgrasp.sim.clutter`).
    neighbours : tuple of ObjectSpec
        The other objects as built, bodies ``neighbour_0``, ``neighbour_1``, ...
    bin : Bin or None
    view : (eye, R_world_camera) or None
        Where the planner's picture is taken from when not from ``camera`` (a tilted camera).
    target : int
        Which object is the target, in :attr:`objects`' order (0, body ``object``, until :meth:`retarget`).
    closed : bool
        Whether the hand was last commanded fully closed (a robot knows what it commanded: a grasp stopped
        by a touch on the way down never closed).

    Every object but the target and those taken out (:meth:`remove`) is a neighbour: the hand must not touch it.
    """

    def __init__(self, model, data, obj: ObjectSpec, hand: HandModel, camera: Camera, placement: Placement, *,
                 kind: str = "single", neighbours: tuple[ObjectSpec, ...] = (), bin: Bin | None = None, view=None):
        self.model, self.data = model, data
        self.hand, self.camera, self.placement = hand, camera, placement
        self.kind, self.neighbours, self.bin, self.view = kind, tuple(neighbours), bin, view
        self.objects = (obj, *self.neighbours)
        self._bodies = np.array([model.body(name).id for name in object_bodies(len(self.objects))], dtype=int)
        self._present = np.ones(len(self.objects), dtype=bool)
        self.target = 0
        self._palm = model.body("palm").id
        joints = BASE_JOINTS + (WRIST_JOINTS if hand.design.wrist else ())
        self._base_qpos = np.array([model.joint(j).qposadr[0] for j in joints])
        self._base_ctrl = np.array([model.actuator(j).id for j in joints])
        self._base_dofs = np.array([model.joint(j).dofadr[0] for j in joints])
        below_palm = [j for j in range(model.njnt) if _descends(model, model.jnt_bodyid[j], self._palm)]
        self._finger_qpos, self._finger_dofs = model.jnt_qposadr[below_palm], model.jnt_dofadr[below_palm]
        self._free_closure, self.closed = None, False
        synergy = getattr(hand, "synergy", None)  # a mounted hand model (handmodels.mount) closes many actuators
        self._closing = synergy(model) if synergy else (np.array([model.actuator("flexion").id]), np.zeros(1),
                                                        np.ones(1))
        for actuator, value in getattr(hand, "held", lambda _: [])(model):
            data.ctrl[actuator] = value

    @property
    def time(self) -> float:
        return float(self.data.time)

    @property
    def object(self) -> ObjectSpec:
        """The target."""
        return self.objects[self.target]

    @property
    def object_body(self) -> int:
        """The target's MuJoCo body id."""
        return int(self._bodies[self.target])

    @property
    def _neighbour_bodies(self) -> np.ndarray:
        others = self._present.copy()
        others[self.target] = False
        return self._bodies[others]

    @property
    def present(self) -> tuple[int, ...]:
        """The objects (indices into :attr:`objects`) still in the scene: none taken out by :meth:`remove`."""
        return tuple(int(k) for k in np.flatnonzero(self._present))

    def retarget(self, index: int) -> None:
        """Make object ``index`` (of :attr:`objects`, present) the target; the others present are its neighbours."""
        if index not in self.present:
            raise SimulationError(f"object {index} is not in the scene: it has {len(self.objects)} objects, "
                                  f"present {list(self.present)}")
        self.target = index

    def remove(self, index: int) -> None:
        """Take object ``index`` out of the scene: parked far from the table (``REMOVED_AT``, a metre apart),
        held there by its free joint's damping, never seen or touched again -- a robot put it in a box."""
        body = int(self._bodies[index])
        joint = self.model.body_jntadr[body]
        qpos, dofs = self.model.jnt_qposadr[joint], self.model.jnt_dofadr[joint] + np.arange(6)
        self.data.qpos[qpos:qpos + 7] = [REMOVED_AT[0] + index, *REMOVED_AT[1:], 1.0, 0.0, 0.0, 0.0]
        self.data.qvel[dofs] = 0.0
        self.model.dof_damping[dofs] = REMOVED_DAMPING
        self._present[index] = False
        with mujoco_warnings():
            mujoco.mj_forward(self.model, self.data)

    def on_support(self) -> np.ndarray:
        """(k,) bool: per object present (:attr:`present`' order), whether its centre of mass is over the table
        (the bin's floor, in a bin) and above its top."""
        return self._supported(self.coms())

    def coms(self) -> np.ndarray:
        """(k, 3) float: the centres of mass of the objects present (:attr:`present`' order), world."""
        return self.data.xipos[self._bodies[self._present]].copy()

    def _supported(self, coms) -> np.ndarray:
        """(k,) bool: whether each centre of mass (k, 3) is over the table (the bin's floor) and above its top."""
        over = self.bin.contains(coms[:, :2]) if self.bin else np.all(np.abs(coms[:, :2]) < TABLE_HALF, axis=1)
        return over & (coms[:, 2] > 0.0)

    def object_position(self) -> np.ndarray:
        """(3,) float: the object's body origin (resting-face centre at placement), world."""
        return self.data.xpos[self.object_body].copy()

    def object_com(self) -> np.ndarray:
        """(3,) float: the object's centre of mass, world."""
        return self.data.xipos[self.object_body].copy()

    def neighbour_coms(self) -> np.ndarray:
        """(k, 3) float: the neighbours' centres of mass, world."""
        return self.data.xipos[self._neighbour_bodies].copy()

    def obstacle_geoms(self) -> np.ndarray:
        """Geom ids the hand must not touch: every neighbour's, and the bin's walls (not its floor)."""
        model = self.model
        neighbours = np.isin(model.geom_bodyid, self._neighbour_bodies)
        walls = [model.geom(name).id for name, _, _ in (self.bin.geoms()[1:] if self.bin else [])]
        return np.union1d(np.flatnonzero(neighbours), walls).astype(int)

    def displaced_neighbours(self, rest) -> list[int]:
        """Neighbours (indices) lifted or knocked off since their centres of mass were at ``rest`` (k, 3).

        Lifted: risen more than :data:`~contourgrasp.tolerances.NEIGHBOUR_LIFT`; knocked off: the
        centre of mass is no longer over the table (over the bin's floor, in a bin) or below its top.
        """
        now = self.neighbour_coms()
        gone = (now[:, 2] - np.asarray(rest)[:, 2] > NEIGHBOUR_LIFT) | ~self._supported(now)
        return [int(k) for k in np.flatnonzero(gone)]

    def to_reference(self, T_view_hand) -> tuple[float, float, float, float]:
        """A hand pose planned in :attr:`view`'s optical frame as (x, y, yaw, approach depth) in :attr:`camera`'s.

        The hand's reference point is kept; its approach is taken along the
        world's vertical (the planner's is the table normal it estimated, a
        fraction of a degree off) and its yaw from its x axis projected on the
        table. The approach depth is that point's depth in the reference camera.
        """
        eye, R_world_view = self.view
        T = np.asarray(T_view_hand, dtype=float)
        origin = self.camera.from_world(R_world_view @ T[:3, 3] + eye)
        x_axis = R_WORLD_CAMERA.T @ R_world_view @ T[:3, 0]
        return float(origin[0]), float(origin[1]), float(np.arctan2(x_axis[1], x_axis[0])), float(origin[2])

    def object_points(self) -> np.ndarray:
        """(p, 3) float: surface points of the object's collision parts where it lies now, world."""
        rotation = self.data.xmat[self.object_body].reshape(3, 3)
        return self.object.points() @ rotation.T + self.data.xpos[self.object_body]

    def palm_pose(self) -> tuple[np.ndarray, np.ndarray]:
        """World position (3,) and rotation (3, 3) of the hand frame."""
        return self.data.xpos[self._palm].copy(), self.data.xmat[self._palm].reshape(3, 3).copy()

    def hand_base(self) -> np.ndarray:
        """(4,) or (6,) float: the hand base's joints now (x, y, z of the hand-frame origin, world; yaw; with a wrist
        tilt and roll), as :meth:`command` takes them."""
        return np.array(self.data.qpos[self._base_qpos], dtype=float)

    def hand_reading(self) -> HandReading:
        """What the hand and its wrist report once its fingers are still (:class:`HandReading`): the scene is
        stepped, the hand held where it is, until no finger joint moves faster than ``HOLD_SPEED``, at most
        ``READ_WAIT`` s -- a slow hand (the Inspire's fingers take seconds to close) is read when it has stopped."""
        self._until_still(self.data, READ_WAIT)
        return self._reading(self.data)

    def _until_still(self, data, longest: float) -> None:
        waited = 0.0
        while waited < longest and np.max(np.abs(data.qvel[self._finger_dofs]), initial=0.0) > HOLD_SPEED:
            with mujoco_warnings():
                mujoco.mj_step(self.model, data, nstep=round(REST_CHECK / self.model.opt.timestep))
            waited += REST_CHECK

    def _reading(self, data) -> HandReading:
        return HandReading(data.qpos[self._finger_qpos].copy(), float(data.actuator_force[self._base_ctrl[2]]))

    def free_closure(self) -> HandReading:
        """:meth:`hand_reading` of the hand closed on nothing -- closed for ``FREE_CLOSURE_TIME`` s far above the
        table and on until its fingers are still (at most ``FREE_CLOSURE_WAIT`` s more), in a copy of the scene
        (computed once): where its joints stop, and the wrist's load to tare."""
        if self._free_closure is None:
            data = copy.copy(self.data)
            base = self.hand_base()
            base[2] = PARK_HEIGHT
            data.qpos[self._base_qpos], data.qvel[:] = base, 0.0
            data.ctrl[self._base_ctrl] = base
            actuators, _, closed = self._closing
            data.ctrl[actuators] = closed
            with mujoco_warnings():
                mujoco.mj_step(self.model, data, nstep=round(FREE_CLOSURE_TIME / self.model.opt.timestep))
            self._until_still(data, FREE_CLOSURE_WAIT)
            self._free_closure = self._reading(data)
        return self._free_closure

    def set_hand(self, x: float, y: float, z: float, yaw: float, closing: float = 0.0, *, tilt: float = 0.0,
                 roll: float = 0.0) -> None:
        """Teleport the hand (and its servo targets): hand-frame origin at world (x, y, z), yaw about camera z,
        tilt and roll as :func:`base_angles` gives them (0: palm facing down)."""
        target = self._base_target([x, y, z, yaw, tilt, roll])
        self.data.qpos[self._base_qpos] = target
        self.data.qvel[self._base_dofs] = 0.0
        self.command(target, closing)
        with mujoco_warnings():
            mujoco.mj_forward(self.model, self.data)

    def command(self, base_target, closing: float) -> None:
        """Servo targets for the hand base (x, y, z, yaw, and tilt, roll: 0 when left out) and the closing (the
        tendon force fraction, or a mounted hand model's synergy: 0 open, 1 closed)."""
        self.data.ctrl[self._base_ctrl] = self._base_target(base_target)
        actuators, open_, closed = self._closing
        self.data.ctrl[actuators] = open_ + closing * (closed - open_)
        self.closed = closing >= 1.0

    def _base_target(self, base_target) -> np.ndarray:
        """The base joints' values of (x, y, z, yaw[, tilt, roll]): tilt and roll 0 when left out.

        Raises SimulationError for a tilt or roll on a hand without a wrist (:attr:`HandDesign.wrist`)."""
        target = np.zeros(6)
        target[:len(base_target)] = base_target
        if len(self._base_qpos) == 4 and np.any(target[4:] != 0.0):
            raise SimulationError("the simulated hand has no wrist to tilt or roll: build the scene with "
                                  "HandDesign(wrist=True) to execute a side or tilted approach")
        return target[:len(self._base_qpos)]

    def step(self, duration: float | None = None) -> None:
        """Advance the simulation by ``duration`` s (one time step if None) at the current commands."""
        steps = 1 if duration is None else max(1, round(duration / self.model.opt.timestep))
        with mujoco_warnings():
            mujoco.mj_step(self.model, self.data, nstep=steps)

    def settle(self, at_least: float) -> None:
        """Step ``at_least`` s, then on in ``REST_CHECK`` s steps while the object or a neighbour moves faster than
        ``REST_SPEED`` (its origin's speed, or its turn rate times ``REST_RADIUS``), for at most ``MAX_SETTLE_TIME``
        s in all: the scene at rest."""
        self.step(at_least)
        waited = at_least
        while waited < MAX_SETTLE_TIME and self._fastest() > REST_SPEED:
            self.step(REST_CHECK)
            waited += REST_CHECK

    def _fastest(self) -> float:
        """The largest speed of the object's and the neighbours' free joints, m/s (a turn rate times ``REST_RADIUS``)."""
        bodies = self._bodies[self._present]
        if not len(bodies):
            return 0.0
        dofs = np.concatenate([self.model.jnt_dofadr[self.model.body_jntadr[b]] + np.arange(6) for b in bodies])
        speeds = self.data.qvel[dofs].reshape(-1, 2, 3)
        return float(max(np.linalg.norm(speeds[:, 0], axis=1).max(),
                         REST_RADIUS * np.linalg.norm(speeds[:, 1], axis=1).max()))

    @property
    def unstable(self) -> bool:
        """Whether MuJoCo found NaN, infinite or huge accelerations (and reset the state) at some step."""
        return self.data.warning[mujoco.mjtWarning.mjWARN_BADQACC].number > 0


def _descends(model, body: int, ancestor: int) -> bool:
    """Whether ``body`` lies strictly below ``ancestor`` in the model's tree."""
    while body != 0:
        body = model.body_parentid[body]
        if body == ancestor:
            return True
    return False


def base_angles(R_world_hand) -> tuple[float, float, float]:
    """(yaw, tilt, roll), rad: the hand base's hinges that turn the hand frame to ``R_world_hand`` (3, 3).

    The palm hangs below the base turned half a turn about x (:func:`~contourgrasp.sim.tendon_hand.base_xml`),
    and the hinges turn it by yaw about the world's -z, then tilt about the turned y, then roll about the
    turned -z: ``R_world_hand = Rz(-yaw) Ry(tilt) Rz(-roll) Rx(pi)``. A hand facing straight down has tilt
    0 and all its turn in yaw.
    """
    M = np.asarray(R_world_hand, dtype=float) @ np.diag([1.0, -1.0, -1.0])
    tilt = math.acos(float(np.clip(M[2, 2], -1.0, 1.0)))
    if math.sin(tilt) < 1e-9:
        return -math.atan2(M[1, 0], M[0, 0]), 0.0, 0.0
    alpha, gamma = math.atan2(M[1, 2], M[0, 2]), math.atan2(M[2, 1], -M[2, 0])
    return -alpha, tilt, -gamma


@contextlib.contextmanager
def mujoco_warnings():
    """Route MuJoCo's warnings away from its default handler, which appends them to ``MUJOCO_LOG.TXT``.

    Without a user handler MuJoCo writes that file into the working directory
    on any warning (an unstable simulation, a full contact buffer). Inside this
    block the warnings are dropped; MuJoCo still counts them in
    ``MjData.warning``, which :attr:`Scene.unstable` reads. A handler the caller
    installed is left in place.
    """
    previous = mujoco.get_mju_user_warning()
    if previous is not None:
        yield
        return
    mujoco.set_mju_user_warning(_ignore)
    try:
        yield
    finally:
        mujoco.set_mju_user_warning(None)


def _ignore(message: str) -> None:
    """The warning handler of :func:`mujoco_warnings`: MuJoCo's own counters keep the record."""


def build_scene(obj, *, seed: int, hand: Hand | str = "five-finger-linear", design: HandDesign = HandDesign(),
                timing: str = "thesis", camera: Camera = Camera(), workspace: Workspace = Workspace(),
                robot: bool = False) -> Scene:
    """A settled scene: the object at a seeded random position and yaw, the hand parked out of view.

    Parameters
    ----------
    obj : ObjectSpec or str
        An object, a name of :data:`~contourgrasp.sim.objects.THESIS_OBJECTS` or a mesh path.
    seed : int
        Chooses the placement.
    hand : Hand, str or MountedHand
        A preset name, hand TOML path or :class:`Hand` with ray fingers; or a hand model mounted
        by :func:`~contourgrasp.handmodels.mount.mount_model`, simulated as itself.
    design, timing
        See :func:`~contourgrasp.sim.tendon_hand.build_hand`.
    camera : Camera
    workspace : Workspace
    robot : bool
        A robot arm in view (:data:`~contourgrasp.sim.mjcf.ROBOT_ARM`).
    """
    obj = object_spec(obj)
    hand_model = simulated_hand(hand, design=design, timing=timing)
    rng = np.random.default_rng(np.random.SeedSequence([seed, 0]))
    placement = Placement(x=float(rng.uniform(-workspace.half_x, workspace.half_x)),
                          y=float(rng.uniform(-workspace.half_y, workspace.half_y)),
                          yaw=float(rng.uniform(0.0, 2 * np.pi)))
    with mujoco_warnings():
        model = compile_scene(scene_xml(obj, hand_model, placement, robot=robot), hand_model)
        data = mujoco.MjData(model)
    scene = Scene(model, data, obj, hand_model, camera, placement)
    scene.set_hand(0.0, 0.0, PARK_HEIGHT, 0.0)
    scene.settle(SETTLE_TIME)
    return scene


def simulated_hand(hand, *, design: HandDesign = HandDesign(), timing: str = "thesis"):
    """The hand a scene simulates: a mounted hand model (:class:`~contourgrasp.handmodels.mount.MountedHand`) as
    itself, else our tendon hand built from ``hand`` (a preset name, a hand TOML path or a :class:`Hand`)."""
    return hand if hasattr(hand, "mount") else build_hand(load_hand(hand), design=design, timing=timing)


def compile_scene(xml: str, hand) -> mujoco.MjModel:
    """The scene's model from its MJCF and :func:`simulated_hand`: a mounted hand model is attached to the parsed
    scene before compiling."""
    if not hasattr(hand, "mount"):
        return mujoco.MjModel.from_xml_string(xml)
    spec = mujoco.MjSpec.from_string(xml)
    hand.mount(spec)
    return spec.compile()
