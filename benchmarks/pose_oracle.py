"""The best any top-down pose can do: a brute-force search of executed poses in the simulation, per object.

The bench asks whether a planner's one pose lifts an object. This asks whether *any* pose of a grid
does, with the same simulated hand and the same execution (:func:`contourgrasp.sim.trial.execute_grasp`:
descent, closing, lift, hold, the same success rule), the object's true position known and no picture
taken. An object some pose lifts is within the hand's reach, and a planner that fails it misses
its aim; an object no pose of the grid lifts is probably out of reach of every planner that executes
one top-down pose with this hand, whatever it sees (probably: a pose that works can fall between the
grid's points).

One settled scene per object and seed (``--seeds``, default 0): the object alone on the table, or the
bench's clutter or bin scene of that seed (``--scene``, ``--pool``: the set its neighbours come from,
the object's split in the bench), where a hit of a neighbour or a wall fails the pose as it fails a
trial. A single scene's placement only moves the object on the table and turns it about the
vertical, which a top-down grasp from every yaw does not distinguish. The grid:
the hand's yaw all the way round (``--yaws`` steps); the centre of the area its fingertips sweep
(the centroid of the convex hull of their open and closed points, hand frame) on a square of
offsets around the object's centre of mass (``--offsets`` per side, ``--step`` apart); the grasp
height (the open hand's lowest fingertip above the table, as a planner gives it) at the lowest the
planner allows (:func:`~contourgrasp.synthesis.grasp_height.open_floor`) and at the ``--heights``
fractions of the object's height that lie above that. The scene's MuJoCo state is restored before
each pose.

Usage::

    .venv/bin/python benchmarks/pose_oracle.py --objects ycb-train [--hand five-finger-linear | --hand-model inspire]
        [--scene clutter|bin --pool ycb-train --seeds 0,1,2] [--workers 2] [--json FILE]

Prints a markdown table, a row per object as it is done: poses, lifted poses, the grasp heights that
lifted, the failures by cause, and the seconds since the start.
"""

import argparse
import collections
import functools
import itertools
import json
import math
import multiprocessing
import time
import warnings
from pathlib import Path
from typing import NamedTuple

import cv2
import mujoco
import numpy as np

from contourgrasp.errors import ContourGraspError
from contourgrasp.hand import rotation
from contourgrasp.io.hand_file import load_hand
from contourgrasp.sim import trial
from contourgrasp.sim.bench.config import SHORT_CAUSES
from contourgrasp.sim.model_mount import mount_model
from contourgrasp.sim.ycb import load_object, object_names
from contourgrasp.synthesis.grasp_height import open_floor

STATE = mujoco.mjtState.mjSTATE_INTEGRATION


@functools.lru_cache(maxsize=2)
def _hand(hand: str, hand_model: str | None):
    if hand_model is None:
        return hand, load_hand(hand)
    mounted = mount_model(hand_model)
    return mounted, mounted.hand


class Task(NamedTuple):
    """One yaw of the grid on one scene."""

    name: str
    seed: int
    scene_kind: str
    pool: tuple[str, ...]
    hand: str
    hand_model: str | None
    yaw: float
    offsets: tuple[tuple[float, float], ...]
    fractions: tuple[float, ...]


class Settled(NamedTuple):
    """A settled scene, its MuJoCo state, and what the grid is laid out from, read in that state."""

    scene: object
    state: np.ndarray
    top: float  # the object's top above the table (the bin's floor), m
    centre: np.ndarray  # (2,) its centre of mass in the reference camera's frame, m


@functools.lru_cache(maxsize=1)
def _scene(name: str, seed: int, scene_kind: str, pool: tuple[str, ...], hand: str, hand_model: str | None):
    simulated, _ = _hand(hand, hand_model)
    scene = trial.trial_scene(load_object(name), seed=seed, scene_kind=scene_kind,
                              pool=[load_object(n) for n in pool], hand=simulated)
    state = np.empty(mujoco.mj_stateSize(scene.model, STATE))
    mujoco.mj_getState(scene.model, scene.data, state, STATE)
    return Settled(scene, state, float(scene.object_points()[:, 2].max()),
                   scene.camera.from_world(scene.object_com()[None])[0][:2])


def heights(planned_hand, object_height: float, fractions) -> list[float]:
    """The grid's grasp heights, m: the planner's floor, then the fractions of the object's height above it."""
    floor = open_floor(planned_hand)
    return [floor] + [f * object_height for f in fractions if f * object_height > floor]


def swept_centre(planned_hand) -> np.ndarray:
    """(2,) float: the centroid of the convex hull of the fingertips' open and closed points, hand frame."""
    hull = cv2.convexHull(np.vstack([planned_hand.starts, planned_hand.ends]).astype(np.float32))
    moments = cv2.moments(hull)
    return np.array([moments["m10"], moments["m01"]]) / moments["m00"]


