"""The objects of the grasping experiments (thesis Fig. 4.4, Table 4.4) and mesh objects.

An object is a rigid body described in its own frame: z up, resting on the table
plane z = 0 when placed with identity orientation (the scene only adds a yaw and
a position on the table). It is made of

* ``collision`` parts, every one convex, because MuJoCo collides a mesh by its
  convex hull: non-convex shapes are split into convex pieces (procedurally for
  the stones, by CoACD for arbitrary meshes, cached on disk);
* ``visual`` parts, what the camera sees; empty means "the collision parts".

Masses and frictions
--------------------
Friction is given per object against the two things it touches: the glove the
thesis put on the qbHand (section 4.1.2) and the table. The scene uses them in
explicit contact pairs, so a value never leaks into the other pair (MuJoCo's
default would take the larger of two geoms' frictions). No measured values exist
for the thesis's objects; these are ordinary handbook ranges for dry contacts,
taken at the low end where the thesis reports slipping.

============  ==========================  =====  =======  =======  ============================================
object        size (m)                    mass   glove    table    reasoning
============  ==========================  =====  =======  =======  ============================================
can           0.066 dia x 0.120           0.35   0.60     0.30     full 330 ml soda can; the example contour's
                                                                   size; rubber-coated glove on painted
                                                                   aluminium ~0.5-0.7, aluminium on a laminate
                                                                   table ~0.3
case          0.160 x 0.060 x 0.040       0.10   0.65     0.40     hard glasses case (~80 g) with a light pair
              rounded (r 0.02 / 0.01)                              inside; fabric/leatherette cover grips a
                                                                   glove a bit better than metal
bottle        0.065 dia x 0.205           0.52   0.50     0.30     0.5 l of water plus ~20 g of PET; smooth PET
              (body, shoulder, neck, cap)                          is slippery (0.4-0.6 against rubber)
stone1        0.121 x 0.088 x 0.042       0.60   0.70     0.50     the thesis's "heaviest and largest" object;
                                                                   density ~2.7 t/m^3 (granite); rough stone
                                                                   against rubber 0.6-0.8, against wood ~0.5
stone2        0.082 x 0.070 x 0.034       0.20   0.70     0.50     "significantly lighter and smaller", same
                                                                   material as stone 1
mesh files    as given (times ``scale``)  0.20   0.60     0.40     defaults for an unknown household object;
                                                                   pass the real values when known
============  ==========================  =====  =======  =======  ============================================

The stones follow the outlines of the example contours ``stone1`` and
``stone2`` (``tools/make_example_contours.py``), given a pebble-like thickness
profile; stone 1 keeps its hollow flank, so it is non-convex and is split into
convex wedges around its centre.
"""

from __future__ import annotations

import hashlib
import os
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..errors import SimulationError
from ..tolerances import MESH_CONVEX, MESH_MAX_EXTENT, MESH_MAX_FACES
from ..validation import choice, finite_array, positive

#: CoACD settings (fast rather than tight: a grasp needs the outline, not every dent).
COACD_SETTINGS = {"threshold": 0.05, "preprocess_resolution": 30, "mcts_iterations": 60, "mcts_max_depth": 2,
                  "max_convex_hull": 16, "seed": 0}

#: Entries of the points x hull-facets matrix :func:`hull_depth` holds at once (8 bytes each), and the nearest
#: facets whose planes bound a point's depth before it is computed exactly.
HULL_CHUNK, HULL_NEAR = 2**22, 8

_PRIMITIVES = ("box", "cylinder", "sphere", "ellipsoid", "capsule")


