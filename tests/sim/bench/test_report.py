"""contourgrasp.sim.bench.report: the bench's outputs end to end (table, trial records, figures), and determinism."""

import json
import math

import contourgrasp
from contourgrasp.cli import main
from contourgrasp.errors import SimulationError
from contourgrasp.sim.bench import BenchTrial, Bench, ablation_table, picked_failures, thesis_objects, write_outputs
from contourgrasp.sim.planners import ablation_planners
from contourgrasp.sim.trial import PUSHED, TrialRecord

import pytest

REQUIRED = {"object", "planner", "trial", "seed", "success", "cause", "fingers_in_contact", "plan_time", "sim_time",
            "wall_time", "pose"}
OUTPUTS = ("table.md", "trials.json", "success.png", "trials.png")
TWO_PLANNERS = ["bench", "--objects", "can", "--trials", "2", "--planners", "paper,random", "--workers", "1", "--sensor", "basic"]


def run_cli(argv, capsys) -> tuple[int, str]:
    code = main([str(a) for a in argv])
    return code, capsys.readouterr().err


@pytest.fixture(scope="module")
def bench_out(tmp_path_factory):
    out = tmp_path_factory.mktemp("bench") / "new-folder"
    assert main([*TWO_PLANNERS, "--out", str(out)]) == 0
    return out


def without_times(records):
    return [{k: v for k, v in r.items() if k not in ("plan_time", "wall_time")} for r in records]


def test_bench_writes_every_output(bench_out):
    assert all((bench_out / name).stat().st_size > 0 for name in OUTPUTS)
    for name in ("success.png", "trials.png"):
        assert (bench_out / name).read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    table = (bench_out / "table.md").read_text()
    assert "| thesis, real robot (Table 4.4) | 80 % | 80 % |" in table
    assert "| thesis (Table 4.4) | 80 % |" in table
    assert "## paper" in table and "## random" in table and "random (baseline)" in table
    assert table.count("Causes of failure") == 2
    assert "- `paper`: `plan_grasp` with harmonics=4" in table and "Median planning time" in table


def test_trials_json_has_one_record_per_trial(bench_out):
    records = json.loads((bench_out / "trials.json").read_text())
    assert len(records) == 4
    assert all(REQUIRED <= set(r) for r in records)
    assert {(r["planner"], r["trial"], r["seed"]) for r in records} == {
        (p, t, t) for p in ("paper", "random") for t in (0, 1)}
    for r in records:
        assert r["object"] == "can" and r["plan_time"] > 0 and r["sim_time"] > 5.0
        assert r["success"] == (r["cause"] is None)
        assert r["pose"] is None or set(r["pose"]) == {"x", "y", "yaw"}


def test_same_seed_same_trials(bench_out, tmp_path):
    assert main([*TWO_PLANNERS, "--out", str(tmp_path)]) == 0
    first = json.loads((bench_out / "trials.json").read_text())
    again = json.loads((tmp_path / "trials.json").read_text())
    assert without_times(first) == without_times(again)


def test_ablation_table_counts_rates_and_causes():
    steps = [p.name for p in ablation_planners()]
    ran = (*steps[:-1], "default")
    bench = Bench(objects=(contourgrasp.sim.objects.object_spec("can"),), planners=ran, trials=2)
    record = dict(object="can", seed=0, fingers_in_contact=(), first_contact=(), push=0.0, lift=0.0, hold_drift=0.0,
                  pose=None, approach_depth=None, grasp_height=None, plan_error=None, sim_time=1.0, plan_time=0.1, wall_time=1.0)
    results = [BenchTrial(p, t, TrialRecord(success=t == 0, cause=None if t == 0 else PUSHED, **record))
               for p in ran for t in range(2)]
    table = ablation_table(bench, results)
    assert len(table) == 2 + len(ran)
    assert table[2].startswith("| paper | 50 % (9–91) |")
    assert table[-1].startswith(f"| {steps[-1]} = `default` | 50 % (9–91) |") and table[-1].count("| 1 |") == 1


def test_a_planner_file_runs_on_the_bench(tmp_path, capsys):
    planner = tmp_path / "coarse.toml"
    planner.write_text('name = "coarse"\nxy_step = 0.05\nyaw_step = 0.1\n')
    out = tmp_path / "out"
    code, err = run_cli(["bench", "--objects", "case", "--trials", "1", "--planners", str(planner), "--out", out,
                         "--workers", "1"],
                        capsys)
    assert code == 0, err
    assert f"- `{planner}`: `plan_grasp` with xy_step=0.05, yaw_step=5.72958°" in (out / "table.md").read_text()


