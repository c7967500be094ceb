"""Which top-down poses lift a low object, and which of them the planner's model can plan (the low-object rule).

On one settled scene (the bench's trial scene of ``--seed``, the object alone on the table) a grid of
poses is executed in MuJoCo at the lowest grasp height the planner allows
(:func:`~contourgrasp.synthesis.grasp_height.open_floor`), as ``benchmarks/pose_oracle.py`` executes
its grid: the centre of the area the fingertips sweep on a square of offsets around the object's
centre of mass, the hand's yaw all the way round. Each pose is also evaluated by the planner's inner
problem (:func:`~contourgrasp.synthesis.evaluate_poses`) on the outline ``default`` perceives in the
same scene's rendered frame, under two models:

* **points**: the thesis's point fingertips on the outline seen, the hand's ``min_touching`` fingers;
* **pinch**: the low-object rule (``synthesis.search(low_object=True)``): the fingertips as balls (the
  outline grown by the fingers' smallest radius), two touching fingers, no ``miss_penalty``.

Prints, per model, the poses it calls feasible, how many of those lift, and how many of its ten
cheapest feasible poses lift (the centring term included, as in ``default``).

``--replay DIR`` instead re-executes the poses a bench run planned for the object (``DIR/trials.json``,
``contourgrasp bench --out DIR``) at the floor height and at their planned height: whether the height
is what fails them.

Usage::

    .venv/bin/python benchmarks/pinch_poses.py --object ycb:073-a_lego_duplo [--seed 0] [--workers 2]
    .venv/bin/python benchmarks/pinch_poses.py --object ycb:073-a_lego_duplo --replay bench-output
"""

import argparse
import json
import math
import multiprocessing
import warnings
from dataclasses import replace
from pathlib import Path

import mujoco
import numpy as np

import pose_oracle
from contourgrasp import contour, load_hand, pipeline
from contourgrasp.hand import rotation
from contourgrasp.io.planner_file import load_planner
from contourgrasp.sim import render, trial
from contourgrasp.sim.ycb import load_object
from contourgrasp.synthesis import evaluate_poses
from contourgrasp.synthesis.grasp_height import open_floor
from contourgrasp.synthesis.outer import _fewest_touching, _grown

HAND = "five-finger-linear"


def run_yaw(task: tuple[str, int, float, int, float]) -> list[dict]:
    """Every offset of the grid at one yaw, at the floor height: the pose (camera frame) and whether it lifted."""
    warnings.simplefilter("ignore")
    name, seed, yaw, offsets, step = task
    scene, state, top, centre = pose_oracle._scene(name, seed, "single", (), HAND, None)
    _, planned = pose_oracle._hand(HAND, None)
    turned = rotation(yaw) @ pose_oracle.swept_centre(planned)
    spokes = (np.arange(offsets) - (offsets - 1) / 2) * step
    rows = []
    for dx in spokes:
        for dy in spokes:
            x, y = centre + (dx, dy) - turned
            outcome = _execute(scene, state, top, x, y, yaw, open_floor(planned))
            rows.append({"x": float(x), "y": float(y), "yaw": float(yaw), "success": bool(outcome.success)})
    return rows


def _execute(scene, state, top, x, y, yaw, height):
    mujoco.mj_setState(scene.model, scene.data, state, pose_oracle.STATE)
    mujoco.mj_forward(scene.model, scene.data)
    return trial.execute_grasp(scene, trial.pose_matrix(x, y, yaw), scene.camera.height - top, grasp_height=height)


def planning_frame_poses(metric, rows) -> np.ndarray:
    """(n, 3) float: the camera-frame poses of ``rows`` in ``metric``'s planning frame (top-down camera)."""
    R, origin = metric.R_camera_plane, metric.origin
    xy = (np.array([[r["x"], r["y"], 0.0] for r in rows]) - origin) @ R[:, :2]
    yaw = np.array([r["yaw"] for r in rows])
    axis = np.stack([np.cos(yaw), np.sin(yaw), np.zeros_like(yaw)], axis=1) @ R[:, :2]
    return np.column_stack([xy, np.arctan2(axis[:, 1], axis[:, 0])])


