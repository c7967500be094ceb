"""`contourgrasp bench` and its planners: outputs end to end, no-plan trials, determinism, bad input."""

import io
import json
import math

import numpy as np
import pytest

import contourgrasp
from contourgrasp.cli import main
from contourgrasp.hand import to_image
from contourgrasp.pipeline import plan_grasp
from contourgrasp.io.planner_file import load_planner
from contourgrasp.sim import NO_PLAN, Camera, ObjectSpec, Part, Workspace, build_scene, render
from contourgrasp.sim.bench import (Bench, BenchTrial, ablation_table, console_progress, run_bench, wilson_interval,
                                    write_outputs)
from contourgrasp.sim.planners import (ABLATION_STEPS, ablation_planners, camera_intrinsics, centroid_pose, perceive,
                                       random_feasible_pose, search_settings)
from contourgrasp.sim.trial import PUSHED, TrialRecord
from contourgrasp.synthesis import evaluate_poses

HAND = contourgrasp.load_hand("five-finger-linear")
REQUIRED = {"object", "planner", "trial", "seed", "success", "cause", "fingers_in_contact", "plan_time", "sim_time",
            "wall_time", "pose"}
OUTPUTS = ("table.md", "trials.json", "success.png", "trials.png")
TWO_PLANNERS = ["bench", "--objects", "can", "--trials", "2", "--planners", "paper,random"]


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


def test_object_too_large_is_no_feasible_plan(tmp_path):
    # A 0.8 m disc under a camera raised to 1 m (whole in view): every pose of the search region starts a
    # fingertip inside it (see test_sim_trial).
    platter = ObjectSpec("platter", (Part("cylinder", (0.40, 0.01), pos=(0.0, 0.0, 0.01)),), mass=3.0,
                         friction_hand=0.6, friction_table=0.4)
    bench = Bench(objects=(platter,), planners=("paper", "centroid-principal-axis"), trials=1,
                  camera=Camera(height=1.0), workspace=Workspace(0.0, 0.0))
    results = run_bench(bench)
    paper, centroid = (r.record for r in results)
    assert paper.cause == NO_PLAN and "larger than the hand" in paper.plan_error
    assert centroid.cause != NO_PLAN  # the baseline plans without the synthesis's constraints
    write_outputs(bench, results, tmp_path, wall_time=1.0)
    assert "| no feasible plan | 1 | 1 |" in (tmp_path / "table.md").read_text()


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


def test_unreadable_mesh_exits_2_and_writes_nothing(tmp_path, capsys):
    mesh = tmp_path / "broken.obj"
    mesh.write_bytes(b"\x00\x01 not a mesh")
    out = tmp_path / "out"
    code, err = run_cli(["bench", "--mesh", mesh, "--out", out], capsys)
    assert code == 2 and "broken.obj" in err and len(err.strip().splitlines()) == 1
    assert not out.exists()


def test_baselines_share_plan_grasps_perception():
    scene = build_scene("case", seed=3)
    rgb, depth = render(scene, noise=True, seed=3)
    camera = camera_intrinsics(scene.camera.intrinsics)
    segmentation, metric = perceive(rgb, depth, camera)
    reference = plan_grasp(rgb, depth, camera, HAND)
    np.testing.assert_array_equal(segmentation.mask, reference.segmentation.mask)
    np.testing.assert_array_equal(metric.contour_xy, reference.metric.contour_xy)
    assert metric.approach_depth == reference.metric.approach_depth


def test_centroid_pose_centres_the_hand_with_the_thumb_on_the_minor_axis():
    angle = math.radians(30)
    t = np.linspace(0, 2 * np.pi, 200, endpoint=False)
    ellipse = np.c_[0.06 * np.cos(t), 0.03 * np.sin(t)] @ np.array([[math.cos(angle), math.sin(angle)],
                                                                   [-math.sin(angle), math.cos(angle)]])
    ellipse += [0.1, -0.05]
    pose = centroid_pose(ellipse, HAND)
    np.testing.assert_allclose(to_image(HAND.grasp_centre[None], pose)[0], [0.1, -0.05], atol=1e-6)
    thumb = to_image(np.array([HAND.fingers[0].trajectory.closing_direction]), (0.0, 0.0, pose[2]))[0]
    minor = [-math.sin(angle), math.cos(angle)]
    assert abs(thumb @ minor) == pytest.approx(1.0, abs=1e-6)


def test_random_pose_is_feasible_and_seeded():
    contour = contourgrasp.example_contour("case")
    settings = search_settings("paper")
    poses = [random_feasible_pose(contour, HAND, np.random.default_rng(seed), settings) for seed in (0, 0, 1)]
    np.testing.assert_array_equal(poses[0], poses[1])
    assert not np.array_equal(poses[0], poses[2])
    model = contourgrasp.efd.fit(contourgrasp.efd.clean_polygon(contour), settings["harmonics"])
    assert evaluate_poses(model, HAND, np.array(poses), d_min=settings["grid"].d_min).feasible.all()


def test_progress_counts_every_trial():
    stream = io.StringIO()
    with console_progress(3, stream) as update:
        for label in "abc":
            update(label)
    assert "3/3" in stream.getvalue()


@pytest.mark.parametrize("wins, n, low, high", [(0, 10, 0.0, 0.2775), (10, 10, 0.7225, 1.0), (5, 10, 0.2366, 0.7634),
                                                (18, 20, 0.6990, 0.9721)])
def test_wilson_interval_matches_its_closed_form(wins, n, low, high):
    assert wilson_interval(wins, n) == pytest.approx((low, high), abs=1e-4)


def test_ablation_walks_from_paper_to_default_one_group_at_a_time():
    steps = ablation_planners()
    assert steps[0].name == "paper" and dict(steps[-1].options) == load_planner("default").plan_options
    groups = dict(ABLATION_STEPS)
    for before, after in zip(steps, steps[1:]):
        changed = {k for k in dict(before.options) | dict(after.options)
                   if dict(before.options).get(k) != dict(after.options).get(k)}
        step = after.name.rsplit("+", 1)[1]
        assert changed and (step == "other" or changed <= set(groups[step]))


def test_ablation_table_counts_rates_and_causes():
    steps = [p.name for p in ablation_planners()]
    ran = (*steps[:-1], "default")
    bench = Bench(objects=(contourgrasp.sim.objects.object_spec("can"),), planners=ran, trials=2)
    record = dict(object="can", seed=0, fingers_in_contact=(), first_contact=(), push=0.0, lift=0.0, hold_drift=0.0,
                  pose=None, approach_depth=None, plan_error=None, sim_time=1.0, plan_time=0.1, wall_time=1.0)
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
    code, err = run_cli(["bench", "--objects", "case", "--trials", "1", "--planners", str(planner), "--out", out],
                        capsys)
    assert code == 0, err
    assert f"- `{planner}`: `plan_grasp` with xy_step=0.05, yaw_step=5.72958°" in (out / "table.md").read_text()


def test_mesh_names_are_distinct_and_never_a_thesis_objects():
    from contourgrasp.cli import _mesh_names

    paths = ["a/YcbMustardBottle/model.obj", "b/YcbGelatinBox/model.obj", "robosuite/bottle.obj", "x/mug.obj"]
    assert _mesh_names(paths) == ["YcbMustardBottle", "YcbGelatinBox", "robosuite-bottle", "mug"]
