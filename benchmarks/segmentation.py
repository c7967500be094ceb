"""Segmentation benchmark: IoU against hand-made masks, per method, on the real RGB-D frames.

Every frame of ``<data>/rgbd/*/`` that has ``color_N.png``, ``depth_N.npy`` and
``segmask_N.png`` (and an ``.intr`` file in its folder) is segmented with each
method of :func:`contourgrasp.perception.segment` (and with depth without the
footprint, "depth, seen": the pixels that see the object); the script prints a
Markdown table of the IoU per frame, the mean, the worst frame and the time
per frame. A refused frame (SegmentationError) scores IoU 0; a note in brackets
says which method ``auto`` used (``depth``, ``depth+rgb`` or ``rgb``) and by how much
it shifted the colour image onto the depth image (``Segmentation.colour_offset_px``).

A second table (:func:`print_real_grey`) scores ``auto`` on the same frames with
the colour image turned grey and stored as three equal channels (ITU-R 601
luma), as a grayscale camera's driver stores it, against ``auto`` on colour.
The rendered frames below are scored in grey too (:func:`print_simulated_grey`).

A third table scores ``auto`` against exact truth, on frames the simulation
renders (:func:`contourgrasp.sim.render`, with the bench's depth sensor, or ``--sensor``'s) of the five
thesis objects and a dark grey tool with a flat plate
(:func:`contourgrasp.sim.objects.flat_tool`), and the same tool in a yellow as
light as the table in grey (``YELLOW``), ``--sim-seeds`` placements each,
from a camera 0.7 m from the table with the PrimeSense intrinsics, looking
straight down and tilted 12.7 deg as the real frames are
(:func:`contourgrasp.sim.tilted_view`); the colour image is misregistered by
``SIM_COLOUR_SHIFT`` px, as the real frames' are, for ``auto`` to find. The truth is
:func:`contourgrasp.sim.object_truth`: the pixels that see the object, and its
footprint (the pixels that see the table where the object stands). ``auto``
aims at the first from a top-down camera and at the second from a tilted one
(its mean is in bold). This table needs no shared data.

A last table scores the scenes of several objects of the bench
(:mod:`contourgrasp.sim.clutter`: ``clutter``, 2-4 YCB objects on the table,
and ``bin``, 1-3 in a bin; the bench's SR300 camera, tilted 0-25 deg by the
seed, its depth sensor), ``--scene-seeds`` scenes per kind and YCB split, the
target the seed's object of the split and its neighbours the split's others,
as in ``contourgrasp bench --scene``. Per kind and split: the target's IoU
when perception is given the target's pixel (:func:`contourgrasp.sim.target_pixel`,
as the bench gives it) against the exact footprint (camera tilted more than
2 deg) or the exact region seen (:func:`contourgrasp.sim.object_truth`, what
``auto`` aims at), a refused frame scoring 0, and how many targets score below
``MATCH_IOU`` (another object planned on, or a merged one); and the candidates
(:func:`contourgrasp.perception.find_candidates` on the fitted table plane)
against the objects present (:func:`contourgrasp.sim.truth_labels`, those
seen by at least ``MIN_AREA_PX`` pixels): how many were found, and how many
objects one candidate matches to IoU >= 0.5 (the bin's walls are a candidate
of their own, matching no object); and the target's IoU with the frame in grey
(:func:`grey`, a refused frame scoring 0); and the single view's ceiling
(:func:`_ceiling`): the target IoU a perfect segmentation would score, the
exact region seen, with exact depth, moved onto the table as perception moves
it, against the exact footprint -- what the object's hidden parts leave out of
reach of a footprint built, as perception builds it, from the surface the
camera sees. ``--worst N`` then lists each kind and split's N targets of lowest
IoU, with their scenes (seed, camera tilt, target, neighbours).

Usage::

    python benchmarks/segmentation.py [--data PATH] [--repeat N] [--sim-seeds N] [--scene-seeds N] [--sensor NAME]
        [--worst N]

``--data`` defaults to ``$CONTOURGRASP_SHARED_DATA`` or ``../shared/data``
beside the repository.
"""

from __future__ import annotations

import argparse
import os
import sys
import time
import warnings
from collections import Counter
from dataclasses import replace
from pathlib import Path