@dataclass(frozen=True, eq=False)
class Part:
    """One geom of an object, in the object frame.

    Attributes
    ----------
    kind : str
        A MuJoCo primitive (``box``, ``cylinder``, ``sphere``, ``ellipsoid``, ``capsule``) or ``mesh``.
    size : tuple of float
        MuJoCo ``size`` of a primitive (half extents, radius, half length); empty for a mesh.
    pos : (3,) float
    quat : (4,) float
        Orientation (w, x, y, z).
    vertices : (v, 3) float or None
        A mesh's vertices in the part frame.
    faces : (f, 3) int or None
        A mesh's triangles; None for a convex collision mesh (MuJoCo takes the hull).
    """

    kind: str
    size: tuple[float, ...] = ()
    pos: tuple[float, float, float] = (0.0, 0.0, 0.0)
    quat: tuple[float, float, float, float] = (1.0, 0.0, 0.0, 0.0)
    vertices: np.ndarray | None = None
    faces: np.ndarray | None = None

    def __post_init__(self):
        choice("part kind", self.kind, (*_PRIMITIVES, "mesh"), error=SimulationError)
        if (self.kind == "mesh") != (self.vertices is not None):
            raise SimulationError("a mesh part needs vertices, a primitive none")

    def surface_points(self) -> np.ndarray:
        """(p, 3) float: points on (or spanning) the part's surface, object frame; for extents and resting height."""
        import trimesh

        if self.kind == "mesh":
            local = np.asarray(self.vertices, dtype=float)
        else:
            local = _primitive_mesh(self.kind, self.size, trimesh).vertices
        return local @ _quat_matrix(self.quat).T + np.asarray(self.pos)


@dataclass(frozen=True, eq=False)
class ObjectSpec:
    """A graspable object: geometry, mass and frictions (see the module's table).

    Attributes
    ----------
    name : str
    collision : tuple of Part
        Convex parts that collide.
    visual : tuple of Part
        Parts the camera sees; empty: the collision parts are drawn.
    mass : float
        kg, spread over the collision parts in proportion to their volume.
    friction_hand, friction_table : float
        Sliding friction against the glove and against the table.
    rgba : (4,) float
    """

    name: str
    collision: tuple[Part, ...]
    mass: float
    friction_hand: float
    friction_table: float
    rgba: tuple[float, float, float, float] = (0.6, 0.6, 0.6, 1.0)
    visual: tuple[Part, ...] = field(default=())

    def __post_init__(self):
        if not self.collision:
            raise SimulationError(f"object {self.name!r} has no collision part")
        positive(f"object {self.name!r}: mass", self.mass, error=SimulationError)

    def points(self) -> np.ndarray:
        """(p, 3) float: surface points of the collision parts, object frame."""
        return np.vstack([p.surface_points() for p in self.collision])

    @property
    def height(self) -> float:
        """Height of the object resting in its own frame, m."""
        pts = self.points()
        return float(pts[:, 2].max() - pts[:, 2].min())


def soda_can(standing: bool = False) -> ObjectSpec:
    """A full 330 ml soda can, lying on its side (axis along x) or standing."""
    radius, length = 0.033, 0.120
    if standing:
        part = Part("cylinder", (radius, length / 2), pos=(0.0, 0.0, length / 2))
    else:
        part = Part("cylinder", (radius, length / 2), pos=(0.0, 0.0, radius), quat=_axis_to_x())
    return ObjectSpec("can-standing" if standing else "can", (part,), mass=0.35, friction_hand=0.60,
                      friction_table=0.30, rgba=(0.80, 0.10, 0.12, 1.0))


def glasses_case() -> ObjectSpec:
    """A hard glasses case: a box 0.16 x 0.06 x 0.04 m, rounded 0.02 m in plan and 0.01 m at its top edges."""
    vertices = _rounded_box((0.16, 0.06, 0.04), plan_radius=0.02, edge_radius=0.01)
    return ObjectSpec("case", (Part("mesh", vertices=vertices),), mass=0.10, friction_hand=0.65,
                      friction_table=0.40, rgba=(0.10, 0.14, 0.35, 1.0))


def water_bottle() -> ObjectSpec:
    """A full 0.5 l water bottle lying down, axis along x: body, tapered shoulder, neck and cap.

    The profile is the example contour ``bottle``: body radius 0.0325 for 0.145 m,
    a shoulder tapering to the 0.014 neck by 0.180, the neck to 0.190 and a 0.016
    cap to 0.205; the whole is centred on its length.
    """
    r_body, x0 = 0.0325, -0.1025
    parts = [
        Part("cylinder", (r_body, 0.0725), pos=(x0 + 0.0725, 0.0, r_body), quat=_axis_to_x()),
        Part("mesh", vertices=_frustum(r_body, 0.014, 0.035, x0 + 0.145, r_body)),
        Part("cylinder", (0.014, 0.005), pos=(x0 + 0.185, 0.0, r_body), quat=_axis_to_x()),
        Part("cylinder", (0.016, 0.0075), pos=(x0 + 0.1975, 0.0, r_body), quat=_axis_to_x()),
    ]
    return ObjectSpec("bottle", tuple(parts), mass=0.52, friction_hand=0.50, friction_table=0.30,
                      rgba=(0.55, 0.75, 0.95, 1.0))


