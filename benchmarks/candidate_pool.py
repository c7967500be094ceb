"""The planner's own candidates, executed: how far a better choice among them could take it.

The pose oracle (``benchmarks/pose_oracle.py``) asks what *any* top-down pose of a grid can lift. This
asks a narrower question: what the poses the planner itself considers can lift -- whether a better
ranking of its candidates would close the gap to a target, or whether the poses that would are not
among them.

Per frame (the bench's trial scene of an object and seed, rendered with depth noise, planned by
``default`` as the bench plans it):

1. The pool. The grid is screened on the outline the plan was made on (the outline seen, the
   cross-section, or the outline grown by the fingertips' radius: the plan's own EFD) with the fewest
   touching fingers the small-object rule allows; the ``--screened`` cheapest feasible poses, and the
   ``--screened`` cheapest of those whose screened contacts nearly balance (where the planner looks
   first: within the hand's ``max_imbalance`` plus ``tolerances.IMBALANCE_SCREEN``), are evaluated exactly under ``default``'s safeguards except the squeeze's balance (force closure and
   the centring cost kept; the imbalance computed, not required); those whose open hand descends clear
   to a grasp height the planner accepts (``descent_feasible`` at the planned height, raised where a
   body needs it, up to the highest allowed) stay.
2. The classes. The pool is split by touching fingers (2 to 5) and balance (imbalance within the
   hand's ``max_imbalance`` or not); the ``--per-class`` cheapest distinct poses of each class
   (``distinct_best``: no two grid neighbours) are executed in MuJoCo with the bench's execution,
   from the same settled state, at their grasp height, and so is the planned pose.

The planned pose's outcome is the bench trial's (same scene, same pose, same height): on 230 frames
measured, trial for trial the same. The frames where some executed pose lifts are the pool's ceiling:
what a perfect choice among these candidates would reach.

Usage::

    .venv/bin/python benchmarks/candidate_pool.py --objects thesis,ycb-train --seeds 0,1,2,3,4 [--workers 2]
        [--hand-model inspire] [--json FILE]

Prints a markdown table per object set given, then the whole: frames, the plan's successes, the pool's
ceiling, per class how often its cheapest pose lifts (of the frames that have the class) and all of
its executed poses, and what a few rules of choice among the pool would lift (:data:`RULES`).
"""

import argparse
import collections
import json
import multiprocessing
import time
import warnings
from dataclasses import replace

import mujoco
import numpy as np

import pose_oracle
from contourgrasp import pipeline
from contourgrasp import tolerances as tol
from contourgrasp.errors import InputError, NoFeasibleGrasp
from contourgrasp.io.planner_file import load_planner
from contourgrasp.sim import render, trial
from contourgrasp.sim.ycb import object_names
from contourgrasp.synthesis import evaluate_poses, screen_grid
from contourgrasp.synthesis.descent import DESCENT_MARGIN, _raised, descent_feasible
from contourgrasp.synthesis.grid import distinct_best
from contourgrasp.synthesis.outer import _fewest_touching, _screened_share
from contourgrasp.synthesis.safeguards import Safeguards

HAND = "five-finger-linear"
#: The cheapest screened poses evaluated exactly per frame (``--screened``'s default).
SCREENED = 1500
#: Just below 1: the safeguards compute each pose's imbalance without requiring any balance.
UNBALANCED = 1.0 - 1e-9


