"""Real-frames benchmark: does every shared real frame plan on one whole object, and how fast?

Every folder ``<data>/rgbd/real_*/`` (PhoXi, PrimeSense, RealSense D4xx and SR300 frames of bins,
clutter and oblique views: ``../shared/data/README.md``) is read as ``contourgrasp plan FOLDER``
reads it (:func:`contourgrasp.io.camera_file.frame_files`, colour at another resolution resampled
onto the depth grid) and planned with the default planner and hand (``--planner default``, ``--hand five-finger-linear``)
(:func:`contourgrasp.pipeline.plan_frame`). Per frame the table gives:

- the outcome: planned (and how many fingers touch), or the reason of the refusal;
- the target against the frame's truth, where the source gives one. The target's *seen* region (the
  chosen candidate's mask, the pixels that see it; a tilted camera plans on its footprint, which no
  source labels), moved into the colour image by the colour-depth shift perception measured
  (``Segmentation.colour_offset_px``: the sources label their colour images, and their depth lies a
  few pixels off them), is compared with:

  * ``seg.png`` (one label per object): the label it overlaps most, the IoU with it, and the share
    of the target on that one label ("one object" when at least ``ONE_OBJECT`` of it is);
  * ``mask.png`` (all objects, one mask): the share of the target on the objects;
  * ``object_mask*.png`` (the one object): the IoU with it;

- the warm frame-to-grasp time: perception and planning, one call of ``plan_frame`` after a
  first untimed one, median of ``--runs``, CPU time of the process on one thread (``--clock
  wall`` for wall time), and the frame's size.

Usage::

    python benchmarks/real_frames.py [--data PATH] [--runs 3] [--clock cpu|wall] [--any]

``--any`` plans with :func:`contourgrasp.picking.plan_any` (``plan --any``): where the object chosen has no
feasible grasp, the next one.

``--data`` defaults to ``$CONTOURGRASP_SHARED_DATA`` or ``../shared/data`` beside the repository.
The frames are the project's shared data, not its training data: nothing was tuned on their figures.
"""

from __future__ import annotations

import os

# One core: set before numpy is imported, so that the BLAS pools see it.
for _var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS", "NUMBA_NUM_THREADS"):
    os.environ[_var] = "1"

import argparse  # noqa: E402
import statistics  # noqa: E402
import sys  # noqa: E402
import time  # noqa: E402
import warnings  # noqa: E402
from pathlib import Path  # noqa: E402

import cv2  # noqa: E402
import numpy as np  # noqa: E402

from contourgrasp import load_hand, load_planner, perception  # noqa: E402
from contourgrasp.errors import ContourGraspError, NoFeasibleGrasp  # noqa: E402
from contourgrasp.io.camera_file import frame_files, read_rgbd  # noqa: E402
from contourgrasp.picking import plan_any  # noqa: E402
from contourgrasp.pipeline import plan_frame  # noqa: E402

SHARED_DATA = Path(os.environ.get("CONTOURGRASP_SHARED_DATA", Path(__file__).resolve().parents[2] / "shared" / "data"))
#: A target is one object when at least this share of its pixels lies on one label.
ONE_OBJECT = 0.9


def frame(folder: Path):
    """(rgb on the depth grid, depth, intrinsics) of a frame folder, as ``contourgrasp plan`` reads it."""
    colour, depth, intrinsics = frame_files(folder)
    rgbd = read_rgbd(colour, depth, intrinsics)
    rgb = perception.colour_on_depth(rgbd.rgb, rgbd.depth.shape, intrinsics=rgbd.intrinsics,
                                     colour_intrinsics=rgbd.colour_intrinsics)
    return rgb, rgbd.depth, rgbd.intrinsics