def _split_results(bench, rates):
    """Trials with ``rates[planner][object]`` successes of 2; failures dropped after a plan (pose set)."""
    record = dict(seed=0, fingers_in_contact=(), first_contact=(), push=0.0, lift=0.0, hold_drift=0.0,
                  pose=None, approach_depth=None, grasp_height=None, plan_error=None, sim_time=1.0, plan_time=0.1, wall_time=1.0)
    return [BenchTrial(p, t, TrialRecord(object=o.name, success=t < rates[p][o.name], cause=None if t < rates[p][o.name]
                                         else PUSHED, **record))
            for p in bench.planners for o in bench.objects for t in range(bench.trials)]


def test_a_bench_with_splits_reports_per_split_and_per_object(tmp_path):
    # Split labels faked on the thesis's objects: what the YCB sets give.
    bench = Bench(objects=thesis_objects(["can", "case", "bottle"]), planners=("paper", "default"), trials=2,
                  splits=(("ycb-train", ("can", "case")), ("ycb-test", ("bottle",))))
    rates = {"paper": {"can": 2, "case": 0, "bottle": 1}, "default": {"can": 1, "case": 2, "bottle": 0}}
    paths = write_outputs(bench, _split_results(bench, rates), tmp_path, wall_time=3.0)
    assert [p.name for p in paths] == [*OUTPUTS, "failures.png"]
    table = (tmp_path / "table.md").read_text()
    assert table.startswith("# contourgrasp bench: ycb-train (2 objects), ycb-test (1 objects), simulated\n")
    assert "| planner | ycb-train | ycb-test | all |" in table
    assert "| paper | 50 % (15–85) 2/4 | 50 % (9–91) 1/2 | 50 % (19–81) 3/6 |" in table
    assert "| default | ycb-test | 0 | 0 | 0 | 2 | 0 | 0 |" in table  # no plan, struck, missed, pushed, ...
    rows = [line for line in table.splitlines() if line.startswith(("| can", "| glasses case", "| bottle"))]
    assert rows == ["| glasses case | ycb-train | 0 % (0–66) | 100 % (34–100) | — |",
                    "| can | ycb-train | 100 % (34–100) | 50 % (9–91) | pushed 1 |",
                    "| bottle | ycb-test | 50 % (9–91) | 0 % (0–66) | pushed 2 |"]
    assert "Table 4.4" not in table and "## Ablation: paper to default" in table  # paper and default: two steps


def test_the_failure_mosaic_shows_the_ranking_planner_first_worst_objects_first():
    bench = Bench(objects=thesis_objects(["can", "case"]), planners=("paper", "default"), trials=2,
                  splits=(("s", ("can", "case")),))
    results = _split_results(bench, {"paper": {"can": 0, "case": 0}, "default": {"can": 1, "case": 0}})
    for r in results:
        object.__setattr__(r.record, "pose", (0.0, 0.0, 0.0))  # as if every trial had a plan
    picked = [(r.planner, r.record.object, r.trial) for r in picked_failures(bench, results, limit=3)]
    assert picked == [("default", "case", 0), ("default", "can", 1), ("paper", "can", 0)]


def test_a_bin_bench_reports_its_scene_and_the_hit_cause(tmp_path, capsys):
    out = tmp_path / "bin"
    code, _ = run_cli(["bench", "--scene", "bin", "--objects", "can,stone2", "--trials", "1", "--planners",
                       "centroid-principal-axis", "--workers", "1", "--out", out], capsys)
    assert code == 0
    table = (out / "table.md").read_text()
    assert "Scene `bin`: 1-3 objects in a bin" in table and "| hit a neighbour or the bin |" in table
    assert "without the hand touching a neighbour or a bin wall" in table
    assert [r["object"] for r in json.loads((out / "trials.json").read_text())] == ["can", "stone2"]


def test_the_reports_first_paragraph_says_how_the_hand_is_simulated():
    from contourgrasp.sim.bench.report import _trials_text

    bench = Bench(objects=thesis_objects(["can"]), planners=("paper",), trials=1)
    text = _trials_text(bench, 1, 1.0, 0)
    assert "Hand `five-finger-linear` (one tendon, the thesis's finger timing); depth sensor `structured-light`;" in text
    tilted = _trials_text(Bench(objects=thesis_objects(["can"]), planners=("paper",), trials=1, sensor="stereo",
                                tilt=math.radians(40)), 1, 1.0, 0)
    assert "depth sensor `stereo`, the camera tilted 40 deg;" in tilted
    robot = _trials_text(Bench(objects=thesis_objects(["can"]), planners=("paper",), trials=1, robot=True), 1, 1.0, 0)
    assert "depth sensor `structured-light`, a robot arm in view (seen, never touched);" in robot
    with pytest.raises(SimulationError, match="robot must be True or False"):
        Bench(objects=thesis_objects(["can"]), robot="yes")


