"""Procedurally generated objects (sim.procedural): seeded, every family, resting and settling on the table."""

from __future__ import annotations

from collections import Counter

import numpy as np
import pytest

from contourgrasp.errors import SimulationError
from contourgrasp.sim import build_scene
from contourgrasp.sim.bench.config import resolve_objects
from contourgrasp.sim.procedural import FAMILIES, TEST_SEED, procedural_names, procedural_object, procedural_seed
from contourgrasp.sim.ycb import load_object, object_names

SEEDS = range(120)


@pytest.fixture(scope="module")
def objects():
    return [procedural_object(s) for s in SEEDS]


def test_a_seed_gives_the_same_object_and_another_seed_another(objects):
    again = procedural_object(5)
    assert again.name == objects[5].name and again.mass == objects[5].mass
    np.testing.assert_array_equal(again.points(), objects[5].points())
    sizes = {tuple(np.round(np.ptp(o.points(), axis=0), 5)) for o in objects}
    assert len(sizes) == len(objects)


def test_every_family_is_drawn_about_as_often(objects):
    counts = Counter(o.name.split("-")[2] for o in objects)
    assert set(counts) == set(FAMILIES)
    assert min(counts.values()) >= 0.4 * len(objects) / len(FAMILIES)


def test_each_rests_on_the_table_centred_with_a_hand_sized_extent_and_mass(objects):
    for o in objects:
        points = o.points()
        extent = points.max(axis=0) - points.min(axis=0)
        assert points[:, 2].min() == pytest.approx(0.0, abs=1e-9), o.name
        np.testing.assert_allclose((points.max(axis=0) + points.min(axis=0))[:2] / 2, 0.0, atol=1e-9)
        assert 0.015 < extent.max() < 0.30, o.name
        assert 0.02 <= o.mass <= 1.0 and 0.2 <= o.friction_table < o.friction_hand <= 1.0
        assert all(p.kind != "mesh" or p.faces is None for p in o.collision), "a collision mesh is a convex hull"


def test_a_mug_is_hollow_with_a_handle_and_a_bowl_is_open():
    mug = next(procedural_object(s) for s in SEEDS if procedural_object(s).name.endswith("-mug"))
    points = mug.points()
    # no part crosses the mug's axis above its bottom: the inside is empty
    centre = (points.max(axis=0) + points.min(axis=0)) / 2
    parts_over_axis = [p for p in mug.collision
                       if np.linalg.norm(p.surface_points()[:, :2].mean(axis=0) - centre[:2]) < 0.01
                       and p.surface_points()[:, 2].max() > 0.01]
    assert parts_over_axis == []
    assert len(mug.collision) > 14  # the wall's segments, the bottom and the handle's three bars


def test_set_tokens_name_training_and_held_out_seeds():
    assert procedural_names("procedural:3") == ("proc-0", "proc-1", "proc-2")
    assert procedural_names("procedural-test:2") == (f"proc-{TEST_SEED}", f"proc-{TEST_SEED + 1}")
    assert procedural_names("ycb-train") is None
    assert procedural_seed("proc-12-mug") == 12 and procedural_seed("proc-12") == 12 and procedural_seed("can") is None
    assert object_names("procedural:2,can") == ("proc-0", "proc-1", "can")
    assert load_object("proc-4").name == procedural_object(4).name
    specs, splits = resolve_objects("procedural:3,procedural-test:1")
    assert [name for _, names in splits for name in names] == [o.name for o in specs]
    assert [split for split, _ in splits] == ["procedural:3", "procedural-test:1"]


@pytest.mark.parametrize("token, message", [
    ("procedural:0", "1 to 1000 objects"),
    ("procedural:1001", "1 to 1000 objects"),
])
def test_a_set_too_large_or_empty_is_refused(token, message):
    with pytest.raises(SimulationError, match=message):
        object_names(token)


@pytest.mark.parametrize("seed", [-1, 2.5, True, "3"])
def test_a_bad_seed_is_refused(seed):
    with pytest.raises(SimulationError, match="non-negative integer"):
        procedural_object(seed)


@pytest.mark.parametrize("seed", [1, 4, 9, 21])  # a bowl, a hammer, a mug, a bottle
def test_it_settles_in_mujoco_where_it_was_put(seed):
    obj = procedural_object(seed)
    scene = build_scene(obj, seed=0)
    before = scene.object_position().copy()
    scene.step(0.5)
    assert np.linalg.norm(scene.object_position() - before) < 0.002, obj.name
