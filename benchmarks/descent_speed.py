"""Speed of the 3-D hand's checks: the descent clearance per pose and the height map's unseen-cell bound.

On the bundled bar-clamp frame and three simulated YCB frames (seed 2, depth noise on), the height map of
`plan_frame`; 400 random poses around the object at random tip heights; median of 5 runs, one thread.

Usage::

    .venv/bin/python benchmarks/descent_speed.py
"""

import argparse
import os
from dataclasses import replace

for _name in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS", "NUMBA_NUM_THREADS"):
    os.environ.setdefault(_name, "1")

import statistics  # noqa: E402
import time  # noqa: E402
from pathlib import Path  # noqa: E402

import numpy as np  # noqa: E402

from contourgrasp import load_hand, plan_grasp  # noqa: E402
from contourgrasp.io.camera_file import read_rgbd  # noqa: E402
from contourgrasp.sim import build_scene, render  # noqa: E402
from contourgrasp.sim.ycb import load_object  # noqa: E402
from contourgrasp.synthesis import descent_clearance  # noqa: E402

RUNS, POSES = 5, 400
BAR_CLAMP = Path(__file__).resolve().parents[1] / "examples" / "bar_clamp"


def frames(hand):
    bundled = read_rgbd(BAR_CLAMP / "color_0.png", BAR_CLAMP / "depth_0.npy", BAR_CLAMP / "primesense_overhead_color.intr")
    yield "bar clamp (bundled)", (bundled.rgb, bundled.depth, bundled.intrinsics)
    for name in ("ycb:005_tomato_soup_can", "ycb:003_cracker_box", "ycb:025_mug"):
        scene = build_scene(load_object(name), seed=2, hand=hand)
        yield name, (*render(scene, sensor="basic", seed=2), scene.camera.intrinsics)


def median_ms(work) -> float:
    times = []
    for _ in range(RUNS):
        start = time.perf_counter()
        work()
        times.append(1e3 * (time.perf_counter() - start))
    return statistics.median(times)


def main() -> None:
    argparse.ArgumentParser(description=__doc__.splitlines()[0]).parse_args()
    hand = load_hand("five-finger-linear")
    print("| frame | descent clearance per pose | unseen-cell bound (`HeightMap.conservative`) |\n|---|---:|---:|")
    for name, (rgb, depth, camera) in frames(hand):
        heights = plan_grasp(rgb, depth, camera, hand, xy_step=0.05, yaw_step=0.5, small_objects=True).height_map
        rng = np.random.default_rng(0)
        centre = np.array([(heights.extent[0] + heights.extent[1]) / 2, (heights.extent[2] + heights.extent[3]) / 2])
        poses = np.c_[centre + rng.uniform(-0.12, 0.12, (POSES, 2)), rng.uniform(0, 2 * np.pi, POSES)]
        tips = rng.uniform(0.0, 0.15, POSES)
        descent_clearance(hand, heights, poses[:2], tips[:2])  # compile / load the kernel
        per_pose = median_ms(lambda: descent_clearance(hand, heights, poses, tips)) / POSES
        def fresh():
            replace(heights).conservative()  # a map computes its bound once: time it on a new map each run

        print(f"| {name} | {per_pose:.3f} ms | {median_ms(fresh):.1f} ms |")
    print(f"\nload average at end: {' '.join(f'{v:.2f}' for v in os.getloadavg())}")


if __name__ == "__main__":
    main()
