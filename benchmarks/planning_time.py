"""Planning time per frame (issue 6: under 100 ms): `plan_grasp` on simulated frames, per planner.

One simulated RGB-D frame per thesis object (seed 3, depth noise on), planned with
the `five-finger-linear` hand: perception, synthesis and the 6-DoF pose, exactly
what a bench trial's planner does. Prints, per planner and object, the median
wall time of 5 runs after a warm-up, and the synthesis's share (its
``timing_ms.total``). One thread (set before numpy is imported).

Usage::

    .venv/bin/python benchmarks/planning_time.py [--planners paper,default]
"""

import os

for _name in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS", "NUMBA_NUM_THREADS"):
    os.environ.setdefault(_name, "1")

import argparse  # noqa: E402
import statistics  # noqa: E402
import time  # noqa: E402

import cv2  # noqa: E402

from contourgrasp import load_hand, pipeline  # noqa: E402
from contourgrasp.io.planner_file import load_planner  # noqa: E402
from contourgrasp.sim import build_scene, render  # noqa: E402

OBJECTS = ("can", "case", "bottle", "stone1", "stone2")
RUNS, SEED = 5, 3


def frame_times(planner: str, obj: str) -> tuple[float, float]:
    """Median wall time of ``plan_grasp`` on one frame and its synthesis time, both ms."""
    scene = build_scene(obj, seed=SEED)
    rgb, depth = render(scene, noise=True, seed=SEED)
    camera, hand = scene.camera.intrinsics, load_hand("five-finger-linear")
    options = load_planner(planner).plan_options
    pipeline.plan_frame(rgb, depth, camera, hand, **options)  # warm-up: numba's compilation, caches
    walls, synthesis = [], []
    for _ in range(RUNS):
        start = time.perf_counter()
        result = pipeline.plan_frame(rgb, depth, camera, hand, **options)
        walls.append(1e3 * (time.perf_counter() - start))
        synthesis.append(result.plan.timing_ms["total"])
    return statistics.median(walls), statistics.median(synthesis)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--planners", default="paper,default", help="comma list of planner names or files")
    args = parser.parse_args()
    cv2.setNumThreads(1)
    print("| planner | " + " | ".join(OBJECTS) + " |")
    print("|---|" + "---:|" * len(OBJECTS))
    for planner in args.planners.split(","):
        cells = [frame_times(planner, obj) for obj in OBJECTS]
        print(f"| {planner} | " + " | ".join(f"{w:.0f} ms (synthesis {s:.0f})" for w, s in cells) + " |")
    print(f"\nload average at end: {' '.join(f'{v:.2f}' for v in os.getloadavg())}")


if __name__ == "__main__":
    main()
