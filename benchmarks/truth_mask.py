"""Bench trials planned twice: with perception's segmentation (the bench's) and with the exact footprint.

Does the segmentation's error cost grasps in a scene? Each trial (the bench's scene, seed, picture,
planner and execution) is run as ``contourgrasp bench`` runs it, and again with ``plan_frame`` given the
target's exact footprint (:func:`contourgrasp.sim.render.object_truth`) as the user's mask. The mask is
read as a footprint on the table (``Segmentation.on_table``, as perception's own footprint of a tilted
view is), so the second plan starts from the outline a perfect segmentation would give; everything after
it (the table plane, the height map and its neighbours, the search) is the planner's.

Usage::

    .venv/bin/python benchmarks/truth_mask.py --scene clutter --objects ycb-train --trials 3 [--workers 2]
"""

import argparse
import collections
import dataclasses
import multiprocessing
import time
import warnings

from contourgrasp import load_hand, perception, pipeline
from contourgrasp.sim.planners import make_planner
from contourgrasp.sim.render import object_truth
from contourgrasp.sim.trial import run_trial, trial_scene
from contourgrasp.sim.ycb import OBJECT_SETS, load_object, object_names

HAND = "five-finger-linear"


#: The library's reading of a user's mask, which :func:`trial_pair` replaces by :func:`_as_footprint`.
_user_mask = perception.segment_from_mask


def _as_footprint(mask, **options):
    return dataclasses.replace(_user_mask(mask, **options), on_table=True)


def trial_pair(task: tuple[str, str, int, str]) -> tuple[str, int, dict]:
    """One trial's outcome (success, cause) with the bench's segmentation and with the exact footprint."""
    warnings.simplefilter("ignore")
    perception.segment_from_mask = _as_footprint
    name, split, seed, kind = task
    hand = load_hand(HAND)
    bench = make_planner("default", hand)
    target = load_object(name)
    others = [load_object(f"ycb:{n}") for n in OBJECT_SETS[split] if f"ycb:{n}" != name]
    _, footprint = object_truth(trial_scene(target, seed=seed, scene_kind=kind, pool=others, hand=hand))

    def exact(rgb, depth, intrinsics, *, target_px=None):
        planned = pipeline.plan_frame(rgb, depth, intrinsics, hand, mask=footprint, **dict(bench.options))
        return planned.T_camera_hand, planned.metric.approach_depth, planned.grasp_height

    outcomes = {}
    for label, planner in (("segmented", bench), ("exact footprint", exact)):
        record = run_trial(target, seed=seed, planner=planner, hand=hand, scene_kind=kind, pool=others)
        outcomes[label] = (record.success, record.cause)
    return name, seed, outcomes


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scene", choices=("single", "clutter", "bin"), default="clutter")
    parser.add_argument("--objects", choices=("ycb-train", "ycb-test"), default="ycb-train")
    parser.add_argument("--trials", type=int, default=3, help="per object: seeds 0 .. trials-1, as the bench's")
    parser.add_argument("--workers", type=int, default=2)
    args = parser.parse_args()
    tasks = [(name, args.objects, seed, args.scene) for name in object_names(args.objects) for seed in range(args.trials)]
    started = time.perf_counter()
    lifted, causes, changed = collections.Counter(), collections.defaultdict(collections.Counter), []
    with multiprocessing.get_context("spawn").Pool(args.workers) as pool:
        for name, seed, outcomes in pool.imap(trial_pair, tasks):
            for label, (success, cause) in outcomes.items():
                lifted[label] += success
                causes[label][cause or "lifted"] += 1
            if len({success for success, _ in outcomes.values()}) > 1:
                changed.append(f"{name} seed {seed}: " + ", ".join(f"{label} {cause or 'lifted'}"
                                                                   for label, (_, cause) in outcomes.items()))
    print(f"{len(tasks)} trials ({args.scene}, {args.objects}) in {time.perf_counter() - started:.0f} s\n")
    print("| segmentation | lifted | causes |\n|---|---:|---|")
    for label, counts in causes.items():
        print(f"| {label} | {lifted[label]} of {len(tasks)} | {', '.join(f'{c} {n}' for c, n in counts.most_common())} |")
    print("\nTrials lifted by one and not the other:\n" + "\n".join(f"- {line}" for line in changed))


if __name__ == "__main__":
    main()
