"""The thesis's objects and mesh files: sizes, masses, bad meshes, convex decomposition and its cache."""

import numpy as np
import pytest
import trimesh

from contourgrasp import InputError
from contourgrasp.cli import main
from contourgrasp.errors import SimulationError
from contourgrasp.sim import THESIS_OBJECTS, ObjectSpec, Part, mesh_object, object_spec
from contourgrasp.sim.objects import hull_depth
from sim_planner import require_shared_data


@pytest.mark.parametrize("name", sorted(THESIS_OBJECTS))
def test_thesis_objects_rest_on_the_table_plane(name):
    obj = object_spec(name)
    points = obj.points()
    assert abs(points[:, 2].min()) < 1e-6
    assert 0.04 <= np.ptp(points[:, :2], axis=0).max() <= 0.21


def test_thesis_object_sizes_and_masses():
    sizes = {name: np.sort(np.ptp(object_spec(name).points(), axis=0))[::-1] for name in THESIS_OBJECTS}
    np.testing.assert_allclose(sizes["can"], [0.120, 0.066, 0.066], atol=1e-3)
    np.testing.assert_allclose(sizes["case"], [0.160, 0.060, 0.040], atol=1e-3)
    assert sizes["stone1"][0] == pytest.approx(0.12, abs=0.01) and sizes["stone2"][0] < sizes["stone1"][0]
    masses = {name: object_spec(name).mass for name in THESIS_OBJECTS}
    assert masses["stone1"] == max(masses.values()) == pytest.approx(0.6)
    assert masses["stone2"] < masses["stone1"]


def test_stone_pieces_are_convex():
    for name in ("stone1", "stone2"):
        for part in object_spec(name).collision:
            assert hull_depth(part.vertices) < 1e-9


def test_hull_depth_equals_the_distance_to_every_facet_plane():
    from scipy.spatial import ConvexHull

    rng = np.random.default_rng(7)
    mug = trimesh.creation.annulus(r_min=0.03, r_max=0.04, height=0.08)  # non-convex: the inner wall is deep
    for vertices, points in [(rng.normal(size=(300, 3)), rng.normal(size=(800, 3)) * 0.6),
                             (mug.vertices, np.vstack([mug.vertices, mug.triangles_center]))]:
        hull = ConvexHull(vertices)
        brute = (-(points @ hull.equations[:, :3].T + hull.equations[:, 3])).min(axis=1).max()
        assert hull_depth(vertices, points) == pytest.approx(brute, abs=1e-15)
    assert hull_depth(mug.vertices, mug.triangles_center) == pytest.approx(0.01, abs=2e-3)


def test_unreadable_mesh_names_the_file(tmp_path):
    bad = tmp_path / "broken.obj"
    bad.write_bytes(b"\x00\x01 not a mesh")
    with pytest.raises(InputError, match="broken.obj"):
        mesh_object(bad, cache_dir=tmp_path)
    with pytest.raises(InputError, match="missing.stl"):
        mesh_object(tmp_path / "missing.stl", cache_dir=tmp_path)


def test_millimetre_mesh_is_refused(tmp_path):
    path = tmp_path / "box_mm.stl"
    trimesh.creation.box(extents=(80.0, 50.0, 30.0)).export(path)
    with pytest.raises(InputError, match="millimetres"):
        mesh_object(path, cache_dir=tmp_path)
    assert len(mesh_object(path, scale=0.001, cache_dir=tmp_path).collision) == 1


def test_non_convex_mesh_is_decomposed_and_cached(tmp_path):
    ell = np.array([(-0.05, -0.01), (0.05, -0.01), (0.05, 0.01), (-0.03, 0.01), (-0.03, 0.09), (-0.05, 0.09)])
    path = tmp_path / "ell.stl"
    trimesh.creation.extrude_triangulation(ell, [(0, 1, 2), (0, 2, 3), (0, 3, 5), (3, 4, 5)], 0.03).export(path)
    obj = mesh_object(path, cache_dir=tmp_path)
    assert len(obj.collision) >= 2 and len(obj.visual) == 1
    cached = list((tmp_path / "coacd").glob("*.npz"))
    assert len(cached) == 1
    again = mesh_object(path, cache_dir=tmp_path)
    for a, b in zip(obj.collision, again.collision, strict=True):
        np.testing.assert_array_equal(a.vertices, b.vertices)


