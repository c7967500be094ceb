"""Throughput of ``contourgrasp bench``: trials per second in this process, in 2 worker processes and on a local Ray,
and the cost of one trial split into scene (build and settle), render, plan and physics (execute).

    .venv/bin/python benchmarks/bench_throughput.py [--objects can,case,bottle] [--trials 4] [--planners default]

Each runner runs the same bench from a cold start (its workers' start-up and imports included), so the
rates are what a user sees; the split repeats the serial trials with each stage timed alone.
"""

from __future__ import annotations

import argparse
import os
import statistics
import time

from contourgrasp.errors import InputError, NoFeasibleGrasp
from contourgrasp.sim import bench
from contourgrasp.sim.planners import make_planner
from contourgrasp.sim.render import render
from contourgrasp.sim.scene import build_scene
from contourgrasp.sim.trial import NO_PLAN, execute_grasp


def rate(setup: bench.Bench, **runner) -> tuple[float, tuple]:
    """Trials per second of the whole bench with ``runner`` (executor options), and its trials."""
    started = time.perf_counter()
    with bench.executor(setup, **runner) as run:
        results = bench.run_bench(setup, execute=run)
    return setup.size / (time.perf_counter() - started), results


def stages(setup: bench.Bench) -> dict[str, list[float]]:
    """Seconds per stage of every trial of ``setup``, run one after another."""
    spent = {"scene": [], "render": [], "plan": [], "physics": []}
    for planner_name, index, trial in setup.tasks():
        seed = setup.seed + trial
        planner = make_planner(planner_name, setup.hand, seed=seed)
        t0 = time.perf_counter()
        scene = build_scene(setup.objects[index], seed=seed, hand=setup.hand, camera=setup.camera,
                            workspace=setup.workspace)
        t1 = time.perf_counter()
        rgb, depth = render(scene, sensor=setup.sensor, seed=seed)
        t2 = time.perf_counter()
        try:  # as run_trial calls a planner: the pose, the approach depth and, planned, the grasp height
            transform, approach_depth, *height = planner(rgb, depth, setup.camera.intrinsics)
        except (NoFeasibleGrasp, InputError):  # no plan: no physics to time
            transform = None
        t3 = time.perf_counter()
        if transform is not None:
            execute_grasp(scene, transform, approach_depth, grasp_height=height[0] if height else None)
        t4 = time.perf_counter()
        for stage, seconds in zip(spent, (t1 - t0, t2 - t1, t3 - t2, t4 - t3)):
            spent[stage].append(seconds)
    return spent


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--objects", default="can,case,bottle")
    parser.add_argument("--trials", type=int, default=4)
    parser.add_argument("--planners", default="default")
    args = parser.parse_args()
    objects, _ = bench.resolve_objects(args.objects)
    setup = bench.Bench(objects=objects, planners=tuple(args.planners.split(",")), trials=args.trials)
    print(f"{setup.size} trials ({args.objects} x {args.trials} x {args.planners}), {bench.cores()} cores, "
          f"load average {os.getloadavg()[0]:.1f} before the run")
    print("| runner | trials/s | s per trial |\n| --- | ---: | ---: |")
    serial_rate, reference = rate(setup, workers=1)
    runs = [("1 worker (this process)", serial_rate, reference), ("2 worker processes", *rate(setup, workers=2))]
    try:
        import ray  # noqa: F401
        runs.append(("local Ray, 2 CPUs", *rate(setup, workers=2, ray=True)))
    except ImportError:
        print("(ray not installed: pip install 'contourgrasp[cluster]')")
    for name, trials_per_second, results in runs:
        same = [r.record for r in results] == [r.record for r in reference]
        print(f"| {name} | {trials_per_second:.2f} | {1 / trials_per_second:.2f} |" + ("" if same else " DIFFERS"))
    spent = stages(setup)
    total = sum(map(sum, spent.values()))
    print("\n| stage | median s | share |\n| --- | ---: | ---: |")
    for stage, seconds in spent.items():
        print(f"| {stage} | {statistics.median(seconds):.3f} | {100 * sum(seconds) / total:.0f} % |")
    no_plan = sum(r.record.cause == NO_PLAN for r in reference)
    print(f"\n{len(spent['scene'])} trials ({no_plan} without a plan); mean {total / len(spent['scene']):.2f} s a trial "
          f"(scene = build and settle, physics = descend, close, lift, hold)")


if __name__ == "__main__":
    main()