def truth_columns(folder: Path, seen: np.ndarray | None) -> str:
    """What the frame's truth says of the target's seen region ``seen`` (None: no target)."""
    if seen is None:
        return "-"
    if (folder / "seg.png").is_file():
        labels = cv2.imread(str(folder / "seg.png"), cv2.IMREAD_UNCHANGED)
        ids, counts = np.unique(labels[seen & (labels > 0)], return_counts=True)
        if not len(ids):
            return "on no labelled object"
        best = ids[np.argmax(counts)]
        share = counts.max() / seen.sum()
        verdict = "one object" if share >= ONE_OBJECT else "more than one object"
        return f"label {best}: IoU {iou(seen, labels == best):.2f}, {share:.0%} of the target on it ({verdict})"
    if (folder / "mask.png").is_file():
        objects = cv2.imread(str(folder / "mask.png"), cv2.IMREAD_GRAYSCALE) > 0
        return f"{(seen & objects).sum() / seen.sum():.0%} of the target on the objects' mask"
    masks = sorted(folder.glob("object_mask*.png"))
    if masks:
        return f"IoU {iou(seen, cv2.imread(str(masks[0]), cv2.IMREAD_GRAYSCALE) > 0):.2f} with the object's mask"
    return "no truth"


def in_colour(mask, offset):
    """``mask`` (depth pixels) moved into the colour image: the colour image moved by ``offset`` (dx, dy) lies on
    the depth image, so the depth image's pixels lie at minus it in the colour image."""
    if offset is None:
        return mask
    dx, dy = offset
    moved = np.zeros_like(mask)
    h, w = mask.shape
    moved[max(-dy, 0):h + min(-dy, 0), max(-dx, 0):w + min(-dx, 0)] = mask[max(dy, 0):h + min(dy, 0),
                                                                        max(dx, 0):w + min(dx, 0)]
    return moved


def iou(a, b) -> float:
    return float((a & b).sum() / max((a | b).sum(), 1))


def plan_once(rgb, depth, intrinsics, hand, options, plan=plan_frame):
    """(plan or None, reason) of one call of ``plan`` (``plan_frame``, or ``plan_any``)."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        try:
            return plan(rgb, depth, intrinsics, hand, options), ""
        except NoFeasibleGrasp as err:
            return None, f"no feasible grasp: {err.reason}"
        except ContourGraspError as err:
            return None, f"refused: {err}"


def run(folder: Path, hand, options, runs: int, clock, plan=plan_frame) -> tuple[str, ...]:
    rgb, depth, intrinsics = frame(folder)
    result, reason = plan_once(rgb, depth, intrinsics, hand, options, plan)  # warm-up, and the result
    times = []
    for _ in range(runs):
        start = clock()
        plan_once(rgb, depth, intrinsics, hand, options, plan)
        times.append(1000 * (clock() - start))
    if result is None:
        outcome, seen = reason[:160], None
    else:
        touching = sum(not f.missed for f in result.plan.fingers)
        outcome = f"planned, {touching}/{len(result.plan.fingers)} fingers touch"
        seen = None if result.target is None else in_colour(result.target.mask, result.segmentation.colour_offset_px)
    tilt = "-" if result is None or result.support is None else f"{np.degrees(result.support.plane.tilt):.0f}"
    return (folder.name, f"{depth.shape[1]}x{depth.shape[0]}", tilt, outcome, truth_columns(folder, seen),
            f"{statistics.median(times):.0f}")


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--data", type=Path, default=SHARED_DATA, help="shared data folder")
    parser.add_argument("--runs", type=int, default=3, help="timed runs per frame; the median is reported")
    parser.add_argument("--clock", choices=("cpu", "wall"), default="cpu", help="CPU time of the process, or wall time")
    parser.add_argument("--any", action="store_true",
                        help="plan_any (plan --any): the next object when the one chosen has no feasible grasp")
    args = parser.parse_args(argv)
    folders = sorted(p for p in (args.data / "rgbd").glob("real_*") if p.is_dir())
    if not folders:
        print(f"no real frames under {args.data / 'rgbd'} (real_*/): nothing to measure", file=sys.stderr)
        return 1
    cv2.setNumThreads(1)
    clock = time.process_time if args.clock == "cpu" else time.perf_counter
    hand, options = load_hand("five-finger-linear"), load_planner("default").options
    print("| frame | depth size | tilt (deg) | outcome | the target against the truth | warm time (ms) |")
    print("|---|---|---:|---|---|---:|")
    for folder in folders:
        print("| " + " | ".join(run(folder, hand, options, args.runs, clock, plan_any if args.any else plan_frame))
              + " |", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