def test_shared_meshes(tmp_path):
    meshes = require_shared_data() / "meshes"
    lemon = mesh_object(meshes / "robosuite" / "lemon.obj", cache_dir=tmp_path)
    assert len(lemon.collision) == 1  # convex: its hull, no decomposition
    blob = meshes / "pybullet_data" / "random_urdfs" / "022" / "022.obj"
    with pytest.raises(InputError, match="millimetres"):
        mesh_object(blob, cache_dir=tmp_path)
    stone = mesh_object(blob, scale=0.015, cache_dir=tmp_path)
    assert len(stone.collision) >= 2
    assert 0.05 < np.ptp(stone.points(), axis=0).max() < 0.2


def run_cli(argv, capsys) -> tuple[int, str]:
    code = main([str(a) for a in argv])
    return code, capsys.readouterr().err


def test_unreadable_mesh_exits_2_and_writes_nothing(tmp_path, capsys):
    mesh = tmp_path / "broken.obj"
    mesh.write_bytes(b"\x00\x01 not a mesh")
    out = tmp_path / "out"
    code, err = run_cli(["bench", "--mesh", mesh, "--out", out], capsys)
    assert code == 2 and "broken.obj" in err and len(err.strip().splitlines()) == 1
    assert not out.exists()


@pytest.mark.parametrize("text, message", [
    ("v 0 0 0\nv 0.1 0 0\nv 0 0.1 0\nf 1 2 3\n", "not a closed volume"),
    ("v 0 0 0\nv 0.1 0 0\nv 0 0.1 0\nv 0 0 nan\nv 0.05 0.05 0.05\nf 1 2 3\nf 1 2 4\nf 1 3 4\nf 2 3 4\nf 1 2 5\n",
     r"vertex 3 is not finite"),
    ("v 0 0 0\nv 0.1 0 0\nv 0.2 0 0\nv 0.3 0 0\nf 1 2 3\nf 2 3 4\n", "not a closed volume"),
])
def test_degenerate_meshes_are_one_line_naming_the_file(tmp_path, capsys, text, message):
    mesh = tmp_path / "bad.obj"
    mesh.write_text(text)
    with pytest.raises(SimulationError, match=message):
        mesh_object(mesh, cache_dir=tmp_path)
    code, err = run_cli(["bench", "--mesh", mesh, "--trials", "1", "--out", tmp_path / "out"], capsys)
    assert code == 2 and f"{mesh}: " in err and message.replace("\\", "") in err
    assert len(err.strip().splitlines()) == 1 and "Traceback" not in err and not (tmp_path / "out").exists()


def test_bad_parts_and_objects_are_simulation_errors():
    with pytest.raises(SimulationError, match="part kind must be one of"):
        Part("torus")
    with pytest.raises(SimulationError, match="mesh part needs vertices"):
        Part("mesh")
    with pytest.raises(SimulationError, match="mass must be a finite number"):
        ObjectSpec("x", (Part("sphere", (0.01,)),), mass=float("nan"), friction_hand=0.5, friction_table=0.5)


def test_a_mesh_of_too_many_triangles_is_refused_before_its_decomposition(tmp_path):
    import trimesh

    from contourgrasp.tolerances import MESH_MAX_FACES

    sphere = trimesh.creation.icosphere(subdivisions=7, radius=0.04)  # 327,680 triangles
    assert len(sphere.faces) > MESH_MAX_FACES
    sphere.export(tmp_path / "dense.stl")
    with pytest.raises(SimulationError, match="dense.stl: 327,680 triangles, more than 100,000: simplify the mesh"):
        mesh_object(tmp_path / "dense.stl")