def models(name: str, seed: int, poses: np.ndarray):
    """{model: PoseEvaluation} of ``poses`` on the outline ``default`` perceives in the scene's frame."""
    hand = load_hand(HAND)
    options = load_planner("default").plan_options
    scene = trial.trial_scene(load_object(name), seed=seed)
    rgb, depth = render(scene, noise=True, seed=seed)
    frame = pipeline.plan_frame(rgb, depth, scene.camera.intrinsics, hand, **options)
    plan = frame.plan
    grown = _grown(plan.contour, min(f.radius for f in hand.fingers))  # as the low-object rule grows it
    fitted = {"points": (plan.efd, hand),
              "pinch": (contour.fit(grown, options["harmonics"], validate=False),
                        replace(hand, min_touching=_fewest_touching(hand), miss_penalty=0.0))}
    return {label: evaluate_poses(model, model_hand, planning_frame_poses(frame.metric, poses),
                                  curvature=plan.curvature_mode, d_min=plan.grid.d_min, safeguards=plan.safeguards)
            for label, (model, model_hand) in fitted.items()}


def replay(name: str, directory: Path) -> None:
    trials = json.loads((directory / "trials.json").read_text())
    trials = trials["trials"] if isinstance(trials, dict) else trials
    _, planned = pose_oracle._hand(HAND, None)
    floor = open_floor(planned)
    print(f"| seed | bench | at the floor, {1000 * floor:.1f} mm | at the planned height |\n|---:|---|---|---|")
    for record in trials:
        if record["object"] != name.removeprefix("ycb:") or record["pose"] is None:
            continue
        pose_oracle._scene.cache_clear()
        scene, state, top, _ = pose_oracle._scene(name, record["seed"], "single", (), HAND, None)
        pose = record["pose"]
        cells = []
        for height in (floor, record["grasp_height"]):
            outcome = _execute(scene, state, top, pose["x"], pose["y"], pose["yaw"], height)
            cells.append(f"{'lifted' if outcome.success else outcome.cause} ({1000 * height:.1f} mm)")
        print(f"| {record['seed']} | {'lifted' if record['success'] else record['cause']} | {cells[0]} | {cells[1]} |")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--object", required=True, help="a bench object name, e.g. ycb:073-a_lego_duplo")
    parser.add_argument("--seed", type=int, default=0, help="the bench's trial seed of the scene")
    parser.add_argument("--offsets", type=int, default=13, help="offsets per side of the square")
    parser.add_argument("--step", type=float, default=0.01, help="offset spacing, m")
    parser.add_argument("--yaws", type=int, default=24, help="yaw steps all the way round")
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--replay", type=Path, default=None, help="a bench run's --out directory")
    args = parser.parse_args()
    if args.replay is not None:
        replay(args.object, args.replay)
        return
    tasks = [(args.object, args.seed, float(yaw), args.offsets, args.step)
             for yaw in np.arange(args.yaws) * 2 * math.pi / args.yaws]
    with multiprocessing.get_context("spawn").Pool(args.workers) as pool:
        rows = [row for rows in pool.map(run_yaw, tasks) for row in rows]
    lifted = np.array([row["success"] for row in rows])
    print(f"{args.object}, seed {args.seed}: {len(rows)} poses at the floor height, {lifted.sum()} lift\n")
    print("| model | feasible | of which lift | of its 10 cheapest, lift |\n|---|---:|---:|---:|")
    for label, evaluation in models(args.object, args.seed, rows).items():
        feasible = np.flatnonzero(evaluation.feasible)
        cheapest = feasible[np.argsort(evaluation.cost[feasible], kind="stable")[:10]]
        print(f"| {label} | {len(feasible)} | {lifted[feasible].sum()} | {lifted[cheapest].sum()} of {len(cheapest)} |")


if __name__ == "__main__":
    main()
