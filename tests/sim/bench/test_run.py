"""contourgrasp.sim.bench.run: running every trial, no-plan trials, progress."""

import io

from contourgrasp.sim import NO_PLAN, Camera, ObjectSpec, Part, Workspace
from contourgrasp.sim.bench import Bench, BenchTrial, console_progress, run_bench, thesis_objects, write_outputs
from contourgrasp.sim.trial import TrialRecord


def test_object_too_large_is_no_feasible_plan(tmp_path):
    # A 0.8 m disc under a camera raised to 1 m (whole in view): every pose of the search region starts a
    # fingertip inside it (see test_sim_trial).
    platter = ObjectSpec("platter", (Part("cylinder", (0.40, 0.01), pos=(0.0, 0.0, 0.01)),), mass=3.0,
                         friction_hand=0.6, friction_table=0.4)
    bench = Bench(objects=(platter,), planners=("paper", "centroid-principal-axis"), trials=1,
                  camera=Camera(height=1.0), workspace=Workspace(0.0, 0.0), sensor="basic")  # 2 cm tall at 1 m
    results = run_bench(bench)
    paper, centroid = (r.record for r in results)
    assert paper.cause == NO_PLAN and "larger than the hand" in paper.plan_error
    assert centroid.cause != NO_PLAN  # the baseline plans without the synthesis's constraints
    write_outputs(bench, results, tmp_path, wall_time=1.0)
    assert "| no feasible plan | 1 | 1 |" in (tmp_path / "table.md").read_text()


def test_progress_prints_a_line_per_finished_object_in_a_log():
    bench = Bench(objects=thesis_objects(["can", "case"]), planners=("paper", "random"), trials=2)
    stream = io.StringIO()
    done = [BenchTrial(p, t, _record("can", t == 0)) for p in bench.planners for t in range(2)]
    with console_progress(bench, stream, done=done[:1]) as update:
        for result in done[1:] + [BenchTrial(p, t, _record("case", True)) for p in bench.planners for t in range(2)]:
            update(result)
    lines = stream.getvalue().splitlines()
    assert len(lines) == 2
    assert lines[0].startswith("bench: can done (paper 1/2, random 1/2); 1/2 objects, 4/8 trials, ")
    assert lines[1].startswith("bench: case done (paper 2/2, random 2/2); 2/2 objects, 8/8 trials, ")
    assert "trials/s, ETA 0:00" in lines[1]


def test_trials_run_object_by_object_and_come_back_planner_by_planner():
    bench = Bench(objects=thesis_objects(["can", "case"]), planners=("paper", "random"), trials=2)
    assert bench.tasks()[:4] == [("paper", 0, 0), ("paper", 0, 1), ("random", 0, 0), ("random", 0, 1)]
    finished = [BenchTrial(p, t, _record(bench.objects[i].name, True)) for p, i, t in reversed(bench.tasks())]
    results = run_bench(bench, execute=lambda tasks: iter(finished))
    assert [(r.planner, r.record.object, r.trial) for r in results] == [
        (p, o, t) for p in bench.planners for o in ("can", "case") for t in range(2)]


def _record(obj, success):
    return TrialRecord(object=obj, seed=0, success=success, cause=None if success else "dropped",
                       fingers_in_contact=(), first_contact=(), push=0.0, lift=0.0, hold_drift=0.0, pose=None,
                       approach_depth=None, grasp_height=None, plan_error=None, sim_time=1.0, plan_time=0.1, wall_time=1.0)


def test_a_trial_of_a_planner_that_approaches_tilted_reproduces_for_its_snapshot(tmp_path):
    """The failure mosaic reruns a trial through a recording planner: the hand must get its wrist there too."""
    from pathlib import Path

    import contourgrasp
    from contourgrasp.sim.bench.run import snapshot
    from contourgrasp.sim.objects import soda_can

    default = Path(contourgrasp.__file__).parent / "data" / "planners" / "default.toml"
    tilted = tmp_path / "tilted.toml"
    tilted.write_text(default.read_text().replace('name = "default"', 'name = "tilted"') + 'approaches = "tilted"\n')
    bench = Bench(objects=(soda_can(standing=True),), planners=(str(tilted),), trials=1, sensor="basic")
    result = run_bench(bench)[0]
    assert result.record.pose is not None
    shot = snapshot(bench, result)
    assert shot.planned.approach.kind == "tilted"


def test_a_clearing_run_reproduces_for_its_snapshot():
    """The mosaic reruns a clearing run through a recording planner: it has the planner's hand, so that after a
    failure it asks about the same objects (those the hand spans)."""
    from contourgrasp.sim.bench.run import _Recording, snapshot
    from contourgrasp.sim.planners import make_planner

    planner = make_planner("default", Bench(objects=thesis_objects(["can"])).hand)
    assert _Recording(planner).hand is planner.hand

    bench = Bench(objects=thesis_objects(["can", "case"]), planners=("default",), trials=1, scene_kind="clutter",
                  protocol="clear")
    result = run_bench(bench)[0]
    assert result.record.pose is not None and result.record.ended is not None
    assert snapshot(bench, result).planned is not None
