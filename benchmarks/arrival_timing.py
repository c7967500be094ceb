"""When each finger reaches the object: the plan's free-air timing against the bench's first contacts.

The ratio cost (thesis 3.4, eq 3.35-3.37) balances the fingers' arrival by
their virtual starts, derived from the hand closing in free air
(:mod:`contourgrasp.sim.calibrate`, ``hand-from-model``). This script asks
whether that timing describes the closing on an object. For each trial of
the bench's ``default`` planner it reads, per finger the plan has touching,
the *planned* arrival -- the time the finger, closing in free air, takes to
travel its planned distance ``lam`` to the grasp point -- and the *observed*
one, the trial's first contact of that finger (seconds from the start of the
closing, as :class:`~contourgrasp.sim.trial.GraspOutcome` records it). It
prints, per finger, how much earlier (negative) or later the contact came
than planned, over the contacts both within the closing ramp, and the spread
of the planned arrivals within a plan (how balanced the plan itself is by
the free-air timing).

It also compares the fingers the plan has *missing* -- closing on air, their
closest approach ``gap`` short of the outline -- with the fingers that touched
in the trial: per band of ``gap``, how many touched anyway; and the trials'
success with and without such an unplanned contact.

Usage::

    .venv/bin/python benchmarks/arrival_timing.py --hand-model inspire --objects ycb-train --trials 4
    .venv/bin/python benchmarks/arrival_timing.py --hand five-finger-linear --objects ycb-train --trials 4
"""

import argparse
import warnings

import numpy as np

from contourgrasp.errors import ContourGraspError
from contourgrasp.io.hand_file import load_hand
from contourgrasp.sim import bench
from contourgrasp.sim.calibrate import measure_closing
from contourgrasp.sim.model_hand import close_model, model_closing, model_spec
from contourgrasp.sim.model_mount import mount_model
from contourgrasp.sim.planners import make_planner
from contourgrasp.sim.trial import Execution


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    hands = parser.add_mutually_exclusive_group()
    hands.add_argument("--hand", default=None, help="a preset or hand file the simulation builds (ray fingers)")
    hands.add_argument("--hand-model", default=None, help="a bundled hand model (inspire, jaco-three-finger)")
    parser.add_argument("--objects", default="ycb-train")
    parser.add_argument("--trials", type=int, default=4)
    args = parser.parse_args(argv)
    if args.trials < 1:
        parser.error(f"--trials must be at least 1, got {args.trials}")
    try:
        objects, splits = bench.resolve_objects(args.objects)
        if args.hand_model is not None:
            mounted = mount_model(args.hand_model)
            hand, closing = mounted.hand, model_closing(mounted.hand, close_model(model_spec(args.hand_model)))
        else:
            mounted, hand = None, load_hand(args.hand or "five-finger-linear")
            closing = measure_closing(hand)
    except ContourGraspError as err:
        parser.error(str(err))
    setup = bench.Bench(objects=objects, planners=("default",), trials=args.trials, hand=hand, hand_model=mounted,
                        splits=splits)
    late, spread = {name: [] for name in closing.names}, []
    gaps, unplanned = [], {True: [], False: []}
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        for obj in setup.objects:
            for trial in range(args.trials):
                planned, observed, missed, success = _trial(setup, obj, trial, closing)
                gaps += [(gap, name in observed) for name, gap in missed.items()]
                if planned:
                    unplanned[bool(missed.keys() & observed.keys())].append(success)
                if len(planned) > 1:
                    spread.append(max(planned.values()) - min(planned.values()))
                for name, at in planned.items():
                    if name in observed and max(at, observed[name]) < Execution().close_time:
                        late[name].append(observed[name] - at)
    print(f"{hand.name}, {len(setup.objects)} objects x {args.trials} trials: first contact minus planned arrival, s")
    print(f"{'finger':8s} {'contacts':>8s} {'mean':>7s} {'median':>7s} {'sd':>6s}")
    for name, values in late.items():
        v = np.array(values)
        print(f"{name:8s} {len(v):8d} " + (f"{v.mean():+7.3f} {np.median(v):+7.3f} {v.std():6.3f}" if len(v) else ""))
    if spread:
        print(f"planned arrivals within a plan: spread median {np.median(spread):.3f} s, "
              f"90th percentile {np.percentile(spread, 90):.3f} s ({len(spread)} plans)")
    _print_missed(gaps, unplanned)
    return 0


#: Bands of a missed finger's planned ``gap``, m.
GAP_BANDS = (0.0, 0.003, 0.006, 0.009, 0.012, 0.02, 0.05, np.inf)


def _print_missed(gaps, unplanned) -> None:
    """The fingers planned to miss that touched anyway, per band of their gap; success with and without one."""
    print("fingers the plan has missing: planned gap, mm | fingers | touched in the trial")
    for lo, hi in zip(GAP_BANDS, GAP_BANDS[1:]):
        touched = [t for gap, t in gaps if lo <= gap < hi]
        print(f"{1e3 * lo:3.0f}-{1e3 * hi:<3.0f} | {len(touched):4d} | {sum(touched):4d}")
    for flag, label in ((True, "with a finger planned missing touching"), (False, "without")):
        print(f"trials {label}: {len(unplanned[flag])}, lifted {sum(unplanned[flag])}")


def _trial(setup, obj, trial, closing):
    """(planned, observed, missed, success): per finger the planned arrival and the first contact, s; the
    planned gap of each finger the plan has missing, m; whether the trial lifted the object."""
    planner, plans = make_planner("default", setup.hand, seed=setup.seed + trial), []

    def plan(rgb, depth, intrinsics, **target):
        planned = planner.plan(rgb, depth, intrinsics, **target)
        plans.append(planned.plan)
        return planned.T_camera_hand, planned.approach_depth, planned.grasp_height

    record = setup.run("default", obj, trial, plan=plan)
    planned, missed = {}, {}
    if plans and plans[0] is not None:
        for i, finger in enumerate(plans[0].fingers):
            if finger.missed:
                missed[finger.name] = finger.gap
            else:
                planned[finger.name] = float(closing.arrival_times(i, np.array([finger.lam]))[0])
    return planned, dict(record.first_contact), missed, record.success


if __name__ == "__main__":
    raise SystemExit(main())