def frame(task: tuple[str, int, int, int, str | None]) -> list[dict]:
    """The planned pose and the executed classes of one frame's pool, one record each."""
    warnings.simplefilter("ignore")
    name, seed, screened, per_class, hand_model = task
    _, hand = pose_oracle._hand(HAND, hand_model)
    options = load_planner("default").plan_options
    scene, state, _, _ = pose_oracle._scene(name, seed, "single", (), HAND, hand_model)
    rgb, depth = render(scene, noise=True, seed=seed)
    base = {"object": name, "seed": seed}
    try:
        planned = pipeline.plan_frame(rgb, depth, scene.camera.intrinsics, hand, **options)
    except (NoFeasibleGrasp, InputError) as err:  # as a bench trial: a frame without a plan is reported
        return [base | {"class": "no plan", "success": False, "cause": str(err).splitlines()[0][:200]}]
    plan, heights = planned.plan, planned.height_map
    fewest, guards = _pool_search(plan, hand, options)
    executed = [(plan.pose, planned.grasp_height, "planned")] + _classes(planned, hand, options, screened, per_class)
    exact = evaluate_poses(plan.efd, fewest, np.array([pose for pose, _, _ in executed]),
                           curvature=plan.curvature_mode, d_min=plan.grid.d_min, safeguards=guards)
    records = []
    for k, (pose, tip, label) in enumerate(executed):
        features = {"cost": float(exact.cost[k]), "curvature_cost": float(exact.cost_curvature[k]),
                    "imbalance": float(exact.imbalance[k]), "touching": int(exact.touching[k].sum())}
        mujoco.mj_setState(scene.model, scene.data, state, pose_oracle.STATE)
        mujoco.mj_forward(scene.model, scene.data)
        depth_at = pipeline._palm_depth(planned.metric, heights, hand, pose, tip)
        outcome = trial.execute_grasp(scene, pipeline.hand_pose(planned.metric, pose, depth_at),
                                      planned.metric.approach_depth, grasp_height=tip)
        records.append(base | features | {"class": label, "pose": [float(v) for v in pose], "grasp_height": tip,
                                          "success": bool(outcome.success), "cause": outcome.cause})
    return records


def _pool_search(plan, hand, options) -> tuple:
    """The hand (the fewest touching fingers) and safeguards (``default``'s, the balance computed, not required)
    the pool is searched and its poses are evaluated with."""
    guards = Safeguards(require_closure=options["require_closure"], friction=options["friction"],
                        centring_gain=options["centring_gain"], max_imbalance=UNBALANCED)
    return replace(plan.hand, min_touching=_fewest_touching(hand)), guards


def _classes(planned, hand, options, screened: int, per_class: int) -> list[tuple]:
    """(pose, grasp height, class) of the cheapest distinct poses of each class of the frame's pool."""
    plan, heights = planned.plan, planned.height_map
    fewest, guards = _pool_search(plan, hand, options)
    screen = screen_grid(plan.efd, fewest, plan.grid, curvature=plan.curvature_mode,
                         centring_gain=options["centring_gain"])
    feasible = np.flatnonzero(screen.feasible)
    feasible = feasible[np.argsort(screen.cost[feasible], kind="stable")]
    share = _screened_share(plan.efd, screen, np.full(len(screen.poses), np.nan), feasible)
    near = feasible[share <= hand.max_imbalance + tol.IMBALANCE_SCREEN]  # where the planner looks first
    cheapest = np.union1d(feasible[:screened], near[:screened])
    exact = evaluate_poses(plan.efd, fewest, screen.poses[cheapest], curvature=plan.curvature_mode,
                           d_min=plan.grid.d_min, safeguards=guards)
    rows = np.flatnonzero(exact.feasible)
    lowest, highest = pipeline._grasp_height(hand, heights, options["descent"], options["grasp_height"])
    tips = np.full(len(exact.poses), np.inf)
    tips[rows] = _raised(descent_feasible(hand, heights, exact.poses[rows], lowest, margin=DESCENT_MARGIN))
    descends = tips <= highest
    touching = exact.touching.sum(axis=1)
    balanced = exact.imbalance <= hand.max_imbalance
    picks = []
    for count in range(2, len(hand.fingers) + 1):
        for balance in (True, False):
            members = exact.feasible & descends & (touching == count) & (balanced == balance)
            label = f"{count} fingers, {'balanced' if balance else 'unbalanced'}"
            picks += [(exact.poses[i], float(tips[i]), label)
                      for i in distinct_best(replace(exact, feasible=members), plan.grid, per_class)]
    return picks


