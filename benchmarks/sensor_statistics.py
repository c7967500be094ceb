"""Sensor statistics of the real frames: what the simulation's sensor presets are set from.

For every real frame under ``<data>/rgbd/`` (the PrimeSense single-object frames and the ``real_*``
folders: ``../shared/data/README.md`` names each one's sensor), on the support surface
(:func:`contourgrasp.perception.find_support`):

- **noise**: the depth's scatter on the support, as the standard deviation of a reading less the
  median of its 5 x 5 neighbours (the surface's own slope and unevenness cancel; residuals beyond
  1 cm left out as outliers), per 5 cm band of depth; ``k`` is the median over bands of that deviation divided by depth squared, the noise model
  of :class:`contourgrasp.sim.Sensor` (sigma = k d^2); and the same with the heights above the
  fitted support plane (within 1 cm of it) for the reading less its neighbours: the scatter a
  sensor whose matcher smooths its depth over a few pixels shows only against the surface;
- **edge dropout**: of the pixels within ``DOCTOR_EDGE_PX`` (3) of a depth edge (a jump of more than
  ``DOCTOR_EDGE_STEP``, 2 cm, between valid readings of a 9 x 9 window:
  :func:`contourgrasp.doctor.near_depth_edges`), the share that read nothing;
- **speckle**: of the support's pixels away from edges (its outline filled), the share that read
  nothing;
- **missing**: the frame's whole missing share.

A frame with no missing reading (a source that filled its depth) says so: its edge dropout and
speckle are the source's, not the sensor's.

``--sim N`` measures the same on frames the simulation renders with each sensor preset
(:data:`contourgrasp.sim.SENSORS`): N clutter scenes of the thesis's five objects on the table, each
from a camera tilted 0-25 deg by its seed, so that each preset's figures stand beside the real frames
of its kind.

Usage::

    python benchmarks/sensor_statistics.py [--data PATH] [--sim N]
"""

from __future__ import annotations

import argparse
import os
import sys
import warnings
from pathlib import Path

import cv2
import numpy as np

from contourgrasp import perception
from contourgrasp.doctor import near_depth_edges
from contourgrasp.errors import ContourGraspError
from contourgrasp.io.camera_file import frame_files, read_masked_frames, read_rgbd

SHARED_DATA = Path(os.environ.get("CONTOURGRASP_SHARED_DATA", Path(__file__).resolve().parents[2] / "shared" / "data"))
#: Depth bands for the noise, m.
BAND = 0.05
#: Residuals beyond this (m) are outliers, not noise.
CLIP = 0.01


def frames(data: Path):
    """(name, depth, intrinsics) of every real frame."""
    for name, frame in read_masked_frames(data / "rgbd"):
        yield name, frame.depth, frame.intrinsics
    for folder in sorted(p for p in (data / "rgbd").glob("real_*") if p.is_dir()):
        colour, depth, intrinsics = frame_files(folder)
        frame = read_rgbd(None, depth, intrinsics)
        yield folder.name, frame.depth, frame.intrinsics


def rendered(scenes: int):
    """(name, depth, intrinsics) of ``scenes`` clutter scenes of the thesis's five, per sensor preset."""
    if not scenes:
        return
    from contourgrasp.sim import SENSORS, THESIS_OBJECTS, build_clutter, render

    names = list(THESIS_OBJECTS)
    built = [build_clutter(names[k % 5], names, kind="clutter", seed=k) for k in range(scenes)]
    for preset in SENSORS:
        for k, scene in enumerate(built):
            yield f"simulated `{preset}`", render(scene, sensor=preset, seed=k)[1], scene.camera.intrinsics


def noise_k(depth, support, height=None) -> float:
    """Median over depth bands of (std of a reading less its 5 x 5 median, on the support) / depth^2; with ``height``
    (the readings' heights above the support plane) the std of those heights instead."""
    d = depth.astype(np.float32)
    quiet = support & (cv2.erode(support.astype(np.uint8), np.ones((5, 5), np.uint8)) > 0)
    residual = (height if height is not None else d - cv2.medianBlur(d, 5))[quiet]
    z = d[quiet]
    ks = []
    for lo in np.arange(z.min(), z.max(), BAND):
        band = (z >= lo) & (z < lo + BAND)
        if band.sum() > 500:
            r = residual[band]
            r = r[np.abs(r) < CLIP]  # a few flying pixels do not count; readings are often whole millimetres
            ks.append(float(r.std()) / (lo + BAND / 2) ** 2)
    return float(np.median(ks)) if ks else float("nan")


def statistics(depth, intrinsics) -> dict:
    missing = ~(np.isfinite(depth) & (depth > 0))
    d = np.where(missing, 0.0, depth)
    edges = near_depth_edges(d, missing)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        filled, _ = perception.fill_depth_holes(d, max_hole_px=0)
        plane = perception.find_support(filled, intrinsics).plane
    with np.errstate(invalid="ignore"):
        height = perception.table.heights(d, intrinsics, plane)
        on = ~missing & (np.abs(height) < 0.005)
    outline = cv2.morphologyEx(on.astype(np.uint8), cv2.MORPH_CLOSE, np.ones((15, 15), np.uint8)) > 0
    away = outline & ~edges
    return {"missing": float(missing.mean()), "edge dropout": float(missing[edges].mean()) if edges.any() else 0.0,
            "speckle": float(missing[away].mean()) if away.any() else 0.0, "k": noise_k(d, on),
            "k plane": noise_k(d, np.abs(height) < CLIP, height),
            "tilt": float(np.degrees(plane.tilt))}


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--data", type=Path, default=SHARED_DATA, help="shared data folder")
    parser.add_argument("--sim", type=int, default=0, metavar="N", help="also N rendered scenes per sensor preset")
    args = parser.parse_args(argv)
    real = (args.data / "rgbd").is_dir()
    if not real and not args.sim:
        print(f"no real frames under {args.data / 'rgbd'}: nothing to measure", file=sys.stderr)
        return 1
    print("| frame | tilt (deg) | missing | edge dropout | speckle | k, pixel (mm at 1 m) | k, plane (mm at 1 m) |")
    print("|---|---:|---:|---:|---:|---:|---:|")
    groups: dict[str, list[dict]] = {}
    for name, depth, intrinsics in [*(frames(args.data) if real else ()), *rendered(args.sim)]:
        try:
            groups.setdefault(name, []).append(statistics(depth, intrinsics))
        except ContourGraspError as err:
            print(f"| {name} | - | - | - | - | - | {err} |")
    for name, found in groups.items():
        s = {key: float(np.mean([f[key] for f in found])) for key in found[0]}
        count = f" (mean of {len(found)})" if len(found) > 1 else ""
        print(f"| {name}{count} | {s['tilt']:.0f} | {s['missing']:.1%} | {s['edge dropout']:.1%} | "
              f"{s['speckle']:.1%} | {1000 * s['k']:.2f} | {1000 * s['k plane']:.2f} |", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
