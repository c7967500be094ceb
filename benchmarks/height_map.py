"""The height map: its object height against the simulation's exact truth, and its cost.

(a) Accuracy: the five thesis objects and a standing can, rendered by ``contourgrasp.sim`` (seeds 0-2,
    camera 0.7 m above the table, top-down and tilted 12.7 deg, exact depth and the sensor's noise),
    perceived and mapped as ``pipeline.plan_frame`` does; prints ``HeightMap.max_height`` minus the
    object's true top (its collision surface's highest point), mm.
(b) Time: ``perception.height_map`` on the bundled frame ``examples/bar_clamp`` (median of 50 runs
    after a warm-up, one thread, wall time), and ``HeightMap.conservative``.

Usage::

    .venv/bin/python benchmarks/height_map.py [--seeds 3] [--skip-sim]
"""

import os

for _name in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS", "NUMBA_NUM_THREADS"):
    os.environ.setdefault(_name, "1")

import argparse  # noqa: E402
import statistics  # noqa: E402
import time  # noqa: E402
import warnings  # noqa: E402
from pathlib import Path  # noqa: E402

import cv2  # noqa: E402
import numpy as np  # noqa: E402

from contourgrasp import perception, pipeline  # noqa: E402
from contourgrasp.io.camera_file import read_rgbd  # noqa: E402

FRAME = Path(__file__).resolve().parents[1] / "examples" / "bar_clamp"
OBJECTS = ("can", "case", "bottle", "stone1", "stone2", "can-standing")


def accuracy(seeds: int) -> None:
    from contourgrasp.sim import Camera, build_scene, render, tilted_view
    from contourgrasp.sim.objects import soda_can

    print("| object | view | exact depth (mm) | with noise (mm) |\n|---|---|---|---|")
    for name in OBJECTS:
        for tilt in (0.0, 12.7):
            cells = []
            for noise in (False, True):
                errors = []
                for seed in range(seeds):
                    scene = build_scene(soda_can(True) if name == "can-standing" else name, seed=seed,
                                        camera=Camera(height=0.7))
                    view = tilted_view(np.radians(tilt), 0.7) if tilt else None
                    rgb, depth = render(scene, sensor="basic" if noise else "ideal", seed=seed, view=view)
                    with warnings.catch_warnings():
                        warnings.simplefilter("ignore")
                        seg, metric, _ = pipeline.perceive(rgb, depth, scene.camera.intrinsics)
                    filled = perception.fill_depth_holes(depth)[0]
                    heights = pipeline.scene_heights(filled, scene.camera.intrinsics, seg, metric)
                    errors.append(1e3 * (heights.max_height - scene.object_points()[:, 2].max()))
                cells.append(" ".join(f"{e:+.1f}" for e in errors))
            print(f"| {name} | {'top-down' if not tilt else f'tilted {tilt} deg'} | {cells[0]} | {cells[1]} |")


def timing() -> None:
    frame = read_rgbd(FRAME / "color_0.png", FRAME / "depth_0.npy", FRAME / "primesense_overhead_color.intr")
    depth = perception.fill_depth_holes(frame.depth)[0]
    seg, metric, _ = pipeline.perceive(frame.rgb, frame.depth, frame.intrinsics)
    args = (depth, frame.intrinsics, seg.plane, metric, seg.mask)
    heights = perception.height_map(*args)
    build, bound = [], []
    for _ in range(50):
        start = time.perf_counter()
        heights = perception.height_map(*args)
        build.append(1e3 * (time.perf_counter() - start))
        start = time.perf_counter()
        heights.conservative()
        bound.append(1e3 * (time.perf_counter() - start))
    print(f"\nbundled frame: {heights.shape[0]} x {heights.shape[1]} cells of {1e3 * heights.cell:g} mm; "
          f"height_map {statistics.median(build):.1f} ms (min {min(build):.1f}), "
          f"conservative {statistics.median(bound):.1f} ms (min {min(bound):.1f}); "
          f"object up to {1e3 * heights.max_height:.1f} mm, obstacles up to {1e3 * heights.obstacle_max_height:.1f} mm")
    print(f"load average at end: {' '.join(f'{v:.2f}' for v in os.getloadavg())}")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", type=int, default=3)
    parser.add_argument("--skip-sim", action="store_true", help="timing only")
    args = parser.parse_args()
    cv2.setNumThreads(1)
    if not args.skip_sim:
        accuracy(args.seeds)
    timing()


if __name__ == "__main__":
    main()