import numpy as np

from contourgrasp import perception, pipeline
from contourgrasp.errors import InputError
from contourgrasp.io.camera_file import read_masked_frames
from contourgrasp.perception import SegmentationError, register_colour, segment
from contourgrasp.sim import (DEFAULT_SENSOR, SENSORS, Camera, Intrinsics, build_clutter, build_scene, object_truth, render, target_pixel,
                              tilted_view, truth_labels)
from contourgrasp.sim.objects import flat_tool
from contourgrasp.tolerances import MIN_AREA_PX

#: Targets for the default method (from the perception issue).
TARGET_MEAN, TARGET_WORST = 0.90, 0.75
#: Table columns: (heading, method, depth options). "depth, seen" is depth without the footprint.
COLUMNS = (("rgb", "rgb", None), ("depth, seen", "depth", {"footprint": False}), ("depth", "depth", None),
           ("auto", "auto", None))
#: The yellow tool's colour: unlike the table's in colour, as light in grey (ITU-R 601 luma 0.82 against the table's
#: 0.84: 5 grey levels apart); in grey only depth tells its flat plate from the table.
YELLOW = (1.0, 0.85, 0.2, 1.0)
#: The simulated frames: objects, camera tilts (deg), a camera like the real frames' PrimeSense, and a
#: colour-depth misregistration like theirs: depth pixel (u + dx, v + dy) sees colour pixel (u, v).
SIM_OBJECTS = {"can": "can", "case": "case", "bottle": "bottle", "stone1": "stone1", "stone2": "stone2",
               "tool": flat_tool(), "yellow tool": replace(flat_tool(), name="yellow tool", rgba=YELLOW)}
SIM_TILTS_DEG = (0.0, 12.7)
SIM_COLOUR_SHIFT = (1, -3)
SIM_CAMERA = Camera(height=0.7, intrinsics=Intrinsics(fx=525.0, fy=525.0, cx=319.5, cy=239.5, width=640, height=480))


def default_data() -> Path:
    return Path(os.environ.get("CONTOURGRASP_SHARED_DATA", Path(__file__).resolve().parents[2] / "shared" / "data"))


def frames(data: Path):
    """(name, rgb, depth, intrinsics, truth) for every frame with a ground-truth mask."""
    for name, frame in read_masked_frames(data / "rgbd"):
        yield name, frame.rgb, frame.depth, frame.intrinsics, frame.mask


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
    notes = [] if result.method == method else [f"used {result.method}"]
    if result.colour_offset_px is not None:
        notes.append("colour shifted ({}, {}) px".format(*result.colour_offset_px))
    return iou(result.mask, truth), ", ".join(notes), best


def iou(a, b) -> float:
    return float((a & b).sum() / (a | b).sum())


def simulated(seeds, sensor):
    """Per (object, tilt), one row per seed: IoU of ``auto`` against the exact seen region and footprint,
    IoU of those two against each other, the colour shift ``auto`` found, and IoU of ``auto`` on the frame in
    grey (:func:`grey`) against its aim (the footprint when tilted, else the region seen)."""
    rows = {}
    for name, spec in SIM_OBJECTS.items():
        for seed in range(seeds):
            scene = build_scene(spec, seed=seed, camera=SIM_CAMERA)
            for tilt in SIM_TILTS_DEG:
                view = tilted_view(np.radians(tilt), SIM_CAMERA.height)
                rgb, depth = render(scene, sensor=sensor, seed=seed, view=view)
                misregistered = register_colour(rgb, (-SIM_COLOUR_SHIFT[0], -SIM_COLOUR_SHIFT[1]))
                seen, footprint = object_truth(scene, view)
                with warnings.catch_warnings():
                    warnings.simplefilter("ignore")
                    result = segment(misregistered, depth, SIM_CAMERA.intrinsics)
                    in_grey = segment(grey(misregistered), depth, SIM_CAMERA.intrinsics)
                aim = footprint if tilt > 2 else seen  # tolerances.TILT_PLANE_THRESHOLD: the footprint above 2 deg
                rows.setdefault((name, tilt), []).append(
                    (iou(result.mask, seen), iou(result.mask, footprint), iou(seen, footprint), result.colour_offset_px,
                     iou(in_grey.mask, aim)))
    return rows