def stone1() -> ObjectSpec:
    """Large heavy stone (~0.12 m, 0.6 kg): the ``stone1`` outline, 0.042 m thick, one hollow flank."""
    def radius(th):
        return 0.052 * (1 + 0.16 * np.cos(2 * th) + 0.05 * np.cos(3 * th + 0.7) + 0.03 * np.sin(th)
                        - 0.10 * np.exp(-((np.angle(np.exp(1j * (th - 1.5 * np.pi)))) / 0.45) ** 2))
    parts = _pebble(radius, top=0.024, bottom=0.018)
    return ObjectSpec("stone1", parts, mass=0.60, friction_hand=0.70, friction_table=0.50,
                      rgba=(0.42, 0.40, 0.38, 1.0))


def stone2() -> ObjectSpec:
    """Smaller, lighter stone (~0.08 m, 0.2 kg) with the more complex ``stone2`` outline."""
    def radius(th):
        return 0.036 * (1 + 0.12 * np.cos(2 * th + 0.3) + 0.08 * np.sin(3 * th) + 0.06 * np.cos(5 * th + 1.0)
                        + 0.04 * np.sin(7 * th + 0.4))
    parts = _pebble(radius, top=0.019, bottom=0.015)
    return ObjectSpec("stone2", parts, mass=0.20, friction_hand=0.70, friction_table=0.50,
                      rgba=(0.55, 0.47, 0.38, 1.0))


def flat_tool() -> ObjectSpec:
    """A dark grey tool for perception checks: a 4 mm plate 0.08 x 0.06 m with a 0.12 x 0.024 x 0.024 m grip.

    Like the can opener of the shared real frames, depth sees the grip and
    not the plate, and its grey differs from the table's in lightness only.
    """
    plate = Part("box", (0.04, 0.03, 0.002), pos=(0.0, 0.0, 0.002))
    grip = Part("box", (0.06, 0.012, 0.012), pos=(0.09, 0.0, 0.012))
    return ObjectSpec("tool", (plate, grip), mass=0.10, friction_hand=0.60, friction_table=0.40,
                      rgba=(0.20, 0.22, 0.20, 1.0))


#: The thesis's test objects by name (Table 4.4 plus the standing can).
THESIS_OBJECTS = {
    "can": soda_can,
    "can-standing": lambda: soda_can(standing=True),
    "case": glasses_case,
    "bottle": water_bottle,
    "stone1": stone1,
    "stone2": stone2,
}


def object_spec(spec) -> ObjectSpec:
    """An :class:`ObjectSpec` from itself, a name of :data:`THESIS_OBJECTS`, or a mesh file path (scale 1)."""
    if isinstance(spec, ObjectSpec):
        return spec
    if str(spec) in THESIS_OBJECTS:
        return THESIS_OBJECTS[str(spec)]()
    return mesh_object(spec)


def mesh_object(path, *, scale: float = 1.0, mass: float = 0.2, friction_hand: float = 0.60,
                friction_table: float = 0.40, rgba=(0.85, 0.55, 0.15, 1.0), name: str | None = None,
                cache_dir=None) -> ObjectSpec:
    """An object from an OBJ/STL/PLY mesh file: z up, units meters after ``scale``.

    The mesh is drawn as given and collides as its convex hull when it is
    convex within :data:`~contourgrasp.tolerances.MESH_CONVEX` of its size, else as the CoACD
    decomposition, cached under ``cache_dir`` (default
    ``$CONTOURGRASP_CACHE`` or ``~/.cache/contourgrasp``) keyed by the file's
    SHA-256, the scale and the CoACD settings.

    Raises
    ------
    SimulationError
        The file cannot be read as a mesh, is empty, has a non-finite vertex,
        encloses no volume (a flat or degenerate mesh), or is larger than
        :data:`~contourgrasp.tolerances.MESH_MAX_EXTENT` (probably millimetres,
        or a missing ``scale``), or has more than :data:`~contourgrasp.tolerances.MESH_MAX_FACES` triangles.
    """
    path = Path(path)
    mesh = _load_mesh(path, scale)
    offset = _rest_offset(mesh.vertices)
    visual = Part("mesh", vertices=mesh.vertices - offset, faces=np.asarray(mesh.faces))
    collision = tuple(Part("mesh", vertices=v - offset) for v in _convex_pieces(mesh, path, scale, cache_dir))
    return ObjectSpec(name or path.stem, collision, mass=mass, friction_hand=friction_hand,
                      friction_table=friction_table, rgba=tuple(rgba), visual=(visual,))


