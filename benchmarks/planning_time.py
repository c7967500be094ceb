"""Planning time per frame (issue 6: under 100 ms): `plan_grasp` on simulated frames, per planner.

One simulated RGB-D frame per thesis object (seed 3, depth noise on), planned with
the `five-finger-linear` hand: perception, synthesis and the 6-DoF pose, exactly
what a bench trial's planner does. Prints, per planner and object, the median
wall time of 5 runs after a warm-up, and the synthesis's share (its
``timing_ms.total``). One thread (set before numpy is imported).

Usage::

    .venv/bin/python benchmarks/planning_time.py [--planners paper,default] [--objects can,ycb:025_mug,...]

``--objects`` takes the bench's object names (the thesis's five by default; ``ycb:<id>`` for a YCB
object, ``ycb-train`` for the whole training split).
"""

import os

for _name in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS", "NUMBA_NUM_THREADS"):
    os.environ.setdefault(_name, "1")

import argparse  # noqa: E402
import math  # noqa: E402
import statistics  # noqa: E402
import time  # noqa: E402

import cv2  # noqa: E402

from contourgrasp import load_hand, pipeline  # noqa: E402
from contourgrasp.io.planner_file import load_planner  # noqa: E402
from contourgrasp.errors import NoFeasibleGrasp  # noqa: E402
from contourgrasp.sim import build_scene, render  # noqa: E402
from contourgrasp.sim.ycb import load_object, object_names  # noqa: E402

OBJECTS = ("can", "case", "bottle", "stone1", "stone2")
RUNS, SEED = 5, 3


def frame_times(planner: str, obj: str) -> tuple[float, float]:
    """Median wall time of ``plan_grasp`` on one frame and its synthesis time, both ms (NaN: no plan)."""
    scene = build_scene(load_object(obj), seed=SEED)
    rgb, depth = render(scene, noise=True, seed=SEED)
    camera, hand = scene.camera.intrinsics, load_hand("five-finger-linear")
    options = load_planner(planner).plan_options
    walls, synthesis = [], []
    try:
        pipeline.plan_frame(rgb, depth, camera, hand, **options)  # warm-up: numba's compilation, caches
        for _ in range(RUNS):
            start = time.perf_counter()
            result = pipeline.plan_frame(rgb, depth, camera, hand, **options)
            walls.append(1e3 * (time.perf_counter() - start))
            synthesis.append(result.plan.timing_ms["total"])
    except NoFeasibleGrasp:
        return math.nan, math.nan
    return statistics.median(walls), statistics.median(synthesis)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--planners", default="paper,default", help="comma list of planner names or files")
    parser.add_argument("--objects", default=",".join(OBJECTS), help="comma list of bench object names or sets")
    args = parser.parse_args()
    cv2.setNumThreads(1)
    objects = object_names(args.objects)
    print("| planner | " + " | ".join(objects) + " |")
    print("|---|" + "---:|" * len(objects))
    for planner in args.planners.split(","):
        cells = [frame_times(planner, obj) for obj in objects]
        print(f"| {planner} | " + " | ".join(f"{w:.0f} ms (synthesis {s:.0f})" for w, s in cells) + " |")
    print(f"\nload average at end: {' '.join(f'{v:.2f}' for v in os.getloadavg())}")


if __name__ == "__main__":
    main()