def print_simulated(seeds, sensor) -> None:
    rows = simulated(seeds, sensor)
    print(f"\nExact truth, rendered frames ({seeds} placements per object, the `{sensor}` depth sensor, colour "
          f"shifted by {SIM_COLOUR_SHIFT} px): IoU of auto, mean over placements (worst)\n")
    heads = [f"{tilt:g} deg vs {truth}" for tilt in SIM_TILTS_DEG for truth in ("seen", "footprint")]
    print("| object | " + " | ".join(heads) + " |")
    print("|---|" + "---:|" * len(heads))
    for name in SIM_OBJECTS:
        cells = [np.array([r[k] for r in rows[name, tilt]]) for tilt in SIM_TILTS_DEG for k in (0, 1)]
        print(f"| {name} | " + " | ".join(f"{c.mean():.3f} ({c.min():.3f})" for c in cells) + " |")
    means, notes = [], []
    for tilt in SIM_TILTS_DEG:
        every = [r for name in SIM_OBJECTS for r in rows[name, tilt]]
        scores = np.array([r[:3] for r in every])
        aim = 1 if tilt > 2 else 0  # tolerances.TILT_PLANE_THRESHOLD: the footprint above 2 deg
        means += [f"**{m:.3f}**" if k == aim else f"{m:.3f}" for k, m in enumerate(scores[:, :2].mean(axis=0))]
        shifts = ", ".join(f"{shift} on {n}" for shift, n in Counter(r[3] for r in every).items())
        notes.append(f"{tilt:g} deg: auto vs its aim {scores[:, aim].min():.3f}-{scores[:, aim].max():.3f} per frame; "
                     f"exact seen vs exact footprint {scores[:, 2].min():.3f}-{scores[:, 2].max():.3f}; "
                     f"colour shift found {shifts} of {len(every)} frames")
    print("| **mean** | " + " | ".join(means) + " |\n")
    print("\n".join(notes))
    print_simulated_grey(rows)


def print_simulated_grey(rows) -> None:
    """IoU of ``auto`` against its aim on the rendered frames in colour and in grey, per object and tilt."""
    print("\nThe same rendered frames in grey (three equal channels): IoU of auto against its aim, mean (worst)\n")
    heads = [f"{tilt:g} deg, {mode}" for tilt in SIM_TILTS_DEG for mode in ("colour", "grey")]
    print("| object | " + " | ".join(heads) + " |")
    print("|---|" + "---:|" * len(heads))
    columns = {}
    for name in SIM_OBJECTS:
        cells = []
        for tilt in SIM_TILTS_DEG:
            for mode, k in (("colour", 1 if tilt > 2 else 0), ("grey", 4)):
                c = np.array([r[k] for r in rows[name, tilt]])
                columns.setdefault((tilt, mode), []).append(c)
                cells.append(f"{c.mean():.3f} ({c.min():.3f})")
        print(f"| {name} | " + " | ".join(cells) + " |")
    print("| **mean** | " + " | ".join(f"**{np.concatenate(c).mean():.3f}**" for c in columns.values()) + " |")


#: The scenes of several objects scored: kinds and the YCB splits their objects come from.
SCENE_KINDS, SCENE_SPLITS = ("clutter", "bin"), ("ycb-train", "ycb-test")
#: A candidate finds an object when their IoU is at least this.
MATCH_IOU = 0.5


def rendered_scenes(seeds, sensor):
    """Per (kind, split), one (row, scene) pair per scene: the row is target IoU (0 when refused), refused,
    objects present, candidates found, objects matched by a candidate, target IoU in grey; the scene says
    which it is (seed, camera tilt, target and neighbours)."""
    from contourgrasp.sim.ycb import OBJECT_SETS, load_object

    rows = {}
    for split in SCENE_SPLITS:
        objects = [load_object(f"ycb:{name}") for name in OBJECT_SETS[split]]
        for kind in SCENE_KINDS:
            for seed in range(seeds):
                target = objects[seed % len(objects)]
                scene = build_clutter(target, [o for o in objects if o is not target], kind=kind, seed=seed)
                tilt = float(np.degrees(np.arccos(-scene.view[1][2, 2])))
                about = (f"seed {seed}, tilt {tilt:.1f} deg: {target.name}"
                         + (f" beside {', '.join(o.name for o in scene.neighbours)}" if scene.neighbours else " alone"))
                rows.setdefault((kind, split), []).append((_score_scene(scene, seed, sensor), about))
    return rows