def _load_mesh(path: Path, scale: float):
    scale = positive("scale", scale, error=SimulationError)
    _check_vertices(path, _read_mesh(path, process=False))  # processing silently drops non-finite vertices
    mesh = _read_mesh(path, process=True).copy()
    mesh.apply_scale(scale)
    mesh.merge_vertices()
    extent = float(np.max(mesh.extents))
    if not np.isfinite(extent) or extent <= 0:
        raise SimulationError(f"{path}: the mesh has no extent")
    if extent > MESH_MAX_EXTENT:
        raise SimulationError(f"{path}: the mesh is {extent:.3g} m across after scale {scale}: "
                              f"probably millimetres (pass scale=0.001) or a missing scale")
    _check_volume(path, np.asarray(mesh.vertices))
    return mesh


def _read_mesh(path: Path, *, process: bool):
    import trimesh

    try:
        loaded = trimesh.load(path, force="mesh", process=process)
    except Exception as err:  # trimesh raises many types for unreadable files
        raise SimulationError(f"{path}: cannot read mesh ({type(err).__name__}: {err})") from None
    if not isinstance(loaded, trimesh.Trimesh) or len(loaded.faces) == 0:
        raise SimulationError(f"{path}: no triangles found in the mesh")
    if len(loaded.faces) > MESH_MAX_FACES:
        raise SimulationError(f"{path}: {len(loaded.faces):,} triangles, more than {MESH_MAX_FACES:,}: simplify the mesh "
                              "(e.g. quadric decimation in MeshLab or Blender)")
    return loaded


def _check_vertices(path: Path, mesh) -> None:
    """Refuse a mesh with a NaN or infinite vertex coordinate, naming the first such vertex."""
    try:
        finite_array("vertices", mesh.vertices, (None, 3), error=SimulationError)
    except SimulationError:
        bad = int(np.flatnonzero(~np.isfinite(np.asarray(mesh.vertices, dtype=float)).all(axis=1))[0])
        raise SimulationError(f"{path}: vertex {bad} is not finite ({mesh.vertices[bad].tolist()})") from None


def _check_volume(path: Path, vertices: np.ndarray) -> None:
    """Refuse a mesh whose vertices span no volume (one triangle, a flat sheet, a line): it cannot collide."""
    from scipy.spatial import ConvexHull, QhullError

    try:
        volume = ConvexHull(vertices).volume if len(vertices) >= 4 else 0.0
    except QhullError:
        volume = 0.0
    if not volume > 0:
        raise SimulationError(f"{path}: not a closed volume: its {len(vertices)} vertices are flat or degenerate "
                              "(a collision mesh must enclose a volume)")


def _rest_offset(vertices: np.ndarray) -> np.ndarray:
    """(3,) float: shift that centres the mesh in x, y and puts its lowest point at z = 0."""
    v = np.asarray(vertices)
    return np.array([(v[:, 0].max() + v[:, 0].min()) / 2, (v[:, 1].max() + v[:, 1].min()) / 2, v[:, 2].min()])


