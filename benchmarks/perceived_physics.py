"""Can a simulation of the object *as perceived* tell the planner's lifting candidates from its failing ones?

``benchmarks/candidate_pool.py`` found that the planner's own candidates hold a lifting pose far more
often than its plan lifts, and that no rule on the planner's costs picks them. A planner on a real robot
does not know the object's mesh, mass or frictions; what it has is the height map of one depth frame.
This executes each frame's pool twice with the bench's execution: on the true object (the bench's
outcome) and on a stand-in built from the plan's height map, and reports how well the second predicts
the first, and what a choice by it would lift.

The stand-in (:func:`perceived_object`): the target's height-map cells, pooled into ``--block`` x
``--block`` columns (a column kept where at least half its cells are the object's and seen), each a box
from the table to its highest reading; one free body, its mass ``--density`` times the columns' volume
(clipped to 0.02-1.2 kg), frictions 0.55 against the glove and 0.35 against the table (the YCB
materials' middle, :data:`contourgrasp.sim.ycb.MATERIALS`). The same hand, camera and grasp heights.
Single scenes only (their camera is the reference camera).

Usage::

    .venv/bin/python benchmarks/perceived_physics.py --objects ycb-train --seeds 0,1 [--density 300]
        [--block 3] [--per-class 2] [--workers 2] [--json FILE]
"""

import argparse
import collections
import time
import warnings

import mujoco
import numpy as np

import candidate_pool
import pose_oracle
from contourgrasp import pipeline
from contourgrasp.errors import InputError, NoFeasibleGrasp
from contourgrasp.io.planner_file import load_planner
from contourgrasp.sim import render, trial
from contourgrasp.sim.objects import ObjectSpec, Part
from contourgrasp.sim.scene import PARK_HEIGHT, Placement, Scene, _compile, mujoco_warnings, scene_xml
from contourgrasp.sim.ycb import object_names

#: Mass bounds of the stand-in, kg, and its frictions against the glove and the table.
MASS_RANGE, FRICTIONS = (0.02, 1.2), (0.55, 0.35)
#: Lowest reading a column keeps, m (the table's own noise is below it).
LOWEST = 0.002


def perceived_object(planned, camera, *, block: int, density: float) -> ObjectSpec:
    """The target of ``planned`` (a :class:`~contourgrasp.pipeline.PlannedFrame`) as box columns, world frame."""
    hm, metric = planned.height_map, planned.metric
    heights = np.where(hm.object, hm.heights, np.nan)
    x_axis = camera.to_world(metric.origin + metric.R_camera_plane[:, 0]) - camera.to_world(metric.origin)
    yaw = float(np.arctan2(x_axis[1], x_axis[0]))
    quat = (np.cos(yaw / 2), 0.0, 0.0, np.sin(yaw / 2))
    parts, volume = [], 0.0
    for i in range(0, heights.shape[0], block):
        for j in range(0, heights.shape[1], block):
            column = heights[i:i + block, j:j + block]
            seen = np.isfinite(column) & (np.nan_to_num(column) > LOWEST)
            if 2 * seen.sum() < column.size:
                continue
            x = hm.origin[0] + (j + column.shape[1] / 2) * hm.cell
            y = hm.origin[1] + (i + column.shape[0] / 2) * hm.cell
            base, top = (_world(hm, metric, camera, x, y, h) for h in (0.0, float(column[seen].max())))
            half = (column.shape[1] * hm.cell / 2, column.shape[0] * hm.cell / 2, max(top[2], 0.003) / 2)
            parts.append(Part("box", half, pos=(base[0], base[1], half[2]), quat=quat))
            volume += 8 * np.prod(half)
    mass = float(np.clip(density * volume, *MASS_RANGE))
    return ObjectSpec("perceived", tuple(parts), mass=mass, friction_hand=FRICTIONS[0], friction_table=FRICTIONS[1])


def _world(hm, metric, camera, x: float, y: float, height: float) -> np.ndarray:
    """(3,) float: the world point at planning (x, y), ``height`` above the table the height map fitted."""
    n = hm.table_normal
    z = (height - hm.table_offset - n[0] * x - n[1] * y) / n[2]
    return camera.to_world(metric.origin + metric.R_camera_plane @ np.array([x, y, z]))


def _settled(obj: ObjectSpec, like: Scene) -> tuple[Scene, np.ndarray]:
    """A scene of ``obj`` alone with ``like``'s hand and camera, settled, and its MuJoCo state."""
    placement = Placement(0.0, 0.0, 0.0)
    with mujoco_warnings():
        model = _compile(scene_xml(obj, like.hand, placement), like.hand)
    scene = Scene(model, mujoco.MjData(model), obj, like.hand, like.camera, placement)
    scene.set_hand(0.0, 0.0, PARK_HEIGHT, 0.0)
    scene.step(0.3)
    state = np.empty(mujoco.mj_stateSize(model, pose_oracle.STATE))
    mujoco.mj_getState(model, scene.data, state, pose_oracle.STATE)
    return scene, state