def _score_scene(scene, seed, sensor):
    rgb, depth = render(scene, sensor=sensor, seed=seed)
    intr = scene.camera.intrinsics
    labels = truth_labels(scene)
    seen, footprint = object_truth(scene)
    tilted = np.arccos(-scene.view[1][2, 2]) > np.radians(2.0)  # tolerances.TILT_PLANE_THRESHOLD
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        try:
            segmentation = pipeline.perceive(rgb, depth, intr, target_px=target_pixel(scene))[0]
            target_iou, refused = iou(segmentation.mask, footprint if tilted else seen), 0
        except InputError:
            target_iou, refused = 0.0, 1
        try:
            in_grey = pipeline.perceive(grey(rgb), depth, intr, target_px=target_pixel(scene))[0]
            grey_iou = iou(in_grey.mask, footprint if tilted else seen)
        except InputError:
            grey_iou = 0.0
        ceiling = _ceiling(scene, seen, footprint) if tilted else 1.0
        filled, _ = perception.fill_depth_holes(perception.as_depth(depth))
        try:
            candidates = perception.find_candidates(filled, intr, perception.fit_table_plane(filled, intr))
        except SegmentationError:
            candidates = ()
    present = [labels == k for k in range(1, len(scene.neighbours) + 2) if (labels == k).sum() >= MIN_AREA_PX]
    matched = sum(any(iou(c.mask, obj) >= MATCH_IOU for c in candidates) for obj in present)
    return target_iou, refused, len(present), len(candidates), matched, grey_iou, ceiling


def _ceiling(scene, seen, footprint) -> float:
    """IoU with ``footprint`` of the exact region ``seen``, with noiseless depth, moved onto the support surface
    (:func:`contourgrasp.perception.object_footprint` on :func:`contourgrasp.perception.find_support`'s plane, as
    :func:`contourgrasp.pipeline.perceive` does): the best perception's footprint can score from a tilted
    camera, its segmentation perfect. What the camera cannot see (a bottle's base under its shoulders, the far side of a
    tall object) stays out of it."""
    _, depth = render(scene, sensor="ideal")
    d = perception.as_depth(depth)
    intr = scene.camera.intrinsics
    return iou(perception.object_footprint(seen, d, intr, perception.find_support(d, intr).plane), footprint)


def print_rendered_scenes(seeds, sensor, worst: int = 0) -> None:
    """The scenes' table; with ``worst``, then each kind and split's ``worst`` targets of lowest IoU, one per line."""
    scenes = rendered_scenes(seeds, sensor)
    rows = {key: [scores for scores, _ in found] for key, found in scenes.items()}
    print(f"\nScenes of several objects ({seeds} per kind and split, the bench's camera tilted 0-25 deg, the `{sensor}` "
          f"depth sensor): the target given by its pixel, candidates against the objects present\n")
    print(f"| scene | split | target IoU, mean (worst) | targets below {MATCH_IOU} | refused | objects present | "
          f"candidates found | objects found (IoU >= {MATCH_IOU}) | target IoU in grey, mean (worst) | "
          f"single view's ceiling, mean (worst) |")
    print("|---|---|---:|---:|---:|---:|---:|---:|---:|---:|")
    for (kind, split), scores in rows.items():
        a = np.array(scores)
        print(f"| {kind} | {split} | {a[:, 0].mean():.3f} ({a[:, 0].min():.3f}) | {int((a[:, 0] < MATCH_IOU).sum())} | "
              f"{int(a[:, 1].sum())} | {int(a[:, 2].sum())} | {int(a[:, 3].sum())} | {int(a[:, 4].sum())} | "
              f"{a[:, 5].mean():.3f} ({a[:, 5].min():.3f}) | {a[:, 6].mean():.3f} ({a[:, 6].min():.3f}) |")
    if worst <= 0:
        return
    for (kind, split), found in scenes.items():
        print(f"\nThe {worst} worst targets, {kind}, {split}: IoU (in grey; the single view's ceiling), scene")
        for scores, about in sorted(found, key=lambda item: item[0][0])[:worst]:
            print(f"- {scores[0]:.3f} ({scores[5]:.3f}; {scores[6]:.3f}) {about}")


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--data", type=Path, default=default_data(), help="shared data folder")
    parser.add_argument("--repeat", type=int, default=3, help="runs per frame; the best time is kept")
    parser.add_argument("--sim-seeds", type=int, default=3, help="placements per simulated object (0: none)")
    parser.add_argument("--scene-seeds", type=int, default=5,
                        help="scenes of several objects per kind and YCB split (0: none)")
    parser.add_argument("--sensor", default=DEFAULT_SENSOR, choices=tuple(SENSORS),
                        help="the simulated depth sensor of the rendered frames (default: %(default)s, the bench's)")
    parser.add_argument("--worst", type=int, default=0,
                        help="also list each kind and split's WORST targets of lowest IoU, with their scenes")
    args = parser.parse_args(argv)
    rows = list(frames(args.data))
    if rows:
        print_real(rows, args.repeat)
        print_real_grey(rows)
    else:
        print(f"no frames with segmask_N.png found under {args.data}/rgbd: real frames skipped", file=sys.stderr)
    if args.sim_seeds > 0:
        print_simulated(args.sim_seeds, args.sensor)
    if args.scene_seeds > 0:
        print_rendered_scenes(args.scene_seeds, args.sensor, args.worst)
    return 0


