"""Segmentation benchmark: IoU against hand-made masks, per method, on the real RGB-D frames.

Every frame of ``<data>/rgbd/*/`` that has ``color_N.png``, ``depth_N.npy`` and
``segmask_N.png`` (and an ``.intr`` file in its folder) is segmented with each
method of :func:`contourgrasp.perception.segment` (and with depth without the
footprint, "depth, seen": the pixels that see the object); the script prints a
Markdown table of the IoU per frame, the mean, the worst frame and the time
per frame. A refused frame (SegmentationError) scores IoU 0; a note in brackets
says which method ``auto`` used (``depth``, ``depth+rgb`` or ``rgb``) and by how much
it shifted the colour image onto the depth image (``Segmentation.colour_offset_px``).

Usage::

    python benchmarks/segmentation.py [--data PATH] [--repeat N]

``--data`` defaults to ``$CONTOURGRASP_SHARED_DATA`` or ``../shared/data``
beside the repository.
"""

from __future__ import annotations

import argparse
import os
import sys
import time
import warnings
from pathlib import Path

import numpy as np

from contourgrasp.io.camera_file import read_intrinsics, read_mask, read_rgb
from contourgrasp.perception import SegmentationError, segment

#: Targets for the default method (from the perception issue).
TARGET_MEAN, TARGET_WORST = 0.90, 0.75
#: Table columns: (heading, method, depth options). "depth, seen" is depth without the footprint.
COLUMNS = (("rgb", "rgb", None), ("depth, seen", "depth", {"footprint": False}), ("depth", "depth", None),
           ("auto", "auto", None))


def default_data() -> Path:
    return Path(os.environ.get("CONTOURGRASP_SHARED_DATA", Path(__file__).resolve().parents[2] / "shared" / "data"))


def frames(data: Path):
    """(name, rgb, depth, intrinsics, truth) for every frame with a ground-truth mask."""
    for truth_path in sorted(data.glob("rgbd/*/segmask_*.png")):
        folder, index = truth_path.parent, truth_path.stem.removeprefix("segmask_")
        intrinsics = sorted(folder.glob("*.intr"))
        if not intrinsics or not (folder / f"depth_{index}.npy").is_file():
            continue
        yield (
            f"{folder.name}/{index}",
            read_rgb(folder / f"color_{index}.png"),
            np.load(folder / f"depth_{index}.npy"),
            read_intrinsics(intrinsics[0]),
            read_mask(truth_path),
        )


def run(rgb, depth, intrinsics, truth, method, depth_options, repeat):
    """IoU (0 when refused), a note, and the best time (s) over ``repeat`` runs."""
    best, result, note = np.inf, None, ""
    for _ in range(repeat):
        start = time.perf_counter()
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            try:
                result = segment(rgb, depth, intrinsics, method=method, depth_options=depth_options)
            except SegmentationError as err:
                note = f"refused ({err.kind})"
        best = min(best, time.perf_counter() - start)
    if result is None:
        return 0.0, note, best
    iou = float((result.mask & truth).sum() / (result.mask | truth).sum())
    notes = [] if result.method == method else [f"used {result.method}"]
    if result.colour_offset_px is not None:
        notes.append("colour shifted ({}, {}) px".format(*result.colour_offset_px))
    return iou, ", ".join(notes), best


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--data", type=Path, default=default_data(), help="shared data folder")
    parser.add_argument("--repeat", type=int, default=3, help="runs per frame; the best time is kept")
    args = parser.parse_args(argv)
    rows = list(frames(args.data))
    if not rows:
        print(f"no frames with segmask_N.png found under {args.data}/rgbd", file=sys.stderr)
        return 1
    headings = [heading for heading, _, _ in COLUMNS]
    ious = {h: [] for h in headings}
    times = {h: [] for h in headings}
    print("| frame | " + " | ".join(f"{h} IoU" for h in headings) + " |")
    print("|---|" + "---:|" * len(COLUMNS))
    for name, rgb, depth, intrinsics, truth in rows:
        cells = []
        for heading, method, depth_options in COLUMNS:
            iou, note, seconds = run(rgb, depth, intrinsics, truth, method, depth_options, args.repeat)
            ious[heading].append(iou)
            times[heading].append(seconds)
            cells.append(f"{iou:.3f}" + (f" ({note})" if note else ""))
        print(f"| {name} | " + " | ".join(cells) + " |")
    print("| **mean** | " + " | ".join(f"**{np.mean(ious[h]):.3f}**" for h in headings) + " |")
    print("| worst | " + " | ".join(f"{np.min(ious[h]):.3f}" for h in headings) + " |")
    print("| time per frame (ms) | " + " | ".join(f"{1000 * np.mean(times[h]):.0f}" for h in headings) + " |")
    mean, worst = np.mean(ious["auto"]), np.min(ious["auto"])
    verdict = "met" if mean >= TARGET_MEAN and worst >= TARGET_WORST else "NOT met"
    print(f"\nauto (default): mean IoU {mean:.3f} (target >= {TARGET_MEAN}), worst {worst:.3f} "
          f"(target >= {TARGET_WORST}): target {verdict}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
