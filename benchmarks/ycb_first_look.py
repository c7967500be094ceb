"""A first look at a planner on YCB objects of ``ycb-train`` (never ``ycb-test``): rates and failure causes.

Runs the bench's own trials (:class:`~contourgrasp.sim.bench.Bench`, seeds
``seed + t``) on YCB objects with their YCB masses and material frictions
(:mod:`contourgrasp.sim.ycb`), and writes the bench's outputs (``table.md``,
``trials.json``, figures) to ``--out``. Until ``contourgrasp bench --objects``
takes YCB names, this is the way to run them. Warm the CoACD cache first
(``python -m contourgrasp.sim.ycb ycb-train``) or the first run decomposes.

Usage::

    .venv/bin/python benchmarks/ycb_first_look.py [--objects ycb-train] [--trials 3] [--planners default]
"""

import argparse
import collections
import time

from contourgrasp.sim import bench, ycb


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--objects", default="ycb-train", help="as --objects of the bench, YCB names included")
    parser.add_argument("--trials", type=int, default=3)
    parser.add_argument("--planners", default="default")
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--out", default="ycb-first-look")
    args = parser.parse_args()
    if any(n.removeprefix(ycb.PREFIX) in ycb.YCB_TEST for n in ycb.object_names(args.objects)):
        parser.error("ycb-test objects are for reporting, not for looking at while tuning")
    started = time.perf_counter()
    setup = bench.Bench(objects=ycb.resolve_objects(args.objects), planners=tuple(args.planners.split(",")),
                        trials=args.trials, seed=args.seed)
    with bench.console_progress(setup.size) as progress:
        results = bench.run_bench(setup, progress)
    bench.write_outputs(setup, results, args.out, wall_time=time.perf_counter() - started)
    for planner in setup.planners:
        mine = [r for r in results if r.planner == planner]
        causes = collections.Counter(r.record.cause for r in mine if not r.record.success)
        print(f"{planner}: {sum(r.record.success for r in mine)}/{len(mine)} lifted; failures: {dict(causes)}")
        for obj in setup.objects:
            rows = [r.record for r in mine if r.record.object == obj.name]
            print(f"  {obj.name:26s} {sum(r.success for r in rows)}/{len(rows)}  "
                  + ", ".join(bench.SHORT_CAUSES[r.cause] for r in rows if not r.success))
    print(f"{len(results)} trials in {time.perf_counter() - started:.0f} s -> {args.out}")


if __name__ == "__main__":
    main()
