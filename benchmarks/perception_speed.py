"""Perception-speed benchmark: milliseconds per frame of ``pipeline.perceive`` and its stages, on one core.

Frames:

(a) simulated: ``contourgrasp.sim.build_scene(name, seed=s)`` rendered with noise for the objects
    can, case, bottle, stone1, stone2 and seeds 0 .. ``--seeds`` - 1;
(b) real: the bundled bar-clamp frame (``examples/bar_clamp``, the ROS latency benchmark's) and the
    PrimeSense frames of ``<data>/rgbd/*/`` loaded as in ``benchmarks/segmentation.py`` (skipped when
    the folder is absent).

Each frame is run once untimed (warm-up), then ``--runs`` times; the median is reported. The stages
are timed separately, in the order :func:`contourgrasp.pipeline.perceive` runs them: ``fill``
(:func:`~contourgrasp.perception.fill_depth_holes`), ``segment``
(:func:`~contourgrasp.perception.segment`, method ``"auto"``: table plane, depth, flat parts) and
``metric`` (:func:`~contourgrasp.perception.contour_to_metric`); ``perceive`` is the whole call.

Times are CPU time of the process by default (``--clock cpu``): on a machine shared with other jobs
wall time also counts the waits for a core; ``--clock wall`` measures wall time. OpenCV, BLAS and
numba run on one thread, so CPU time is the time on one core.

``--grey`` times every frame turned grey first (``segmentation.grey``: luma in three equal channels, as a
grayscale camera stores it), where flat parts are also looked for in depth.

``--save FILE`` writes the medians as JSON; ``--baseline FILE`` adds them as the "before" columns
of the table, so a run before and one after a change print both.

Usage::

    python benchmarks/perception_speed.py [--data PATH] [--runs 7] [--seeds 2] [--clock cpu|wall] [--grey]
        [--save F] [--baseline F]
"""

from __future__ import annotations

import os

# One core: set before numpy is imported, so that the BLAS pools see it.
THREAD_VARS = ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS", "NUMBA_NUM_THREADS")
for _var in THREAD_VARS:
    os.environ[_var] = "1"

import argparse  # noqa: E402
import json  # noqa: E402
import statistics  # noqa: E402
import sys  # noqa: E402
import time  # noqa: E402
import warnings  # noqa: E402
from pathlib import Path  # noqa: E402

import cv2  # noqa: E402
import numpy as np  # noqa: E402

from contourgrasp import perception, pipeline  # noqa: E402
from contourgrasp.io.camera_file import read_masked_frames, read_rgbd  # noqa: E402
from contourgrasp.sim import build_scene, render  # noqa: E402

SIM_OBJECTS = ("can", "case", "bottle", "stone1", "stone2")
#: The shared real frames (``../shared/data``, or ``$CONTOURGRASP_SHARED_DATA``).
SHARED_DATA = Path(os.environ.get("CONTOURGRASP_SHARED_DATA", Path(__file__).resolve().parents[2] / "shared" / "data"))
BAR_CLAMP = Path(__file__).resolve().parents[1] / "examples" / "bar_clamp"
STAGES = ("fill", "segment", "metric", "perceive")
CLOCKS = {"cpu": time.process_time, "wall": time.perf_counter}
#: Perception's share of the planner's 100 ms budget per frame.
TARGET_MS = 40.0


def grey(rgb) -> np.ndarray:
    """(H, W, 3) uint8: ``rgb``'s luma (ITU-R 601) in three equal channels, as a grayscale camera stores it."""
    luma = np.rint(np.asarray(rgb, dtype=float) @ [0.299, 0.587, 0.114]).astype(np.uint8)
    return np.repeat(luma[..., None], 3, axis=2)


def sim_frames(seeds: int):
    """(name, rgb, depth, intrinsics) of the simulated frames."""
    for name in SIM_OBJECTS:
        for seed in range(seeds):
            scene = build_scene(name, seed=seed)
            rgb, depth = render(scene, sensor="basic", seed=seed)
            yield f"sim {name} s{seed}", rgb, depth, scene.camera.intrinsics