def _execute(scene, state, transform, approach_depth: float, tip: float):
    mujoco.mj_setState(scene.model, scene.data, state, pose_oracle.STATE)
    mujoco.mj_forward(scene.model, scene.data)
    return trial.execute_grasp(scene, transform, approach_depth, grasp_height=tip)


def frame(task: tuple) -> list[dict]:
    """One frame: the planned pose and its pool's classes, each executed on the true object and the stand-in."""
    warnings.simplefilter("ignore")
    name, seed, per_class, block, density = task
    _, hand = pose_oracle._hand(candidate_pool.HAND, None)
    options = load_planner("default").plan_options
    scene, state, _, _ = pose_oracle._scene(name, seed, "single", (), candidate_pool.HAND, None)
    rgb, depth = render(scene, noise=True, seed=seed)
    base = {"object": name, "seed": seed}
    try:
        planned = pipeline.plan_frame(rgb, depth, scene.camera.intrinsics, hand, **options)
    except (NoFeasibleGrasp, InputError):
        return [base | {"class": "no plan", "success": False, "predicted": False}]
    executed = [(planned.plan.pose, planned.grasp_height, "planned")]
    executed += candidate_pool._classes(planned, hand, options, candidate_pool.SCREENED, per_class)
    stand_in = perceived_object(planned, scene.camera, block=block, density=density)
    perceived, perceived_state = _settled(stand_in, scene)
    records = []
    for pose, tip, label in executed:
        depth_at = pipeline._palm_depth(planned.metric, planned.height_map, hand, pose, tip)
        transform = pipeline.hand_pose(planned.metric, pose, depth_at)
        real = _execute(scene, state, transform, planned.metric.approach_depth, tip)
        started = time.perf_counter()
        guess = _execute(perceived, perceived_state, transform, planned.metric.approach_depth, tip)
        records.append(base | {"class": label, "success": bool(real.success), "cause": real.cause,
                               "predicted": bool(guess.success), "predicted_cause": guess.cause,
                               "seconds": time.perf_counter() - started, "columns": len(stand_in.collision),
                               "mass": stand_in.mass})
    return records


def table(records: list[dict]) -> list[str]:
    """Markdown: the prediction's confusion over every executed pose, then what choosing by it lifts per frame."""
    executed = [r for r in records if r["class"] != "no plan"]
    confusion = collections.Counter((r["predicted"], r["success"]) for r in executed)
    frames = collections.defaultdict(list)
    for record in records:
        frames[record["object"], record["seed"]].append(record)
    chosen = [next((r for r in f if r["predicted"]), f[0]) for f in frames.values()]
    seconds = [r["seconds"] for r in executed]
    lines = [f"{len(frames)} frames, {len(executed)} executed poses (median {np.median(seconds):.1f} s each on "
             "the stand-in).", "", "| stand-in | true object lifts | fails |", "|---|---:|---:|"]
    for guess in (True, False):
        lines.append(f"| {'lifts' if guess else 'fails'} | {confusion[guess, True]} | {confusion[guess, False]} |")
    lines += ["", "| rule | frames lifted |", "|---|---:|",
              f"| the plan | {sum(f[0]['success'] for f in frames.values())} of {len(frames)} |",
              f"| the first pose the stand-in lifts (the plan, then the pool's classes; else the plan) | "
              f"{sum(r['success'] for r in chosen)} of {len(frames)} |",
              f"| some pose of the pool (its ceiling) | {sum(any(r['success'] for r in f) for f in frames.values())}"
              f" of {len(frames)} |"]
    return lines


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--objects", default="ycb-train", help="as the bench's --objects (sets or names)")
    parser.add_argument("--seeds", default="0,1", help="comma-separated scene seeds (the bench's trial t: seed t)")
    parser.add_argument("--per-class", type=int, default=2, help="distinct poses executed per class of the pool")
    parser.add_argument("--block", type=int, default=3, help="height-map cells per column side")
    parser.add_argument("--density", type=float, default=300.0, help="of the stand-in, kg/m^3")
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--json", default=None, help="write every executed pose's record here")
    args = parser.parse_args()
    names = [name for part in args.objects.split(",") for name in object_names(part)]
    tasks = [(name, int(seed), args.per_class, args.block, args.density)
             for name in names for seed in args.seeds.split(",")]
    records = candidate_pool.run_frames(frame, tasks, args.workers, args.json)
    print("\n".join(table(records)))


if __name__ == "__main__":
    main()
