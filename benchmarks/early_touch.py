"""Would the thesis's abort help: how often a grasp whose first finger touches long before the others still lifts.

The thesis's discussion proposes to abort a grasp where one finger touches the object long before the
others (the ratio cost's failure mode: the object is pushed away), open, back off and grasp again. A bench
journal (``trials.jsonl`` of ``contourgrasp bench``) keeps, per trial, when each finger first touched the
object while closing. For every rule "abort when at most K fingers touched within T s of the first
touch" this prints, per planner and object set, how many trials the rule would abort, and how many of
those lifted the object as they were: an abort throws those successes away to re-plan the failures.
The touch times are the simulator's contacts -- what a perfect touch sensor would report -- so the
figures bound what any abort rule built on touch can gain.

Read the training sets (``ycb-train``, ``procedural:N``); ``ycb-test`` and ``procedural-test:N`` are
reported beside them, never chosen on.

Usage::

    .venv/bin/python benchmarks/early_touch.py OUT/trials.jsonl [OUT2/trials.jsonl ...] \
        [--rules 0.2:1,0.3:1,0.3:2,0.5:2]
"""

import argparse
import json
from pathlib import Path

from contourgrasp.sim.ycb import object_names

#: Default abort rules: (seconds after the first touch, at most this many fingers touching by then).
RULES = ((0.2, 1), (0.3, 1), (0.3, 2), (0.5, 2))


def aborted(trial: dict, seconds: float, fingers: int) -> bool:
    """Whether the rule aborts this trial: at most ``fingers`` had touched ``seconds`` after the first touch."""
    times = [t for _, t in trial["first_contact"]]
    return bool(times) and sum(t <= times[0] + seconds for t in times) <= fingers


def object_set(name: str, sets: dict[str, set[str]]) -> str:
    """The set an object belongs to: a YCB split by name, procedural objects by their seed (held out from 10**6)."""
    if name.startswith("proc-"):
        return "procedural-test" if int(name.split("-")[1]) >= 1_000_000 else "procedural"
    return next((s for s, members in sets.items() if name in members), "other")


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("journals", nargs="+", type=Path, help="bench journals (trials.jsonl)")
    parser.add_argument("--rules", default=",".join(f"{t}:{k}" for t, k in RULES),
                        help="abort rules SECONDS:FINGERS, comma-separated")
    args = parser.parse_args(argv)
    rules = [(float(t), int(k)) for t, k in (r.split(":") for r in args.rules.split(","))]
    sets = {s: {n.removeprefix("ycb:") for n in object_names([s])} for s in ("ycb-train", "ycb-test")}
    trials = [json.loads(line) for path in args.journals for line in path.read_text().splitlines()[1:] if line]
    touched = [t for t in trials if t["first_contact"]]
    groups = sorted({(t["planner"], object_set(t["object"], sets)) for t in touched})
    heads = " | ".join(f"abort {t:g} s, <= {k}" for t, k in rules)
    print(f"| planner | set | trials touched | lifted | {heads} |")
    print("|---|---|---:|---:|" + "---:|" * len(rules))
    for planner, group in groups:
        own = [t for t in touched if t["planner"] == planner and object_set(t["object"], sets) == group]
        cells = []
        for seconds, fingers in rules:
            cut = [t for t in own if aborted(t, seconds, fingers)]
            cells.append(f"{len(cut)} ({sum(t['success'] for t in cut)} lifted)")
        lifted = sum(t["success"] for t in own)
        print(f"| {Path(planner).stem} | {group} | {len(own)} | {lifted} | {' | '.join(cells)} |")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