def bundled_frame():
    """(name, rgb, depth, intrinsics) of the bundled bar-clamp frame."""
    frame = read_rgbd(BAR_CLAMP / "color_0.png", BAR_CLAMP / "depth_0.npy", BAR_CLAMP / "primesense_overhead_color.intr")
    return "examples/bar_clamp", frame.rgb, frame.depth, frame.intrinsics


def stage_times(rgb, depth, intrinsics, clock) -> dict[str, float]:
    """Seconds of each stage of one ``perceive`` call, and of the whole call, on ``clock``."""
    times = {}
    start = clock()
    filled, _ = perception.fill_depth_holes(depth)
    times["fill"] = clock() - start
    start = clock()
    seg = perception.segment(rgb, filled, intrinsics)
    times["segment"] = clock() - start
    start = clock()
    perception.contour_to_metric(seg.contour_px, filled, intrinsics, plane=seg.plane, on_table=seg.on_table)
    times["metric"] = clock() - start
    start = clock()
    pipeline.perceive(rgb, depth, intrinsics)
    times["perceive"] = clock() - start
    return times


def median_ms(rgb, depth, intrinsics, runs: int, clock) -> dict[str, float]:
    """Median milliseconds per stage over ``runs`` timed runs after one warm-up run."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        stage_times(rgb, depth, intrinsics, clock)
        samples = [stage_times(rgb, depth, intrinsics, clock) for _ in range(runs)]
    return {s: 1000 * statistics.median(t[s] for t in samples) for s in STAGES}


def with_means(results: dict) -> dict:
    """``results`` plus a mean row per group of frames (simulated, real) that has frames."""
    groups = {"sim": [f for f in results if f.startswith("sim ")], "real": [f for f in results if not f.startswith("sim ")]}
    means = {
        f"**mean {group}** ({len(names)})": {s: float(np.mean([results[f][s] for f in names])) for s in STAGES}
        for group, names in groups.items()
        if names
    }
    return {**results, **means}


def table(results: dict, baseline: dict) -> list[str]:
    """Markdown rows: ms per stage per frame (before -> after where the baseline has the frame)."""
    results, baseline = with_means(results), with_means(baseline)

    def cell(frame, stage):
        after = f"{results[frame][stage]:.1f}"
        return f"{baseline[frame][stage]:.1f} -> {after}" if frame in baseline else after

    lines = ["| frame | " + " | ".join(f"{s} (ms)" for s in STAGES) + " |", "|---|" + "---:|" * len(STAGES)]
    return lines + [f"| {frame} | " + " | ".join(cell(frame, s) for s in STAGES) + " |" for frame in results]


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--data", type=Path, default=SHARED_DATA, help="shared data folder")
    parser.add_argument("--runs", type=int, default=7, help="timed runs per frame; the median is kept")
    parser.add_argument("--seeds", type=int, default=2, help="simulated scenes per object")
    parser.add_argument("--clock", choices=sorted(CLOCKS), default="cpu", help="process CPU time or wall time")
    parser.add_argument("--grey", action="store_true", help="time the frames turned grey (three equal channels)")
    parser.add_argument("--save", type=Path, help="write the medians (ms) to this JSON file")
    parser.add_argument("--baseline", type=Path, help="JSON of an earlier --save, printed as 'before'")
    args = parser.parse_args(argv)
    cv2.setNumThreads(1)
    frames = list(sim_frames(args.seeds))
    real = [(name, f.rgb, f.depth, f.intrinsics) for name, f in read_masked_frames(args.data / "rgbd")]
    if not real:
        print(f"no real frames under {args.data}/rgbd: simulated frames and the bar clamp only", file=sys.stderr)
    real.insert(0, bundled_frame())
    results = {}
    for name, rgb, depth, intrinsics in frames + real:
        results[name] = median_ms(grey(rgb) if args.grey else rgb, depth, intrinsics, args.runs, CLOCKS[args.clock])
        print(f"{name}: {results[name]['perceive']:.1f} ms", file=sys.stderr, flush=True)
    baseline = json.loads(args.baseline.read_text()) if args.baseline else {}
    print("\n".join(table(results, baseline)))
    worst = max(r["perceive"] for r in results.values())
    print(f"\nperceive ({args.clock} time): worst frame {worst:.1f} ms (target <= {TARGET_MS:.0f} ms on one core)")
    if args.save:
        args.save.write_text(json.dumps(results, indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
