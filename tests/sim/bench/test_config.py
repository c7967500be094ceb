"""contourgrasp.sim.bench.config: what a bench runs, refused before any trial when it cannot run."""

from dataclasses import replace

import pytest

from contourgrasp.cli import main
from contourgrasp.errors import SimulationError
from contourgrasp.sim.bench import Bench, resolve_objects, thesis_objects


def run_cli(argv, capsys) -> tuple[int, str]:
    code = main([str(a) for a in argv])
    return code, capsys.readouterr().err


@pytest.mark.parametrize("argv, message", [
    (["--objects", "can,teapot"], "unknown object 'teapot'"),
    (["--planners", "paper,oracle"], "oracle"),
    (["--hand", "five-finger-curved-thumb"], "arc"),
])
def test_bad_names_exit_2_and_write_nothing(argv, message, tmp_path, capsys):
    out = tmp_path / "out"
    code, err = run_cli(["bench", *argv, "--trials", "1", "--out", out], capsys)
    assert code == 2 and message in err and len(err.strip().splitlines()) == 1
    assert not out.exists()


@pytest.mark.parametrize("options, message", [
    ({"objects": ()}, "no object"),
    ({"trials": 0}, "trials must be an integer >= 1"),
    ({"trials": 1.5}, "trials must be an integer"),
    ({"seed": -1}, "seed must be an integer >= 0"),
    ({"trials": 1001}, "trials must be at most 1000"),
    ({"seed": 2**40}, "seed must be at most"),
    ({"planners": ("paper", "default", "random"), "trials": 1000, "objects": "many"}, "at most 100000 in one bench"),
    ({"planners": ("paper", "paper")}, "planners must be distinct"),
])
def test_a_bench_that_cannot_run_is_a_simulation_error(options, message):
    setup = {"objects": thesis_objects(["can"]), "trials": 1} | options
    if setup["objects"] == "many":  # 40 differently named copies of the can
        setup["objects"] = tuple(replace(thesis_objects(["can"])[0], name=f"can{i}") for i in range(40))
    with pytest.raises(SimulationError, match=message):
        Bench(**setup)


def test_a_named_set_becomes_a_split_and_plain_names_belong_to_none():
    objects, splits = resolve_objects("can,thesis,can")
    assert [o.name for o in objects] == ["can", "case", "bottle", "stone1", "stone2"]
    assert splits == (("thesis", ("can", "case", "bottle", "stone1", "stone2")),)
    objects, splits = resolve_objects(["case", "can"])
    assert [o.name for o in objects] == ["case", "can"] and splits == ()
    bench = Bench(objects=objects, trials=1, splits=(("test", ("can",)),))
    assert bench.split_of("can") == "test" and bench.split_of("case") is None


@pytest.mark.parametrize("splits, message", [
    ((("test", ("teapot",)),), "split 'test' names teapot"),
    ((("test", ()),), "split 'test' names no object"),
])
def test_a_split_names_objects_the_bench_runs(splits, message):
    with pytest.raises(SimulationError, match=message):
        Bench(objects=thesis_objects(["can"]), trials=1, splits=splits)


def test_an_unknown_name_is_refused_before_any_object_is_loaded():
    with pytest.raises(SimulationError, match="unknown object 'teapot'"):
        resolve_objects("thesis,teapot")


def test_a_scene_of_several_objects_draws_neighbours_from_the_targets_split():
    objects = thesis_objects(["can", "case", "bottle", "stone1"])
    bench = Bench(objects=objects, trials=1, scene_kind="clutter",
                  splits=(("train", ("can", "case")), ("test", ("bottle",))))
    assert [o.name for o in bench.pool("can")] == ["case"]
    assert [o.name for o in bench.pool("bottle")] == ["bottle"]  # alone in its split: beside copies of itself
    assert [o.name for o in bench.pool("stone1")] == ["can", "case", "bottle"]  # in no split: beside all the others
    assert "hit a neighbour or the bin" in bench.causes
    assert "hit a neighbour or the bin" not in Bench(objects=objects, trials=1).causes
    with pytest.raises(SimulationError, match="scene must be one of"):
        Bench(objects=objects, trials=1, scene_kind="heap")


@pytest.mark.parametrize("options, message", [
    ({"protocol": "heap", "scene_kind": "clutter"}, "protocol must be one of"),
    ({"protocol": "clear"}, "protocol 'clear' needs a scene of several objects"),
    ({"protocol": "clear", "scene_kind": "bin", "attempts": 3}, "attempts must be 1 with protocol 'clear'"),
])
def test_the_clearing_protocol_needs_a_scene_of_several_objects_and_makes_its_own_attempts(options, message):
    with pytest.raises(SimulationError, match=message):
        Bench(objects=thesis_objects(["can"]), trials=1, **options)


def test_a_clearing_bench_clears_its_scenes():
    bench = Bench(objects=thesis_objects(["can", "case"]), planners=("default",), trials=1, scene_kind="clutter",
                  protocol="clear")
    record = bench.run("default", bench.object("can"), 0)
    assert record.scene_objects >= 2 and record.ended is not None and len(record.outcomes) >= 1
    assert record.success == (record.cleared == record.scene_objects)
