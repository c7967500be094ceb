"""RGB-D images of a scene by ray casting (no OpenGL needed): the camera's picture, views for figures, exact masks.

One ray per pixel centre leaves the optical centre (``mujoco.mj_multiRay``);
the hit distance along a ray whose camera-frame direction has unit z is the
depth along the optical axis directly. Colour is the hit geom's rgba, shaded by
the cosine between its surface normal and the ray (a light at the camera).

The depth is that of a sensor (:class:`Sensor`, by preset name in :data:`SENSORS`), each a model of
how a kind of depth camera fails, its statistics set from the shared real frames of that kind
(``benchmarks/sensor_statistics.py``; docs/bench.md, "Sensors"): Gaussian noise growing with the
square of the depth; readings missing along depth discontinuities; the shadow of a projector or a
second camera beside raised edges (the points it cannot see read nothing); dropouts on dark
surfaces; speckle holes; flying pixels between an edge's two sides; and nothing outside the
sensor's range. ``ideal`` is exact depth.

:func:`object_truth` gives the exact segmentation of a picture, for judging
perception against it: the pixels that see the object, and the pixels that see
the table where the object stands (its footprint); :func:`truth_labels` which
object of a scene of several every pixel sees (the geom its ray meets first). :func:`tilted_view` places
a camera that is not top-down, like the PrimeSense of the shared real frames.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import SimulationError
from ..perception import Intrinsics
from .mjcf import object_bodies
from .scene import R_WORLD_CAMERA, Scene, mujoco

#: Geom groups the camera sees: table and objects (0) and objects' drawn meshes (1), not the hand (2)
#: nor collision-only pieces (3).
SCENE_GROUPS = (0, 1)
#: A small camera for :func:`render_view` (320 x 240, ~56 x 43 degrees).
VIEW_INTRINSICS = Intrinsics(fx=300.0, fy=300.0, cx=159.5, cy=119.5, width=320, height=240)
#: Farthest hit :func:`render_view` looks for, m.
VIEW_RANGE = 5.0
#: The label of the bin in :func:`truth_labels`.
BIN_LABEL = -1
#: :func:`object_truth` looks for the object this far (m) beyond its collision parts' extent.
TRUTH_MARGIN = 0.05


@dataclass(frozen=True)
class Sensor:
    """How a depth camera fails: the model :func:`render` applies to the exact depth.

    Attributes
    ----------
    name : str
    source : str
        What its statistics come from, one line.
    sigma : float
        Standard deviation of the depth noise at 1 m, m; it scales with depth squared.
    edge_jump : float
        A pixel whose 3 x 3 neighbourhood spans more depth than this (m) lies on an edge.
    edge_dropout : float
        Probability that an edge pixel reads nothing.
    shadow_baseline : float
        A projector (structured light) or the second camera (active stereo) this far (m) along the camera's
        +x axis: a point it cannot see reads nothing, a band beside every raised edge. 0: none.
    dark_dropout : float
        Probability that a pixel whose colour is darker than ``DARK`` reads nothing (light absorbed, or a
        shiny surface's reflection missing the sensor).
    speckle : float
        Share of the image in holes of missing readings scattered at random, ``SPECKLE_PX`` across.
    flying : float
        Probability that an edge pixel reads a depth between its neighbourhood's nearest and farthest
        (a time-of-flight pixel mixing the two sides of an edge).
    """

    name: str
    source: str = ""
    sigma: float = 0.0
    edge_jump: float = 0.01
    edge_dropout: float = 0.0
    shadow_baseline: float = 0.0
    dark_dropout: float = 0.0
    speckle: float = 0.0
    flying: float = 0.0

    @property
    def ideal(self) -> bool:
        """Whether the depth is left exact."""
        return not any((self.sigma, self.edge_dropout, self.shadow_baseline, self.dark_dropout, self.speckle,
                        self.flying))


#: A pixel darker than this (mean of its rgb, 0-255) is dark (:attr:`Sensor.dark_dropout`).
DARK = 50
#: Speckle holes are about this wide, px.
SPECKLE_PX = 3
#: A point is in the projector's shadow when something lies more than this (m) before it on the projector's ray.
SHADOW_SLACK = 0.002

#: The sensor presets, by name. Statistics from ``benchmarks/sensor_statistics.py`` on the shared real frames;
#: the time-of-flight preset, whose sensor the shared frames lack, from its published behaviour.
SENSORS: dict[str, Sensor] = {s.name: s for s in (
    Sensor("ideal", "exact depth"),
    Sensor("basic", "Gaussian noise and random edge dropouts: the bench's camera before the presets",
           sigma=0.004, edge_dropout=0.5),
    Sensor("structured-light", "SR300 / PrimeSense: the projector 5 cm beside the camera casts a shadow beside "
           "raised edges, dark surfaces drop out; noise, edge dropouts and speckle of the SR300 bin frame",
           sigma=0.006, edge_dropout=0.9, shadow_baseline=0.05, dark_dropout=0.3, speckle=0.01),
    Sensor("stereo", "RealSense D4xx: the second camera 5 cm away leaves an invalid band on one side of objects, "
           "noise grows with depth squared; the three RealSense frames' statistics",
           sigma=0.0025, edge_dropout=0.2, shadow_baseline=0.05, speckle=0.0005),
    Sensor("tof", "Kinect v2 time of flight: flying pixels and dropouts at edges, speckle holes (its published "
           "behaviour: no shared frame is of one)", sigma=0.002, edge_dropout=0.2, flying=0.5, speckle=0.005,
           dark_dropout=0.1),
    Sensor("industrial", "PhoXi / Ensenso industrial structured light: low noise, the projector's shadow; the "
           "PhoXi bin frame's edge dropouts", sigma=0.001, edge_dropout=0.9, shadow_baseline=0.1),
)}
#: The bench's sensor by default.
DEFAULT_SENSOR = "structured-light"


def sensor_named(sensor) -> Sensor:
    """``sensor`` itself, a preset of :data:`SENSORS` by name, or for a bool the ``basic`` preset (True) or ``ideal``."""
    if isinstance(sensor, Sensor):
        return sensor
    if isinstance(sensor, (bool, np.bool_)):
        return SENSORS["basic" if sensor else "ideal"]
    if isinstance(sensor, str) and sensor in SENSORS:
        return SENSORS[sensor]
    raise SimulationError(f"unknown sensor {sensor!r}: choose one of {', '.join(SENSORS)}")


def render(scene: Scene, *, sensor: Sensor | str | bool = False, seed: int = 0,
           show_hand: bool = False, view=None) -> tuple[np.ndarray, np.ndarray]:
    """Render the scene from its camera (or from ``view``, with the camera's intrinsics).

    Parameters
    ----------
    scene : Scene
    sensor : Sensor, str or bool
        A :class:`Sensor` or the name of one of :data:`SENSORS`; ``True`` is ``"basic"``, ``False`` ``"ideal"``.
    seed : int
        Seeds the sensor's noise.
    show_hand : bool
        Draw the hand too (for figures; the planner's picture is taken without it).
    view : (eye, R_world_camera), optional
        The optical centre (3,) and the optical frame's rotation (3, 3), world
        frame (e.g. from :func:`tilted_view`); default: the scene's :attr:`~Scene.view`
        if it has one (a tilted camera of :mod:`~contourgrasp.sim.clutter`), else its top-down camera.

    Returns
    -------
    rgb : (H, W, 3) uint8
    depth : (H, W) float32
        Meters along the optical axis; 0 where nothing is hit or out of range.
    """
    depth_min, depth_max = scene.camera.depth_range
    eye, R_world_camera = _view(scene, view)
    sensor = sensor_named(sensor)
    rgb, depth, _ = _cast(scene, eye, R_world_camera, scene.camera.intrinsics, show_hand, 2 * depth_max)
    if not sensor.ideal:
        shadow = _shadowed(scene, eye, R_world_camera, depth, sensor.shadow_baseline) if sensor.shadow_baseline else None
        depth = _sensed(depth, rgb, shadow, sensor, np.random.default_rng([seed, 1]))
    depth = np.where((depth >= depth_min) & (depth <= depth_max), depth, 0.0)
    return rgb, depth.astype(np.float32)


def render_view(scene: Scene, eye, target, intrinsics: Intrinsics = VIEW_INTRINSICS, *,
                show_hand: bool = True) -> tuple[np.ndarray, np.ndarray]:
    """Render the scene from any viewpoint, for figures (e.g. the hand holding the object, seen from the side).

    Parameters
    ----------
    scene : Scene
    eye, target : (3,) float
        The pinhole's position and the point it looks at, world frame; image up is world z.
    intrinsics : Intrinsics
    show_hand : bool

    Returns
    -------
    rgb : (H, W, 3) uint8
        Black where the ray hits nothing.
    hit : (H, W) bool
    """
    eye, target = np.asarray(eye, dtype=float), np.asarray(target, dtype=float)
    forward = (target - eye) / np.linalg.norm(target - eye)
    right = np.cross(forward, [0.0, 0.0, 1.0])
    right /= np.linalg.norm(right)
    rotation = np.column_stack([right, np.cross(forward, right), forward])  # optical frame: x right, y down
    rgb, depth, _ = _cast(scene, eye, rotation, intrinsics, show_hand, VIEW_RANGE)
    return rgb, depth > 0


def tilted_view(tilt: float, distance: float, target=(0.0, 0.0, 0.0)) -> tuple[np.ndarray, np.ndarray]:
    """A camera ``distance`` m from ``target`` looking at it, tilted ``tilt`` rad from looking straight down.

    The camera leans back along world -y, so the image's top sees farther
    than its bottom and the table's normal has a negative y in the optical
    frame, as in the shared PrimeSense frames (12.7 deg at about 0.7 m).

    Returns
    -------
    eye : (3,) float
        Optical centre, world frame.
    R_world_camera : (3, 3) float
        Optical frame (x right, y down, z forward) in the world frame.
    """
    c, s = np.cos(tilt), np.sin(tilt)
    R_world_camera = np.array([[1.0, 0.0, 0.0], [0.0, -c, s], [0.0, -s, -c]])
    return np.asarray(target, dtype=float) - distance * R_world_camera[:, 2], R_world_camera


def object_truth(scene: Scene, view=None) -> tuple[np.ndarray, np.ndarray]:
    """The exact segmentation of :func:`render`'s picture (same ``view``), hand never shown.

    Returns
    -------
    seen : (H, W) bool
        Pixels whose ray meets the object first.
    footprint : (H, W) bool
        Pixels whose ray meets the table top (z = 0) at a point under the
        object: a vertical ray down through that point meets the object
        before the table. Seen from straight above this is the object's
        outline; from a tilted camera it is where the object stands, which
        :func:`contourgrasp.perception.object_footprint` estimates.
    """
    intr = scene.camera.intrinsics
    eye, R_world_camera = _view(scene, view)
    _, _, geom = _cast(scene, eye, R_world_camera, intr, False, VIEW_RANGE)
    obj = scene.object_body
    seen = (geom >= 0) & (scene.model.geom_bodyid[np.maximum(geom, 0)] == obj)
    rays = pixel_rays(intr).reshape(-1, 3) @ R_world_camera.T
    with np.errstate(divide="ignore", invalid="ignore"):
        on_table = eye - (eye[2] / rays[:, 2])[:, None] * rays
    # Only table points within the object's plan extent (with a margin for drawn meshes) need a vertical ray.
    points = scene.object_points()
    lo, hi = points[:, :2].min(axis=0) - TRUTH_MARGIN, points[:, :2].max(axis=0) + TRUTH_MARGIN
    under = np.flatnonzero((rays[:, 2] < 0) & np.all((on_table[:, :2] >= lo) & (on_table[:, :2] <= hi), axis=1))
    footprint = np.zeros(len(rays), dtype=bool)
    start = np.array([0.0, 0.0, points[:, 2].max() + TRUTH_MARGIN])
    down, hit, groups = np.array([0.0, 0.0, -1.0]), np.zeros(1, np.int32), _groups(False)
    for i in under:
        start[:2] = on_table[i, :2]
        mujoco.mj_ray(scene.model, scene.data, start, down, groups, 1, -1, hit)
        footprint[i] = hit[0] >= 0 and scene.model.geom_bodyid[hit[0]] == obj
    return seen, footprint.reshape(seen.shape)


def truth_labels(scene: Scene, view=None) -> np.ndarray:
    """(H, W) int: which object each pixel of :func:`render`'s picture (same ``view``) sees, hand never shown.

    0 the table, the bin's floor (or nothing), ``k + 1`` the object ``k`` of :attr:`Scene.objects
    <contourgrasp.sim.scene.Scene.objects>` (``1`` the target as built, body ``object``; ``k + 2`` the
    neighbour ``k``), :data:`BIN_LABEL` the bin's walls. Exact: the geom each pixel's ray meets first.
    """
    eye, R_world_camera = _view(scene, view)
    _, _, geom = _cast(scene, eye, R_world_camera, scene.camera.intrinsics, False, VIEW_RANGE)
    model = scene.model
    body_label = np.zeros(model.nbody, dtype=int)
    for k, name in enumerate(object_bodies(len(scene.objects))):
        body_label[model.body(name).id] = k + 1
    geom_label = body_label[model.geom_bodyid]
    if scene.bin is not None:
        geom_label[[model.geom(name).id for name, _, _ in scene.bin.geoms()[1:]]] = BIN_LABEL
    return np.where(geom >= 0, geom_label[np.maximum(geom, 0)], 0)


def pixel_rays(intrinsics: Intrinsics) -> np.ndarray:
    """(height, width, 3) float: per pixel centre, the ray direction with unit z (camera frame)."""
    u, v = np.meshgrid(np.arange(intrinsics.width, dtype=float), np.arange(intrinsics.height, dtype=float))
    return intrinsics.rays(np.stack([u, v], axis=-1)).reshape(intrinsics.height, intrinsics.width, 3)


def _view(scene: Scene, view):
    view = scene.view if view is None else view
    if view is None:
        return scene.camera.position, R_WORLD_CAMERA
    eye, R_world_camera = view
    return np.asarray(eye, dtype=float), np.asarray(R_world_camera, dtype=float)


def _groups(show_hand: bool) -> np.ndarray:
    groups = np.zeros(6, dtype=np.uint8)
    groups[list(SCENE_GROUPS) + ([2] if show_hand else [])] = 1
    return groups


def _cast(scene: Scene, eye, R_world_camera, intr: Intrinsics, show_hand: bool, max_distance: float):
    """Colour (H, W, 3) uint8, depth along the optical axis (H, W) float (0: no hit) and geom hit (H, W) int (-1: none)."""
    rays_world = np.ascontiguousarray(pixel_rays(intr).reshape(-1, 3) @ np.asarray(R_world_camera).T)
    n = len(rays_world)
    geom = np.empty(n, dtype=np.int32)
    dist = np.empty(n, dtype=np.float64)
    normal = np.empty((n, 3), dtype=np.float64)
    mujoco.mj_multiRay(scene.model, scene.data, np.asarray(eye, dtype=float), rays_world.ravel(), _groups(show_hand),
                       1, -1, geom, dist, normal.ravel(), n, max_distance)
    hit = geom >= 0
    rgb = _shade(scene.model.geom_rgba[geom, :3], normal, rays_world, hit)
    shape = (intr.height, intr.width)
    return rgb.reshape(*shape, 3), np.where(hit, dist, 0.0).reshape(shape), geom.reshape(shape)


def _shade(colour: np.ndarray, normal: np.ndarray, rays: np.ndarray, hit: np.ndarray) -> np.ndarray:
    cosine = np.abs(np.einsum("ij,ij->i", normal, rays)) / np.linalg.norm(rays, axis=1)
    lit = colour * (0.35 + 0.65 * cosine)[:, None]
    return np.where(hit[:, None], np.round(255 * np.clip(lit, 0, 1)), 0).astype(np.uint8)


def _shadowed(scene: Scene, eye, R_world_camera, depth, baseline: float) -> np.ndarray:
    """(H, W) bool: the pixels whose point a projector ``baseline`` m along the camera's +x cannot see."""
    intr = scene.camera.intrinsics
    points = pixel_rays(intr) * depth[..., None]
    hit = depth > 0
    world = points[hit] @ np.asarray(R_world_camera).T + eye
    projector = np.asarray(eye, dtype=float) + baseline * np.asarray(R_world_camera)[:, 0]
    towards = np.ascontiguousarray(world - projector)
    n = len(towards)
    geom, dist, normal = np.empty(n, dtype=np.int32), np.empty(n, dtype=np.float64), np.empty(3 * n)
    mujoco.mj_multiRay(scene.model, scene.data, projector, towards.ravel(), _groups(False), 1, -1, geom, dist,
                       normal, n, 2.0)
    out = np.zeros(depth.shape, dtype=bool)
    out[hit] = (geom >= 0) & (dist < 1.0 - SHADOW_SLACK / np.linalg.norm(towards, axis=1))
    return out


def _sensed(depth, rgb, shadow, sensor: Sensor, rng: np.random.Generator) -> np.ndarray:
    """The exact ``depth`` as ``sensor`` reads it (:class:`Sensor`): 0 where it reads nothing.

    The noise and the edge dropouts are drawn first and in that order, so that ``basic`` reads as the
    bench's camera did before the presets, seed for seed."""
    from scipy.ndimage import maximum_filter, minimum_filter

    edge = maximum_filter(depth, size=3) - minimum_filter(depth, size=3) > sensor.edge_jump
    out = depth + rng.normal(0.0, 1.0, depth.shape) * sensor.sigma * depth**2
    dropped = (edge & (rng.random(depth.shape) < sensor.edge_dropout)) | (depth == 0)
    if sensor.flying:
        near = minimum_filter(np.where(depth > 0, depth, np.inf), size=3)
        far = maximum_filter(depth, size=3)
        flying = edge & np.isfinite(near) & (rng.random(depth.shape) < sensor.flying)
        mix = rng.random(depth.shape)
        out[flying] = near[flying] + mix[flying] * (far - near)[flying]
    if shadow is not None:
        dropped |= shadow
    if sensor.dark_dropout:
        dropped |= (rgb.mean(axis=2) < DARK) & (rng.random(depth.shape) < sensor.dark_dropout)
    if sensor.speckle:
        seeds = rng.random(depth.shape) < sensor.speckle / SPECKLE_PX**2
        dropped |= maximum_filter(seeds, size=SPECKLE_PX)
    return np.where(dropped, 0.0, out)
