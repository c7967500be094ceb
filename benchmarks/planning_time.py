"""Planning time per frame (the target: under 100 ms): `plan_frame` on simulated frames, per planner.

One simulated RGB-D frame per thesis object (seed 3 unless ``--seed``, the ``basic`` sensor: noise and
edge dropouts), planned with the `five-finger-linear` hand: perception, synthesis and the 6-DoF pose, exactly
what a bench trial's planner does. Prints, per planner and object, the median
wall time of 5 runs (``--runs``) after a warm-up, the slowest of them, and the
synthesis's share (its ``timing_ms.total``), then a line per planner: the slowest median and plan, the
median of the medians, how many exceed 100 ms. One thread (set before numpy is imported). ``--cpu``
times the process's CPU time instead of the wall clock (steadier on a
loaded machine); ``--real`` also plans the real frames with hand-made masks
(``benchmarks/segmentation.py``'s, in ``../shared/data``), perception
included.

Usage::

    .venv/bin/python benchmarks/planning_time.py [--planners paper,default] [--cpu] [--real] [--objects ...] [--seed N]
        [--runs N]

``--objects`` takes the bench's object names (the thesis's five by default; ``ycb:<id>`` for a YCB
object, ``ycb-train`` for the whole training split); a frame without a plan reads "nan ms".
"""

import os

for _name in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS", "NUMBA_NUM_THREADS"):
    os.environ.setdefault(_name, "1")

import argparse  # noqa: E402
import math  # noqa: E402
import statistics  # noqa: E402
import sys  # noqa: E402
import time  # noqa: E402
import warnings  # noqa: E402
from pathlib import Path  # noqa: E402

import cv2  # noqa: E402

from contourgrasp import load_hand, pipeline  # noqa: E402
from contourgrasp.io.camera_file import read_masked_frames  # noqa: E402
from contourgrasp.io.planner_file import load_planner  # noqa: E402
from contourgrasp.errors import NoFeasibleGrasp  # noqa: E402
from contourgrasp.sim import build_scene, render  # noqa: E402
from contourgrasp.sim.ycb import load_object, object_names  # noqa: E402

OBJECTS = ("can", "case", "bottle", "stone1", "stone2")
RUNS, SEED = 5, 3


def simulated_frame(obj: str, seed: int = SEED):
    """(rgb, depth, intrinsics) of the simulated frame of ``obj`` (a bench object name, e.g. ``ycb:025_mug``)."""
    scene = build_scene(load_object(obj), seed=seed)
    return (*render(scene, sensor="basic", seed=seed), scene.camera.intrinsics)


def frame_times(planner: str, frame, clock=time.perf_counter, runs: int = RUNS) -> tuple[float, float, float]:
    """Median and slowest time (``clock``) of ``runs`` ``plan_frame`` on one (rgb, depth, intrinsics) frame, and
    its median synthesis time, ms."""
    rgb, depth, camera = frame
    hand = load_hand("five-finger-linear")
    options = load_planner(planner).options
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        walls, synthesis = [], []
        try:
            pipeline.plan_frame(rgb, depth, camera, hand, options)  # warm-up: numba's compilation, caches
            for _ in range(runs):
                start = clock()
                result = pipeline.plan_frame(rgb, depth, camera, hand, options)
                walls.append(1e3 * (clock() - start))
                synthesis.append(result.plan.timing_ms["total"])
        except NoFeasibleGrasp:
            return math.nan, math.nan, math.nan
    return statistics.median(walls), max(walls), statistics.median(synthesis)


def real_frames() -> dict:
    """name -> (rgb, depth, intrinsics) of the real frames with hand-made masks (none without the shared data)."""
    shared = Path(os.environ.get("CONTOURGRASP_SHARED_DATA", Path(__file__).resolve().parents[2] / "shared" / "data"))
    return {name.rsplit("/", 1)[-1]: (f.rgb, f.depth, f.intrinsics) for name, f in read_masked_frames(shared / "rgbd")}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--planners", default="paper,default", help="comma list of planner names or files")
    parser.add_argument("--cpu", action="store_true", help="CPU time of the process, not wall time")
    parser.add_argument("--real", action="store_true", help="also the real frames of ../shared/data")
    parser.add_argument("--objects", default=",".join(OBJECTS),
                        help="comma list of bench object names or sets (e.g. ycb:025_mug, ycb-train)")
    parser.add_argument("--seed", type=int, default=SEED, help="the bench trial's seed of every simulated frame")
    parser.add_argument("--runs", type=int, default=RUNS, help="timed plans per frame, after one untimed")
    args = parser.parse_args()
    if args.runs < 1:
        parser.error(f"--runs must be at least 1, got {args.runs}")
    cv2.setNumThreads(1)
    clock = time.process_time if args.cpu else time.perf_counter
    frames = {obj: simulated_frame(obj, args.seed) for obj in object_names(args.objects)} | (real_frames() if args.real else {})
    print(f"{'CPU' if args.cpu else 'wall'} time of plan_frame, median of {args.runs} (the slowest of them; synthesis: "
          f"its timing_ms.total, wall time)\n")
    print("| planner | " + " | ".join(frames) + " |")
    print("|---|" + "---:|" * len(frames))
    summaries = []
    for planner in args.planners.split(","):
        cells = [frame_times(planner, frame, clock, args.runs) for frame in frames.values()]
        print(f"| {planner} | " + " | ".join(f"{w:.0f} ms (slowest {m:.0f}; synthesis {s:.0f})" for w, m, s in cells)
              + " |")
        summaries.append(summary(planner, dict(zip(frames, cells))))
    print("", *summaries, sep="\n")
    print(f"\nload average at end: {' '.join(f'{v:.2f}' for v in os.getloadavg())}")


def summary(planner: str, cells: dict, budget: float = 100.0) -> str:
    """One line per planner: the slowest median and plan, the median of the medians, the frames over ``budget`` ms."""
    planned = {name: cell for name, cell in cells.items() if not math.isnan(cell[0])}
    if not planned:
        return f"{planner}: no frame planned"
    medians = {name: cell[0] for name, cell in planned.items()}
    slowest = {name: cell[1] for name, cell in planned.items()}
    worst, worst_plan = max(medians, key=medians.get), max(slowest, key=slowest.get)
    return (f"{planner}: slowest median {medians[worst]:.0f} ms ({worst}), median of the {len(planned)} medians "
            f"{statistics.median(medians.values()):.0f} ms, slowest plan {slowest[worst_plan]:.0f} ms ({worst_plan}); "
            f"over {budget:.0f} ms: {sum(v > budget for v in medians.values())} medians, "
            f"{sum(v > budget for v in slowest.values())} slowest plans")


if __name__ == "__main__":
    main()