def test_procedural_objects_are_reported_per_family_too(tmp_path):
    from contourgrasp.sim.procedural import procedural_object

    objects = tuple(procedural_object(s) for s in (1, 6, 9))  # two bowls and a mug
    assert [o.name for o in objects] == ["proc-1-bowl", "proc-6-bowl", "proc-9-mug"]
    bench = Bench(objects=objects, planners=("default",), trials=2,
                  splits=(("procedural:10", tuple(o.name for o in objects)),))
    rates = {"default": {"proc-1-bowl": 2, "proc-6-bowl": 1, "proc-9-mug": 0}}
    write_outputs(bench, _split_results(bench, rates), tmp_path, wall_time=1.0)
    table = (tmp_path / "table.md").read_text()
    assert "## Per family (procedural objects)" in table
    assert "| mug | 1 | 0 % (0–66) 0/2 | pushed 2 |" in table
    assert "| bowl | 2 | 75 % (30–95) 3/4 | pushed 1 |" in table
    assert table.index("| mug |") < table.index("| bowl |")  # the families' order: FAMILIES


def test_a_bench_without_procedural_objects_has_no_family_table(bench_out):
    assert "Per family" not in (bench_out / "table.md").read_text()


def test_several_attempts_are_reported_first_within_and_as_told(tmp_path):
    from dataclasses import replace

    from contourgrasp.sim.bench import trial_from_dict, trial_to_dict

    bench = Bench(objects=thesis_objects(["can", "case"]), planners=("default",), trials=2, attempts=3)
    base = _split_results(bench, {"default": {"can": 2, "case": 0}})
    told = {("can", 0): ((True,), (True,)), ("can", 1): ((False, True), (False, True)),
            ("case", 0): ((False, False, False), (False, True, False)), ("case", 1): ((False,), (True,))}
    results = [BenchTrial(r.planner, r.trial, replace(r.record, outcomes=told[r.record.object, r.trial][0],
                                                      detected=told[r.record.object, r.trial][1]))
               for r in base]
    assert [trial_from_dict(trial_to_dict(r)) for r in results] == results  # the journal keeps them
    write_outputs(bench, results, tmp_path, wall_time=1.0)
    table = (tmp_path / "table.md").read_text()
    assert "## Attempts (at most 3)" in table
    assert "| default | all | 25 % (5–70) 1/4 | 50 % (15–85) 2/4 | 1.75 |" in table
    assert "| succeeded | 2 | 2 |" in table and "| failed | 0 | 3 |" in table
    assert "False success: 2 of 7 attempts (28.6 %)." in table


def test_clearing_is_reported_per_attempt_per_object_and_by_its_end(tmp_path):
    from dataclasses import replace

    bench = Bench(objects=thesis_objects(["can", "case"]), planners=("default",), trials=2, scene_kind="clutter",
                  protocol="clear")
    runs = {("can", 0): ((True, True), 2, 2, "table cleared"), ("can", 1): ((True, False, False), 3, 1,
                                                                              "failed twice in a row"),
            ("case", 0): ((), 4, 0, "nothing to plan on"), ("case", 1): ((False, True, True, True), 3, 3,
                                                                          "table cleared")}
    results = []
    for r in _split_results(bench, {"default": {"can": 0, "case": 0}}):
        outcomes, objects, cleared, ended = runs[r.record.object, r.trial]
        results.append(BenchTrial(r.planner, r.trial, replace(r.record, outcomes=outcomes, detected=outcomes,
                                                              scene_objects=objects, cleared=cleared, ended=ended,
                                                              success=cleared == objects)))
    write_outputs(bench, results, tmp_path, wall_time=1.0)
    table = (tmp_path / "table.md").read_text()
    # 6 of 9 attempts lifted; 6 of 12 objects cleared; 9 attempts / 12 objects; 2 of 4 tables cleared
    assert "| default | all | 67 % (35–88) 6/9 | 50 % (25–75) 6/12 | 0.75 | 50 % (15–85) 2/4 |" in table
    assert "| default | 2 | 1 | 1 | 0 |" in table  # table cleared, nothing to plan on, failed twice, limit
    assert "False success: 0 of 9 attempts (0.0 %)." in table and "Protocol `clear`" in table
