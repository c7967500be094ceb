"""Scenes of several objects: clutter on the table, objects in a bin, a seeded tilted camera.

Kinds (:data:`SCENE_KINDS`)
    ``single``
        Today's scene, :func:`~contourgrasp.sim.scene.build_scene`: one object on the table.
    ``clutter``
        2-4 objects on the table: the target and 1-3 neighbours.
    ``bin``
        1-3 objects in a :class:`~contourgrasp.sim.mjcf.Bin` fixed on the table
        (walls 10 cm high, floor 40 x 30 cm inside, 5 mm walls, 4 mm floor): the
        target and 0-2 neighbours.

Placement (:func:`arrange`), all from the seed (stream 3 of the trial's seed:
0 places a single object, 1 is the depth noise, 2 the random baseline):

1. the camera's tilt, uniform in 0-25 deg (:data:`MAX_TILT`), leaning back
   along -y as :func:`~contourgrasp.sim.render.tilted_view` does, at the
   reference camera's distance from the table's centre;
2. the number of objects, uniform in the kind's range;
3. the target, at a uniform yaw and position: in the :class:`Workspace` (as a
   single object) on the table, anywhere its outline fits in the bin with
   :data:`WALL_GAP` to spare;
4. the neighbours, drawn from the pool (without repeats while it lasts), each
   at a uniform yaw, then along a uniform direction from the target's centre:
   moved out until its outline (the convex hull of its collision parts seen
   from above) clears every object placed, i.e. touches one, then a further
   gap uniform in 0-4 cm (:data:`GAP`). A spot that overlaps another object
   or leaves the bin is drawn again, up to :data:`PLACEMENT_TRIES` times; a
   neighbour without a spot is left out (rare: it takes a crowded bin).

Outlines that are disjoint from above cannot interpenetrate, so the objects
are then dropped from :data:`~contourgrasp.sim.mjcf.DROP_HEIGHT` and settle
for :data:`CLUTTER_SETTLE` s, touching where they were placed touching (a
tall object may topple onto its neighbour).

The target
    The bench's object is the target; the planner is told which object it is
    as a user who clicked on it would: :func:`target_pixel`, the pixel of its
    exact mask (:func:`~contourgrasp.sim.render.truth_labels`) deepest inside
    it, in the planner's picture. Placed in the workspace's middle, it is
    wholly in view.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..errors import SimulationError
from ..perception import deepest_pixel
from ..hand import Hand
from ..validation import choice
from .tendon_hand import HandDesign
from .objects import ObjectSpec, object_spec
from .render import tilted_view, truth_labels
from .mjcf import Bin, Placement, scene_xml
from .scene import PARK_HEIGHT, Camera, Scene, Workspace, compile_scene, mujoco, mujoco_warnings, simulated_hand

#: The scenes a trial can take place in.
SCENE_KINDS = ("single", "clutter", "bin")
#: Objects in a scene, target included (fewest, most), per kind.
OBJECT_COUNTS = {"clutter": (2, 4), "bin": (1, 3)}
#: Largest camera tilt from looking straight down, rad.
MAX_TILT = math.radians(25.0)
#: Gap between a neighbour and the object it is placed beside, m (smallest, largest).
GAP = (0.0, 0.04)
#: Smallest distance of an object's outline from the bin's walls when placed, m.
WALL_GAP = 0.01
#: Directions drawn for a neighbour before it is left out.
PLACEMENT_TRIES = 40
#: Settling time of a scene of several objects before the picture, s.
CLUTTER_SETTLE = 0.6
#: Step (m) in which a neighbour is moved out along its direction, before bisection to the touching distance.
PLACEMENT_STEP = 0.01


@dataclass(frozen=True)
class Arrangement:
    """Where everything goes before it settles.

    Attributes
    ----------
    target : Placement
    neighbours : tuple of (ObjectSpec, Placement)
    tilt : float
        Of the planner's camera from looking straight down, rad.
    bin : Bin or None
    """

    target: Placement
    neighbours: tuple[tuple[ObjectSpec, Placement], ...]
    tilt: float
    bin: Bin | None


def arrange(kind: str, obj: ObjectSpec, pool, *, seed: int, workspace: Workspace = Workspace(),
            bin: Bin = Bin()) -> Arrangement:
    """The seeded placement of a ``clutter`` or ``bin`` scene (module docstring).

    Parameters
    ----------
    kind : {"clutter", "bin"}
    obj : ObjectSpec
        The target.
    pool : sequence of ObjectSpec
        The neighbours are drawn from it (the same object may be drawn again when it is short).
    seed : int
    workspace : Workspace
        Where the target's centre may be on the table (clutter).
    bin : Bin
        The bin of a ``bin`` scene.
    """
    choice("scene kind", kind, tuple(OBJECT_COUNTS), error=SimulationError)
    pool = tuple(pool)
    if not pool:
        raise SimulationError("a scene of several objects needs a pool of neighbours")
    rng = np.random.default_rng(np.random.SeedSequence([seed, 3]))
    tilt = float(rng.uniform(0.0, MAX_TILT))
    low, high = OBJECT_COUNTS[kind]
    count = int(rng.integers(low, high + 1))
    box = bin if kind == "bin" else None
    yaw = float(rng.uniform(0.0, 2 * np.pi))
    hull = _turned(plan_hull(obj), yaw)
    if box is None:
        x, y = rng.uniform(-workspace.half_x, workspace.half_x), rng.uniform(-workspace.half_y, workspace.half_y)
    else:
        x, y = (rng.uniform(*_inside(box, hull[:, k], box.inner[k] / 2)) for k in (0, 1))
    target = Placement(float(x), float(y), yaw)
    placed = [hull + [x, y]]
    chosen = rng.choice(len(pool), size=count - 1, replace=len(pool) < count - 1)
    neighbours = []
    for index in chosen:
        spot = _beside(rng, plan_hull(pool[index]), placed, np.array([x, y]), box)
        if spot is not None:
            placed.append(spot[1])
            neighbours.append((pool[index], spot[0]))
    return Arrangement(target, tuple(neighbours), tilt, box)


def _inside(box: Bin, extent: np.ndarray, half: float) -> tuple[float, float]:
    """The range of centres along one axis keeping an outline of ``extent`` (its points' coordinates) in the bin."""
    low, high = -half + WALL_GAP - extent.min(), half - WALL_GAP - extent.max()
    return (low, high) if low < high else (0.0, 0.0)


def _beside(rng, local_hull, placed, centre, box):
    """(Placement, outline) of a neighbour beside the objects ``placed``, or None when no spot was found."""
    yaw = float(rng.uniform(0.0, 2 * np.pi))
    hull = _turned(local_hull, yaw)
    for _ in range(PLACEMENT_TRIES):
        theta, gap = rng.uniform(0.0, 2 * np.pi), rng.uniform(*GAP)
        direction = np.array([math.cos(theta), math.sin(theta)])
        at = centre + (_touching(hull, placed, centre, direction) + gap) * direction
        outline = hull + at
        if any(overlap(outline, other) for other in placed):
            continue
        if box is not None and not np.all(np.abs(outline) <= np.array(box.inner) / 2 - WALL_GAP):
            continue
        return Placement(float(at[0]), float(at[1]), yaw), outline
    return None


def _touching(hull, placed, centre, direction, reach: float = 1.0) -> float:
    """The distance along ``direction`` from ``centre`` at which ``hull`` first clears every outline of ``placed``."""
    def clear(s):
        return not any(overlap(hull + centre + s * direction, other) for other in placed)

    outside = 0.0
    while not clear(outside) and outside < reach:
        outside += PLACEMENT_STEP
    inside = max(0.0, outside - PLACEMENT_STEP)
    for _ in range(12):  # to 2.4 um
        middle = (inside + outside) / 2
        inside, outside = (inside, middle) if clear(middle) else (middle, outside)
    return outside


def plan_hull(obj: ObjectSpec) -> np.ndarray:
    """(m, 2) float: the convex hull of the object's collision parts seen from above, object frame, counter-clockwise."""
    from scipy.spatial import ConvexHull

    points = obj.points()[:, :2]
    return points[ConvexHull(points).vertices]


def _turned(points: np.ndarray, yaw: float) -> np.ndarray:
    c, s = math.cos(yaw), math.sin(yaw)
    return points @ np.array([[c, s], [-s, c]])


def overlap(a: np.ndarray, b: np.ndarray) -> bool:
    """Whether two convex polygons (m, 2) and (n, 2) overlap (separating axis theorem; touching is not overlap)."""
    for polygon in (a, b):
        edges = np.roll(polygon, -1, axis=0) - polygon
        normals = np.stack([-edges[:, 1], edges[:, 0]], axis=1)
        pa, pb = a @ normals.T, b @ normals.T
        if np.any(pa.max(axis=0) <= pb.min(axis=0)) or np.any(pb.max(axis=0) <= pa.min(axis=0)):
            return False
    return True


def build_clutter(obj, pool, *, kind: str, seed: int, hand: Hand | str = "five-finger-linear",
                  design: HandDesign = HandDesign(), timing: str = "thesis", camera: Camera = Camera(),
                  workspace: Workspace = Workspace(), settle: float = CLUTTER_SETTLE, robot: bool = False) -> Scene:
    """A settled ``clutter`` or ``bin`` scene: ``obj`` the target, neighbours from ``pool``, a seeded tilted camera.

    Parameters
    ----------
    obj : ObjectSpec or str
    pool : sequence of ObjectSpec or str
    kind : {"clutter", "bin"}
    seed : int
        Chooses everything (:func:`arrange`); same seed, same scene.
    hand, design, timing, camera, workspace
        As :func:`~contourgrasp.sim.scene.build_scene` (a mounted hand model too); ``camera`` is the top-down
        reference the grasp is executed in, and its height the tilted camera's distance.
    settle : float
        Seconds the objects settle before anything looks at them, and longer while they still move
        (:meth:`~contourgrasp.sim.scene.Scene.settle`).
    robot : bool
        A robot arm in view (:data:`~contourgrasp.sim.mjcf.ROBOT_ARM`).
    """
    obj = object_spec(obj)
    layout = arrange(kind, obj, [object_spec(o) for o in pool], seed=seed, workspace=workspace)
    hand_model = simulated_hand(hand, design=design, timing=timing)
    with mujoco_warnings():
        model = compile_scene(scene_xml(obj, hand_model, layout.target, neighbours=layout.neighbours, bin=layout.bin,
                                        robot=robot), hand_model)
        data = mujoco.MjData(model)
    scene = Scene(model, data, obj, hand_model, camera, layout.target, kind=kind,
                  neighbours=tuple(o for o, _ in layout.neighbours), bin=layout.bin,
                  view=tilted_view(layout.tilt, camera.height))
    scene.set_hand(0.0, 0.0, PARK_HEIGHT, 0.0)
    scene.settle(settle)
    return scene


def target_pixel(scene: Scene) -> tuple[int, int]:
    """The pixel (u, v) of the planner's picture a user would click on the target: deepest inside its exact mask.

    The pixel farthest from the mask's edge (a distance transform's maximum, the
    first in image order on ties); the projection of the target's centre of
    mass when nothing of it is in view.
    """
    mask = truth_labels(scene) == scene.target + 1
    if not mask.any():
        eye, R_world_camera = scene.view
        u, v = scene.camera.intrinsics.project(((scene.object_com() - eye) @ R_world_camera)[None])[0]
        return int(round(u)), int(round(v))
    return deepest_pixel(mask)


