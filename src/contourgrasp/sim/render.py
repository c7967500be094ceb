"""RGB-D images of a scene by ray casting (no OpenGL needed).

One ray per pixel centre leaves the optical centre (``mujoco.mj_multiRay``);
the hit distance along a ray whose camera-frame direction has unit z is the
depth along the optical axis directly. Colour is the hit geom's rgba, shaded by
the cosine between its surface normal and the ray (a light at the camera).

Depth noise (:class:`DepthNoise`) mimics a structured-light sensor such as the
SR300: Gaussian noise growing with the square of the depth (~1.7 mm at
0.65 m), readings missing at random along depth discontinuities (the projector
and the camera do not see the same side of an edge), and nothing outside the
sensor's range.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .scene import R_WORLD_CAMERA, Scene, mujoco

#: Geom groups the camera sees: table and objects (0) and objects' drawn meshes (1), not the hand (2)
#: nor collision-only pieces (3).
SCENE_GROUPS = (0, 1)


@dataclass(frozen=True)
class DepthNoise:
    """Sensor noise model.

    Attributes
    ----------
    sigma : float
        Standard deviation of the depth noise at 1 m, m; it scales with depth squared.
    edge_jump : float
        A pixel whose 3 x 3 neighbourhood spans more depth than this (m) lies on an edge.
    edge_dropout : float
        Probability that an edge pixel reads nothing.
    """

    sigma: float = 0.004
    edge_jump: float = 0.01
    edge_dropout: float = 0.5


def render(scene: Scene, *, noise: DepthNoise | bool = False, seed: int = 0,
           show_hand: bool = False) -> tuple[np.ndarray, np.ndarray]:
    """Render the scene from its camera.

    Parameters
    ----------
    scene : Scene
    noise : DepthNoise or bool
        ``True`` for the default :class:`DepthNoise`; ``False`` for exact depth.
    seed : int
        Seeds the noise.
    show_hand : bool
        Draw the hand too (for figures; the planner's picture is taken without it).

    Returns
    -------
    rgb : (H, W, 3) uint8
    depth : (H, W) float32
        Meters along the optical axis; 0 where nothing is hit or out of range.
    """
    intr = scene.camera.intrinsics
    rays_camera = intr.rays().reshape(-1, 3)
    rays_world = np.ascontiguousarray(rays_camera @ R_WORLD_CAMERA.T)
    n = len(rays_world)
    geom = np.empty(n, dtype=np.int32)
    dist = np.empty(n, dtype=np.float64)
    normal = np.empty((n, 3), dtype=np.float64)
    groups = np.zeros(6, dtype=np.uint8)
    groups[list(SCENE_GROUPS) + ([2] if show_hand else [])] = 1
    mujoco.mj_multiRay(scene.model, scene.data, scene.camera.position, rays_world.ravel(), groups, 1, -1,
                       geom, dist, normal.ravel(), n, 2 * intr.depth_max)
    hit = geom >= 0
    depth = np.where(hit, dist, 0.0)
    rgb = _shade(scene.model.geom_rgba[geom, :3], normal, rays_world, hit)
    shape = (intr.height, intr.width)
    depth = depth.reshape(shape)
    if noise:
        depth = _noisy(depth, DepthNoise() if noise is True else noise, np.random.default_rng([seed, 1]))
    depth = np.where((depth >= intr.depth_min) & (depth <= intr.depth_max), depth, 0.0)
    return rgb.reshape(*shape, 3), depth.astype(np.float32)


def _shade(colour: np.ndarray, normal: np.ndarray, rays: np.ndarray, hit: np.ndarray) -> np.ndarray:
    cosine = np.abs(np.einsum("ij,ij->i", normal, rays)) / np.linalg.norm(rays, axis=1)
    lit = colour * (0.35 + 0.65 * cosine)[:, None]
    return np.where(hit[:, None], np.round(255 * np.clip(lit, 0, 1)), 0).astype(np.uint8)


def _noisy(depth: np.ndarray, noise: DepthNoise, rng: np.random.Generator) -> np.ndarray:
    from scipy.ndimage import maximum_filter, minimum_filter

    noisy = depth + rng.normal(0.0, 1.0, depth.shape) * noise.sigma * depth**2
    edge = maximum_filter(depth, size=3) - minimum_filter(depth, size=3) > noise.edge_jump
    dropped = edge & (rng.random(depth.shape) < noise.edge_dropout)
    return np.where(dropped | (depth == 0), 0.0, noisy)
