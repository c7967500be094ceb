"""How the simulated bench depends on its contact model: the measurements behind ``sim.scene.IMPRATIO``.

Two measurements, neither of which changes the library:

``--squeeze``
    No planner: ``sim.measure.squeeze_creep`` (two pads squeeze a box against gravity with the scene's
    grip contact and solver settings, ``sim.scene.solver_option``) with ``impratio`` (and, with ``--noslip``, MuJoCo's noslip
    iterations) as given; prints how far the box falls in 2 s at several friction margins (the cone's
    limit over the load: above 1 Coulomb friction holds it still, below 1 it slides).
``--objects SPLIT``
    The bench's single-scene trials of ``default`` (seed = trial, as ``contourgrasp bench`` runs them) with
    the hand-object contact's ``solref`` time constant, ``solimp`` or torsional friction
    (``sim.scene.grip_contact``), ``impratio`` or the noslip iterations (``sim.scene.solver_option``) replaced; prints successes and failures by cause.

Usage::

    .venv/bin/python benchmarks/contact_sweep.py --squeeze --impratio 1 10 30 100
    .venv/bin/python benchmarks/contact_sweep.py --objects ycb-train --trials 10 --impratio 100
    .venv/bin/python benchmarks/contact_sweep.py --objects ycb-train --trials 10 --impratio 10 --timeconst 0.005

Results: ``benchmarks/contact_sweep.md``.
"""

import argparse
import collections
import multiprocessing
import warnings

from contourgrasp import load_hand
from contourgrasp.sim import scene as scene_module
from contourgrasp.sim.bench.config import resolve_objects
from contourgrasp.sim.measure import squeeze_creep
from contourgrasp.sim.planners import make_planner
from contourgrasp.sim.trial import run_trial

MARGINS = (0.5, 0.9, 1.2, 2.0, 5.0, 20.0)


def patch_contacts(args) -> None:
    """Replace the scene's solver settings and grip contact in this process (and in the workers it forks)."""
    grip = scene_module.grip_contact

    def patched_grip(obj):
        attributes = grip(obj).replace('solref="0.01 1"', f'solref="{args.timeconst:g} 1"'
                                       + (f' solimp="{args.solimp}"' if args.solimp else ""))
        if args.torsion is not None:
            attributes = attributes.replace(' 0.005 0.0001 0.0001"', f' {args.torsion:g} 0.0001 0.0001"')
        return attributes

    scene_module.grip_contact = patched_grip
    scene_module.SOLVER = scene_module.solver_option(args.impratio[0], args.noslip)


def _trial(task):
    warnings.simplefilter("ignore")
    obj, seed = task
    record = run_trial(obj, seed=seed, planner=make_planner("default", load_hand("five-finger-linear"), seed=seed))
    return obj.name, record.success, record.cause


def main(argv=None) -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--squeeze", action="store_true")
    parser.add_argument("--objects", help="bench objects, e.g. ycb-train")
    parser.add_argument("--trials", type=int, default=10)
    parser.add_argument("--impratio", type=float, nargs="+", default=[scene_module.IMPRATIO])
    parser.add_argument("--noslip", type=int, default=0)
    parser.add_argument("--timeconst", type=float, default=0.01, help="hand-object solref time constant, s")
    parser.add_argument("--solimp", help='hand-object solimp, e.g. "0.5 0.95 0.005"')
    parser.add_argument("--torsion", type=float, help="hand-object torsional friction, m")
    parser.add_argument("--workers", type=int, default=2)
    args = parser.parse_args(argv)
    if args.squeeze:
        print("impratio noslip | drop in 2 s (mm) at friction margins " + " ".join(f"{m:g}" for m in MARGINS))
        for impratio in args.impratio:
            drops = [squeeze_creep(m, impratio=impratio, noslip=args.noslip) * 1e3 for m in MARGINS]
            print(f"{impratio:8g} {args.noslip:6d} | " + " ".join(f"{d:9.2f}" for d in drops))
    if args.objects:
        patch_contacts(args)
        objects, _ = resolve_objects(args.objects)
        tasks = [(obj, t) for obj in objects for t in range(args.trials)]
        with multiprocessing.get_context("fork").Pool(args.workers) as pool:
            rows = pool.map(_trial, tasks, chunksize=1)
        per_object = collections.Counter(name for name, ok, _ in rows if ok)
        causes = collections.Counter(cause for _, ok, cause in rows if not ok)
        print(f"{args.objects}: {sum(per_object.values())}/{len(rows)} lifted; failures {dict(causes)}")
        print("  " + ", ".join(f"{obj.name} {per_object[obj.name]}" for obj in objects))


if __name__ == "__main__":
    main()