def print_real(rows, repeat) -> None:
    headings = [heading for heading, _, _ in COLUMNS]
    ious = {h: [] for h in headings}
    times = {h: [] for h in headings}
    print("| frame | " + " | ".join(f"{h} IoU" for h in headings) + " |")
    print("|---|" + "---:|" * len(COLUMNS))
    for name, rgb, depth, intrinsics, truth in rows:
        cells = []
        for heading, method, depth_options in COLUMNS:
            score, note, seconds = run(rgb, depth, intrinsics, truth, method, depth_options, repeat)
            ious[heading].append(score)
            times[heading].append(seconds)
            cells.append(f"{score:.3f}" + (f" ({note})" if note else ""))
        print(f"| {name} | " + " | ".join(cells) + " |")
    print("| **mean** | " + " | ".join(f"**{np.mean(ious[h]):.3f}**" for h in headings) + " |")
    print("| worst | " + " | ".join(f"{np.min(ious[h]):.3f}" for h in headings) + " |")
    print("| time per frame (ms) | " + " | ".join(f"{1000 * np.mean(times[h]):.0f}" for h in headings) + " |")
    mean, worst = np.mean(ious["auto"]), np.min(ious["auto"])
    verdict = "met" if mean >= TARGET_MEAN and worst >= TARGET_WORST else "NOT met"
    print(f"\nauto (default): mean IoU {mean:.3f} (target >= {TARGET_MEAN}), worst {worst:.3f} "
          f"(target >= {TARGET_WORST}): target {verdict}")


def grey(rgb) -> np.ndarray:
    """(H, W, 3) uint8: ``rgb``'s luma (ITU-R 601) in three equal channels, as a grayscale camera stores it."""
    luma = np.rint(np.asarray(rgb, dtype=float) @ [0.299, 0.587, 0.114]).astype(np.uint8)
    return np.repeat(luma[..., None], 3, axis=2)


def print_real_grey(rows) -> None:
    """IoU of ``auto`` on the real frames in colour and in grey (three equal channels), per frame."""
    print("\nThe same frames in grey (three equal channels): IoU of auto\n")
    print("| frame | colour | grey | grey: method used |")
    print("|---|---:|---:|---|")
    scores = []
    for name, rgb, depth, intrinsics, truth in rows:
        colour, _, _ = run(rgb, depth, intrinsics, truth, "auto", None, 1)
        gray, note, _ = run(grey(rgb), depth, intrinsics, truth, "auto", None, 1)
        scores.append((colour, gray))
        print(f"| {name} | {colour:.3f} | {gray:.3f} | {note} |")
    mean = np.mean(scores, axis=0)
    print(f"| **mean** | **{mean[0]:.3f}** | **{mean[1]:.3f}** | |")


if __name__ == "__main__":
    sys.exit(main())
