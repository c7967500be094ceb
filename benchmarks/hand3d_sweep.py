"""The 3-D hand's rules tuned on the training objects (issue 16): success of planner variants in simulated trials.

Each variant is ``default`` (the 2-D planner of the thesis's method on the dense grid) with the 3-D options
(``descent``, ``grasp_height="auto"``, ...) and, optionally, the "auto" rule's two height fractions
(``tolerances.GRASP_HEIGHT_FRACTION``, ``MAX_GRASP_HEIGHT_FRACTION``). Trials are the bench's (same seeds:
trial k of an object uses seed k), on ``ycb-train`` by default -- never run it on ``ycb-test`` to choose
anything. Prints per variant the lifts out of the trials and the failure causes.

Usage::

    .venv/bin/python benchmarks/hand3d_sweep.py --trials 4 \\
        --variant "base: descent=True, grasp_height='auto' @ 0.4:0.7" \\
        --variant "small: descent=True, grasp_height='auto', small_objects=True @ 0.4:0.7" [--objects ycb-train]

A variant is ``name: option=value, ... [@ fraction:max_fraction]``; the options are ``plan_frame``'s.
Results of the runs that chose ``default``'s 3-D settings: benchmarks/hand3d_sweep.md.
"""

import argparse
import collections
import itertools
import multiprocessing

from contourgrasp import tolerances as tol


def parse_variant(text: str) -> tuple[str, dict, tuple[float, float]]:
    name, _, rest = text.partition(":")
    options, _, fractions = rest.partition("@")
    parsed = eval(f"dict({options.strip()})", {"dict": dict, "True": True, "False": False})  # noqa: S307 (our own command line)
    low, high = (float(v) for v in fractions.split(":")) if fractions.strip() else (tol.GRASP_HEIGHT_FRACTION,
                                                                                  tol.MAX_GRASP_HEIGHT_FRACTION)
    return name.strip(), parsed, (low, high)


def trial(task):
    variant, obj, seed = task
    from contourgrasp.io.hand_file import load_hand
    from contourgrasp.io.planner_file import load_planner
    from contourgrasp.sim.planners import SynthesisPlanner
    from contourgrasp.sim.trial import run_trial
    from contourgrasp.sim.ycb import load_object

    name, options, (tol.GRASP_HEIGHT_FRACTION, tol.MAX_GRASP_HEIGHT_FRACTION) = variant
    hand = load_hand("five-finger-linear")
    base = {k: v for k, v in load_planner("default").options
            if k not in ("descent", "grasp_height", "slice_contour", "closing_sweep", "small_objects")}
    planner = SynthesisPlanner(hand, tuple((base | options).items()))
    record = run_trial(load_object(obj), seed=seed, planner=planner, hand=hand)
    return name, record.cause or "lifted"


def main() -> None:
    from contourgrasp.sim.ycb import object_names

    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--variant", action="append", required=True, help="name: options [@ fraction:max]")
    parser.add_argument("--objects", default="ycb-train")
    parser.add_argument("--trials", type=int, default=4)
    parser.add_argument("--workers", type=int, default=2)
    args = parser.parse_args()
    variants = [parse_variant(v) for v in args.variant]
    tasks = list(itertools.product(variants, object_names(args.objects), range(args.trials)))
    with multiprocessing.Pool(args.workers) as pool:
        results = pool.map(trial, tasks, chunksize=1)
    for name, *_ in variants:
        causes = collections.Counter(cause for n, cause in results if n == name)
        total = sum(causes.values())
        print(f"{name}: {causes['lifted']}/{total} lifted; " + ", ".join(f"{c} {k}" for k, c in causes.most_common()
                                                                      if k != "lifted"))


if __name__ == "__main__":
    main()
