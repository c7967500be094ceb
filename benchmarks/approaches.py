"""Which approach lifts the object: every trial planned and executed top-down, from the side and tilted.

For each object and seed the bench's scene is built and photographed (``--sensor``, the bench's
default ``structured-light``), planned with ``default`` three times -- approaches ``top``, ``side`` and ``tilted``
alone -- and each plan executed on a fresh copy of the scene (the same seed builds the same scene; the hand
with a wrist for the side and tilted plans, as the bench gives it). One
JSON line per trial (object, seed, and per kind its cost, success and cause) goes to ``--out``; the
summary prints, per object set, the success of each kind alone and of every way of choosing among them
by cost (the lowest cost, with a penalty added to the side and tilted costs, ``--penalties``), and of
an oracle that knew which would lift. Choose a penalty on the training sets (``ycb-train``,
``procedural:N``) and read ``ycb-test`` and ``procedural-test:N`` beside them, never the other way.

Usage::

    .venv/bin/python benchmarks/approaches.py --objects ycb-train,ycb-test --trials 10 --out approaches.jsonl
    .venv/bin/python benchmarks/approaches.py --summary approaches.jsonl [--penalties 0,100,200]
"""

import argparse
import json
import multiprocessing
import sys
import warnings
from dataclasses import replace
from pathlib import Path

from contourgrasp import load_hand, pipeline
from contourgrasp.errors import ContourGraspWarning, InputError, NoFeasibleGrasp
from contourgrasp.io.planner_file import load_planner
from contourgrasp.sim.render import DEFAULT_SENSOR, render
from contourgrasp.sim.tendon_hand import HandDesign
from contourgrasp.sim.trial import execute_grasp, trial_scene
from contourgrasp.sim.ycb import load_object, object_names

KINDS = ("top", "side", "tilted")
CHOICES = ("top+side", "top+tilted", "top+side+tilted")


def one_trial(job):
    """The JSON record of one (object name, seed): per kind its plan's cost and the execution's outcome."""
    name, seed, sets, sensor = job
    hand = load_hand("five-finger-linear")
    base = load_planner("default").options
    spec = load_object(name)
    record = {"object": name, "seed": seed, "sets": sets}
    rgb, depth = render(trial_scene(spec, seed=seed, hand=hand), sensor=sensor, seed=seed)
    for kind in KINDS:
        options = replace(base, scene=replace(base.scene, approaches=kind))
        scene = trial_scene(spec, seed=seed, hand=hand, design=HandDesign(wrist=kind != "top"))
        try:
            with warnings.catch_warnings():
                warnings.simplefilter("ignore", ContourGraspWarning)
                plan = pipeline.plan_frame(rgb, depth, scene.camera.intrinsics, hand, options)
        except (NoFeasibleGrasp, InputError):
            record[kind] = {"cost": None, "success": False, "cause": "no feasible plan"}
            continue
        outcome = execute_grasp(scene, plan.T_camera_hand, plan.metric.approach_depth, grasp_height=plan.grasp_height)
        record[kind] = {"cost": plan.plan.cost.total, "success": bool(outcome.success), "cause": outcome.cause,
                        "approach": plan.approach.describe(), "balanced": plan.plan.balanced}
    return record


def chosen(record, kinds, penalty):
    """The kind the lowest (penalised) cost picks among ``kinds``; None if none has a plan."""
    costs = {k: record[k]["cost"] + (0.0 if k == "top" else penalty) for k in kinds if record[k]["cost"] is not None}
    return min(costs, key=lambda k: (costs[k], KINDS.index(k))) if costs else None


def _balanced_first(record, kinds) -> bool:
    """Success of the rule of ``pipeline``: the first kind in order whose plan balances the squeeze, else the first
    with a plan."""
    planned = [k for k in kinds if record[k]["cost"] is not None]
    pick = next((k for k in planned if record[k].get("balanced")), planned[0] if planned else None)
    return pick is not None and record[pick]["success"]


def summary(records, penalties) -> list[str]:
    sets = sorted({s for r in records for s in r["sets"]})
    lines = [f"| rule | {' | '.join(sets)} |", "|---|" + "---|" * len(sets)]

    def row(label, succeeded):
        cells = []
        for group in sets:
            mine = [r for r in records if group in r["sets"]]
            cells.append(f"{sum(map(succeeded, mine))}/{len(mine)}")
        lines.append(f"| {label} | {' | '.join(cells)} |")

    for kind in KINDS:
        row(f"{kind} alone", lambda r, k=kind: r[k]["success"])
    for kinds in CHOICES:
        for penalty in penalties:
            def succeeded(r, ks=kinds.split("+"), p=penalty):
                pick = chosen(r, ks, p)
                return pick is not None and r[pick]["success"]
            row(f"{kinds}, penalty {penalty:g}", succeeded)
    for kinds in CHOICES:
        row(f"{kinds}, balanced first", lambda r, ks=kinds.split("+"): _balanced_first(r, ks))
    row("oracle (any kind lifts)", lambda r: any(r[k]["success"] for k in KINDS))
    return lines


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--objects", default="ycb-train,ycb-test")
    parser.add_argument("--trials", type=int, default=10)
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--sensor", default=DEFAULT_SENSOR, help="the bench's sensor names (default: %(default)s)")
    parser.add_argument("--out", type=Path)
    parser.add_argument("--summary", type=Path, help="summarise the JSON lines of an earlier run")
    parser.add_argument("--penalties", default="0,50,100,200,400")
    args = parser.parse_args(argv)
    penalties = [float(p) for p in args.penalties.split(",")]
    if args.summary:
        records = [json.loads(line) for line in args.summary.read_text().splitlines() if line.strip()]
    else:
        sets = {}
        for group in args.objects.split(","):
            for name in object_names([group]):
                sets.setdefault(name, []).append(group)
        jobs = [(name, seed, sets[name], args.sensor) for name in sets for seed in range(args.trials)]
        records = []
        with multiprocessing.get_context("spawn").Pool(args.workers) as pool:
            out = args.out.open("w") if args.out else None
            for k, record in enumerate(pool.imap(one_trial, jobs)):
                records.append(record)
                if out:
                    out.write(json.dumps(record) + "\n")
                    out.flush()
                print(f"{k + 1}/{len(jobs)} {record['object']} {record['seed']}: "
                      + ", ".join(f"{kind} {record[kind]['success']}" for kind in KINDS), file=sys.stderr, flush=True)
            if out:
                out.close()
    print("\n".join(summary(records, penalties)))
    return 0


if __name__ == "__main__":
    sys.exit(main())