def hull_depth(vertices: np.ndarray, points: np.ndarray | None = None) -> float:
    """Largest distance (m) of ``points`` (default: the vertices) inside the convex hull of ``vertices``.

    0 for a convex shape. Pass the triangle centres too: the vertices of a
    non-convex prism (an L) all lie on its hull's boundary planes, the centres
    of its inner walls do not.
    """
    from scipy.spatial import ConvexHull, cKDTree

    hull = ConvexHull(vertices)
    points = np.asarray(vertices if points is None else points, dtype=float)
    # equations: n . p + b <= 0 inside; a point's depth is its smallest distance -(n . p + b) to a facet plane.
    normals, offsets = hull.equations[:, :3], hull.equations[:, 3]

    # Exact without points x facets at once (a 16k-face scan has ~16k facets: gigabytes): the distance to any
    # facets bounds a depth from above, so bound every point by its nearest facets, then take exact depths in
    # order of decreasing bound until the bound falls to the deepest point found.
    centres = np.einsum("fij->fj", hull.points[hull.simplices]) / 3
    near = cKDTree(centres).query(points, k=min(HULL_NEAR, len(centres)))[1].reshape(len(points), -1)
    bound = (-np.einsum("pj,pkj->pk", points, normals[near]) - offsets[near]).min(axis=1)
    order, deepest = np.argsort(-bound), -np.inf
    step = max(1, HULL_CHUNK // len(offsets))
    for i in range(0, len(order), step):
        chunk = order[i:i + step]
        if bound[chunk[0]] <= deepest:
            break
        deepest = max(deepest, float((-(points[chunk] @ normals.T) - offsets).min(axis=1).max()))
    return deepest


def _convex_pieces(mesh, path: Path, scale: float, cache_dir) -> list[np.ndarray]:
    vertices = np.asarray(mesh.vertices)
    surface = np.vstack([vertices, mesh.triangles_center])
    if hull_depth(vertices, surface) <= MESH_CONVEX * float(np.max(mesh.extents)):
        return [vertices]
    cache = _cache_file(path, scale, cache_dir)
    if cache.exists():
        with np.load(cache) as stored:
            return [stored[k] for k in sorted(stored.files, key=lambda k: int(k[1:]))]
    pieces = _coacd(mesh)
    cache.parent.mkdir(parents=True, exist_ok=True)
    tmp = cache.with_suffix(f".{os.getpid()}.tmp.npz")
    np.savez(tmp, **{f"p{i}": v for i, v in enumerate(pieces)})
    os.replace(tmp, cache)  # atomic: a concurrent run never reads half a file
    return pieces


def _coacd(mesh) -> list[np.ndarray]:
    import coacd

    coacd.set_log_level("error")
    parts = coacd.run_coacd(coacd.Mesh(np.asarray(mesh.vertices), np.asarray(mesh.faces)), **COACD_SETTINGS)
    return [np.asarray(v, dtype=float) for v, _ in parts if len(v) >= 4]


def default_cache_dir() -> Path:
    """Where decompositions are cached: ``$CONTOURGRASP_CACHE`` or ``~/.cache/contourgrasp``."""
    return Path(os.environ.get("CONTOURGRASP_CACHE", Path.home() / ".cache" / "contourgrasp"))


def _cache_file(path: Path, scale: float, cache_dir) -> Path:
    digest = hashlib.sha256(path.read_bytes())
    digest.update(repr((float(scale), sorted(COACD_SETTINGS.items()))).encode())
    return Path(cache_dir or default_cache_dir()) / "coacd" / f"{digest.hexdigest()[:32]}.npz"


def _pebble(radius_of_angle, *, top: float, bottom: float, n: int = 72) -> tuple[Part, ...]:
    """Convex wedges of a pebble with a star-shaped outline ``r(theta)`` and a lens-like thickness.

    The outline polygon is cut into fans around its centre, each as long as the
    outline keeps turning the same way (at most 120 degrees), so every fan is a
    convex polygon; each wedge is the hull of its fan lifted to the thickness
    profile (flat-ish bottom, domed top). The wedges' union has the outline
    exactly as its silhouette.
    """
    theta = np.linspace(0, 2 * np.pi, n, endpoint=False)
    rim = np.c_[radius_of_angle(theta) * np.cos(theta), radius_of_angle(theta) * np.sin(theta)]
    rho = np.array([0.0, 0.35, 0.6, 0.8, 0.92, 1.0])
    z_top = top * np.sqrt(1 - rho**2) ** 0.7
    z_bottom = -bottom * np.sqrt(1 - rho**4)
    parts = []
    for fan in _convex_fans(rim):
        ring = rim[fan]
        layers = [np.c_[r * ring, np.full(len(ring), z)]
                  for r, zt, zb in zip(rho, z_top, z_bottom, strict=True) for z in (zt, zb)]
        parts.append(np.vstack(layers))
    lowest = min(p[:, 2].min() for p in parts)
    return tuple(Part("mesh", vertices=p - [0.0, 0.0, lowest]) for p in parts)


def _convex_fans(rim: np.ndarray, max_span: float = np.radians(120)) -> list[np.ndarray]:
    """Index runs of a star-shaped polygon (CCW about the origin) whose fans from the origin are convex."""
    n = len(rim)
    back, ahead = rim - np.roll(rim, 1, axis=0), np.roll(rim, -1, axis=0) - rim
    turn = back[:, 0] * ahead[:, 1] - back[:, 1] * ahead[:, 0]  # > 0: convex vertex
    start = int(np.argmin(turn))  # begin at the most concave vertex so a fan never needs to span it
    fans, current = [], [start]
    angle = np.arctan2(rim[:, 1], rim[:, 0])
    for k in range(1, n + 1):
        i = (start + k) % n
        span = (angle[i] - angle[current[0]]) % (2 * np.pi)
        if turn[current[-1]] <= 0 and len(current) > 1 or span > max_span:
            fans.append(np.array(current))
            current = [current[-1]]
        current.append(i)
    fans.append(np.array(current))
    return fans


def _rounded_box(size, *, plan_radius: float, edge_radius: float, n: int = 8) -> np.ndarray:
    """(v, 3) float: hull vertices of a box rounded by ``plan_radius`` in plan and ``edge_radius`` at its top."""
    lx, ly, lz = size
    a = np.linspace(0, np.pi / 2, n)
    corners = []
    for sx, sy in [(1, 1), (-1, 1), (-1, -1), (1, -1)]:
        cx, cy = sx * (lx / 2 - plan_radius), sy * (ly / 2 - plan_radius)
        for b in np.linspace(0, np.pi / 2, n):  # top edge rounding: shrink the plan outline as z rises
            r = plan_radius - edge_radius * (1 - np.cos(b))
            z = lz - edge_radius + edge_radius * np.sin(b)
            corners.append(np.c_[cx + sx * r * np.cos(a), cy + sy * r * np.sin(a), np.full(n, z)])
        corners.append(np.c_[cx + sx * plan_radius * np.cos(a), cy + sy * plan_radius * np.sin(a), np.zeros(n)])
    return np.vstack(corners)


def _frustum(r0: float, r1: float, length: float, x0: float, z_axis: float, n: int = 24) -> np.ndarray:
    """(2n, 3) float: a cone frustum along x from radius r0 at x0 to r1 at x0 + length, axis at height z_axis."""
    a = np.linspace(0, 2 * np.pi, n, endpoint=False)
    ring = np.c_[np.cos(a), np.sin(a)]
    return np.vstack([np.c_[np.full(n, x), r * ring[:, 0], z_axis + r * ring[:, 1]]
                      for x, r in [(x0, r0), (x0 + length, r1)]])


def _axis_to_x() -> tuple[float, float, float, float]:
    """Quaternion turning a geom's z axis (cylinder axis) onto x: 90 degrees about y."""
    return (float(np.cos(np.pi / 4)), 0.0, float(np.sin(np.pi / 4)), 0.0)


def _quat_matrix(q) -> np.ndarray:
    w, x, y, z = np.asarray(q, dtype=float) / np.linalg.norm(q)
    return np.array([
        [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
        [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
        [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)],
    ])


def _primitive_mesh(kind: str, size, trimesh):
    if kind == "box":
        return trimesh.creation.box(extents=2 * np.asarray(size))
    if kind == "cylinder":
        return trimesh.creation.cylinder(radius=size[0], height=2 * size[1], sections=48)
    if kind == "capsule":
        return trimesh.creation.capsule(radius=size[0], height=2 * size[1])
    if kind == "sphere":
        return trimesh.creation.icosphere(subdivisions=3, radius=size[0])
    sphere = trimesh.creation.icosphere(subdivisions=3)
    sphere.apply_scale(np.asarray(size))
    return sphere