def run_yaw(task: Task) -> tuple[float, list[dict]]:
    """Every offset and height of the grid at one yaw of the hand: the object's height (m) and each pose's outcome."""
    warnings.simplefilter("ignore")
    scene, state, top, centre = _scene(task.name, task.seed, task.scene_kind, task.pool, task.hand, task.hand_model)
    _, planned = _hand(task.hand, task.hand_model)
    model, data, yaw = scene.model, scene.data, task.yaw
    turned = rotation(yaw) @ swept_centre(planned)
    rows = []
    for (dx, dy), height in itertools.product(task.offsets, heights(planned, top, task.fractions)):
        x, y = centre + (dx, dy) - turned
        mujoco.mj_setState(model, data, state, STATE)
        mujoco.mj_forward(model, data)
        outcome = trial.execute_grasp(scene, trial.pose_matrix(x, y, yaw), scene.camera.height - top,
                                      grasp_height=height)
        rows.append({"yaw": yaw, "dx": dx, "dy": dy, "grasp_height": height, "success": outcome.success,
                     "cause": outcome.cause})
    return top, rows


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--objects", default="ycb-train", help="as the bench's --objects")
    parser.add_argument("--hand", default="five-finger-linear", help="preset name or hand TOML file")
    parser.add_argument("--hand-model", default=None, help="a bundled model (inspire, jaco-three-finger)")
    parser.add_argument("--yaws", type=int, default=12, help="yaw steps all the way round")
    parser.add_argument("--offsets", type=int, default=9, help="grasp-centre offsets per side of the square")
    parser.add_argument("--step", type=float, default=0.015, help="offset spacing, m")
    parser.add_argument("--heights", default="0.2,0.35,0.5,0.65",
                        help="grasp heights besides the floor, fractions of the object's height")
    parser.add_argument("--scene", choices=("single", "clutter", "bin"), default="single")
    parser.add_argument("--seeds", default="0", help="comma-separated scene seeds (the bench's trial t: seed t)")
    parser.add_argument("--pool", default=None, help="with --scene clutter|bin: the object set the neighbours "
                                                     "come from (in the bench: the target's split)")
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--json", default=None, help="write every pose's outcome here")
    args = parser.parse_args()
    if args.scene != "single" and args.pool is None:
        parser.error("--scene clutter|bin needs --pool, e.g. ycb-train")
    if args.scene != "single" and args.hand_model is not None:
        parser.error("the clutter and bin scenes simulate the hand files' hands, not --hand-model")
    try:
        names = object_names(args.objects)
        pools = {name: _pool(args.pool, name) for name in names}
        seeds = [int(seed) for seed in args.seeds.split(",")]
        fractions = tuple(float(f) for f in args.heights.split(","))
    except (ContourGraspError, ValueError) as err:
        parser.error(str(err))
    spokes = (np.arange(args.offsets) - (args.offsets - 1) / 2) * args.step
    offsets = [(float(dx), float(dy)) for dx in spokes for dy in spokes]
    tasks = [Task(name, seed, args.scene, pools[name], args.hand, args.hand_model, float(yaw),
                  tuple(offsets), fractions)
             for name in names for seed in seeds for yaw in np.arange(args.yaws) * 2 * math.pi / args.yaws]
    print(f"hand: {args.hand_model or args.hand}; {len(offsets)} offsets, {args.yaws} yaws, up to "
          f"{len(fractions) + 1} grasp heights per object\n")
    print("| object | height, mm | poses | lifted | share | lifting grasp heights, mm | failures by cause | s |\n"
          "|---|---:|---:|---:|---:|---|---|---:|", flush=True)
    started = time.perf_counter()
    by_object, reachable = {}, 0
    with multiprocessing.get_context("spawn").Pool(args.workers) as pool:
        for task, (top, rows) in zip(tasks, pool.imap(run_yaw, tasks)):
            key = task.name if len(seeds) == 1 and args.scene == "single" else f"{task.name} (seed {task.seed})"
            by_object.setdefault(key, []).extend(rows)
            if len(by_object[key]) == len(rows) * args.yaws:
                reachable += _print_row(key, top, by_object[key], time.perf_counter() - started)
    print(f"\nobjects with a lifting pose: {reachable} of {len(by_object)}")
    if args.json:
        partial = Path(f"{args.json}.partial")
        partial.write_text(json.dumps(by_object))
        partial.replace(args.json)


def _print_row(name: str, top: float, rows: list[dict], elapsed: float) -> bool:
    lifted = [r for r in rows if r["success"]]
    causes = collections.Counter(SHORT_CAUSES[r["cause"]] for r in rows if not r["success"])
    lifting = sorted({round(1000 * r["grasp_height"]) for r in lifted})
    print(f"| {name.removeprefix('ycb:')} | {1000 * top:.0f} | {len(rows)} | {len(lifted)} | "
          f"{100 * len(lifted) / len(rows):.1f} % | {', '.join(map(str, lifting)) or '-'} | "
          + ", ".join(f"{c} {n}" for c, n in causes.most_common()) + f" | {elapsed:.0f} |", flush=True)
    return bool(lifted)


def _pool(pool: str | None, target: str) -> tuple[str, ...]:
    """The neighbours' object names: the set's other members (the target itself when it is alone)."""
    if pool is None:
        return ()
    others = tuple(n for n in object_names(pool) if n != target)
    return others or (target,)


if __name__ == "__main__":
    main()