def table(records: list[dict]) -> list[str]:
    """Markdown: frames, the plan's successes, the pool's ceiling, then per class its cheapest pose's rate and all."""
    frames = collections.defaultdict(list)
    for record in records:
        frames[record["object"], record["seed"]].append(record)
    plan = sum(r["success"] for f in frames.values() for r in f if r["class"] == "planned")
    ceiling = sum(any(r["success"] for r in f) for f in frames.values())
    lines = [f"{len(frames)} frames: the plan lifts {plan}, some pose of the pool {ceiling}.", "",
             "| class | its cheapest pose lifts | all its executed poses lift |", "|---|---:|---:|"]
    classes = sorted({r["class"] for r in records} - {"planned", "no plan"})
    for label in classes:
        firsts = [next(r for r in f if r["class"] == label) for f in frames.values() if any(r["class"] == label for r in f)]
        every = [r for r in records if r["class"] == label]
        lines.append(f"| {label} | {sum(r['success'] for r in firsts)} of {len(firsts)} | "
                     f"{sum(r['success'] for r in every)} of {len(every)} |")
    lines += ["", "| rule: the pose it picks from the pool (the plan's where the pool has none) | lifts |", "|---|---:|"]
    for label, rule in RULES.items():
        lines.append(f"| {label} | {sum(rule(f)['success'] for f in frames.values())} of {len(frames)} |")
    return lines


def _first_of(*classes):
    """The rule picking the cheapest pose of the first of ``classes`` the frame's pool has, else the plan."""
    def rule(records):
        for label in classes:
            for r in records:
                if r["class"] == label:
                    return r
        return records[0]
    return rule


def _least(key, *, with_plan: bool = False):
    """The rule picking the pool's pose (or, ``with_plan``, the pool's or the plan's) least in ``key(record)``
    (the frame's only record where its pool is empty, or it had no plan)."""
    return lambda records: min(records[0 if with_plan else 1:] or records[:1], key=key)


#: Rules of choice among a frame's records (the planned pose first): the plan's, then alternatives.
RULES = {
    "the plan": lambda records: records[0],
    "balanced first, 4 then 3 then 2 fingers (the planner's order)": _first_of(
        *(f"{n} fingers, balanced" for n in (4, 3, 2))),
    "balanced first, 2 then 3 then 4 fingers": _first_of(*(f"{n} fingers, balanced" for n in (2, 3, 4))),
    "the cheapest of any class": _least(lambda r: r.get("cost", np.inf)),
    "the least imbalance": _least(lambda r: r.get("imbalance", np.inf)),
    "the plan's or the pool's least curvature cost + 1000 x imbalance": _least(
        lambda r: r.get("curvature_cost", np.inf) + 1000 * r.get("imbalance", np.inf), with_plan=True),
}


def run_frames(frame_records, tasks: list, workers: int, json_path: str | None) -> list[dict]:
    """Every task's records (``frame_records(task) -> list of dict``) on ``workers`` processes, in task order,
    written to ``json_path`` when given; prints the time taken."""
    started = time.perf_counter()
    with multiprocessing.get_context("spawn").Pool(workers) as pool:
        records = [r for rows in pool.imap(frame_records, tasks) for r in rows]
    if json_path:
        with open(json_path, "w") as out:
            json.dump(records, out)
    print(f"{len(tasks)} frames in {time.perf_counter() - started:.0f} s\n")
    return records


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--objects", default="ycb-train", help="as the bench's --objects (sets or names)")
    parser.add_argument("--seeds", default="0,1,2,3,4", help="comma-separated scene seeds (the bench's trial t: seed t)")
    parser.add_argument("--screened", type=int, default=SCREENED, help="cheapest screened poses evaluated exactly")
    parser.add_argument("--per-class", type=int, default=3, help="distinct poses executed per class")
    parser.add_argument("--hand-model", default=None, help="a bundled model (inspire, jaco-three-finger), "
                        "simulated as itself and planned with its derived hand file, as the bench's --hand-model")
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--json", default=None, help="write every executed pose's record here")
    args = parser.parse_args()
    sets = {part: object_names(part) for part in args.objects.split(",")}
    seeds = [int(s) for s in args.seeds.split(",")]
    tasks = [(name, seed, args.screened, args.per_class, args.hand_model)
             for names in sets.values() for name in names for seed in seeds]
    records = run_frames(frame, tasks, args.workers, args.json)
    for part, names in sets.items():
        print(f"## {part}\n")
        print("\n".join(table([r for r in records if r["object"] in names])) + "\n")
    if len(sets) > 1:
        print("## all\n\n" + "\n".join(table(records)))


if __name__ == "__main__":
    main()
