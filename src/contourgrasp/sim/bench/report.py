"""The bench's outputs: Markdown tables, the trial records as JSON, and writing them all into one folder.

Outputs (:func:`write_outputs`, all written atomically into one folder):

* ``table.md`` -- success rates of every planner beside the thesis's, then per
  planner a table laid out like Table 4.4 (trial rows, object columns, success
  rate row, the thesis's rates) and its causes of failure;
* ``trials.json`` -- one record per trial (:func:`trial_to_dict`);
* ``success.png`` -- success rate per object and planner, the thesis's beside;
* ``trials.png`` -- per planner its first success and first failure with a plan:
  the camera's picture with the plan drawn on it, and the hand at the end of the
  hold seen from the side (:func:`~contourgrasp.sim.bench.figures.trials_figure`).

A bench whose objects come from named sets (:attr:`Bench.splits`, e.g.
``ycb-train`` and ``ycb-test``) is reported per split instead: ``table.md``
holds a per-split summary (rate, 95 % Wilson interval and failure causes per
planner) and a per-object table sorted by ``default``'s rate; ``success.png``
is a bar chart per object and split
(:func:`~contourgrasp.sim.bench.figures.objects_figure`); ``failures.png`` a
mosaic of failed trials (:func:`~contourgrasp.sim.bench.figures.failures_figure`).
"""

from __future__ import annotations

import math
import statistics
from dataclasses import asdict
from pathlib import Path

from ...io.plan_file import atomic_outputs, write_json
from ..planners import BASELINES, ablation_planners, synthesis_planner
from ..clearing import ENDINGS
from ..procedural import FAMILIES, procedural_family
from ..trial import TrialRecord
from .config import SHORT_CAUSES, Bench, BenchTrial, label
from .run import picked_trials, snapshot
from .stats import records, sort_planner, success_rates, thesis_rates, wilson_interval

#: Output file names.
TABLE, TRIALS, CHART, PICTURE, FAILURES = "table.md", "trials.json", "success.png", "trials.png", "failures.png"
#: Failed trials in the mosaic of a bench with splits, at most.
MOSAIC_TILES = 12


def trial_to_dict(result: BenchTrial) -> dict:
    """The JSON record of a trial: planner, trial, then every field of its :class:`TrialRecord` (SI units)."""
    record = asdict(result.record)
    pose = record.pop("pose")
    return {
        "object": record.pop("object"),
        "planner": result.planner,
        "trial": result.trial,
        **record,
        "pose": None if pose is None else dict(zip(("x", "y", "yaw"), pose)),
    }


def trial_from_dict(data: dict) -> BenchTrial:
    """The trial of a :func:`trial_to_dict` record (read back from JSON): equal to the one written."""
    fields = dict(data)
    planner, trial, pose = fields.pop("planner"), fields.pop("trial"), fields.pop("pose")
    fields.setdefault("grasp_height", None)  # journals written before planned grasp heights
    fields["fingers_in_contact"] = tuple(fields["fingers_in_contact"])
    fields["first_contact"] = tuple((finger, t) for finger, t in fields["first_contact"])
    for name in ("outcomes", "detected"):  # journals written before several attempts have none
        fields[name] = tuple(fields.get(name, ()))
    fields["pose"] = None if pose is None else (pose["x"], pose["y"], pose["yaw"])
    return BenchTrial(planner, trial, TrialRecord(**fields))


def write_outputs(bench: Bench, results, out, *, wall_time: float, kept: int = 0) -> list[Path]:
    """Write table.md, trials.json, success.png and trials.png (failures.png too with splits) into ``out``.

    ``out`` is created if missing; returns the paths written.
    """
    from .figures import failures_figure, objects_figure, success_figure, trials_figure

    snapshots = [snapshot(bench, r) for r in picked_trials(results)]
    failed = [snapshot(bench, r) for r in picked_failures(bench, results)] if bench.splits else []
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    names = (TABLE, TRIALS, CHART, PICTURE, *((FAILURES,) if bench.splits else ()))
    paths = [out / name for name in names]
    with atomic_outputs(*paths) as (table, trials, chart, picture, *mosaic):
        Path(table).write_text(markdown(bench, results, wall_time=wall_time, kept=kept), encoding="utf-8")
        write_json([trial_to_dict(r) for r in results], trials)
        chart_figure = objects_figure(bench, results) if bench.splits else success_figure(bench, results)
        chart_figure.savefig(chart, dpi=110, format="png")
        trials_figure(bench, snapshots).savefig(picture, dpi=90, format="png")
        for path in mosaic:
            failures_figure(bench, failed).savefig(path, dpi=80, format="png")
    return paths


def picked_failures(bench: Bench, results, limit: int = MOSAIC_TILES) -> list[BenchTrial]:
    """Failed trials with a plan, one per planner and object: :func:`sort_planner`'s first, lowest rates first.

    The other planners' failures fill the rest, up to ``limit``.
    """
    names = [o.name for o in bench.objects]
    picked = []
    for planner in dict.fromkeys([sort_planner(bench), *bench.planners]):
        rates = success_rates(results, planner, names)
        for name in sorted(names, key=lambda o: (rates[o], names.index(o))):
            picked += [r for r in results if r.planner == planner and r.record.object == name
                       and not r.record.success and r.record.pose is not None][:1]
    return picked[:limit]


def _percent(rate: float | None) -> str:
    return "—" if rate is None else f"{100 * rate:.0f} %"


def _row(cells) -> str:
    return "| " + " | ".join(str(c) for c in cells) + " |"


def _header(first: str, columns, *, left: int = 0) -> list[str]:
    """A table's heading: ``first`` and the first ``left`` columns left-aligned, the others right-aligned."""
    return [_row([first, *columns]), _row(["---", *["---"] * left, *["---:"] * (len(columns) - left)])]


def markdown(bench: Bench, results, *, wall_time: float, kept: int = 0) -> str:
    """The whole of table.md (:func:`split_markdown` for a bench with splits)."""
    if bench.splits:
        return split_markdown(bench, results, wall_time=wall_time, kept=kept)
    lines = [
        "# contourgrasp bench: the grasping experiment of thesis 4.2.4 (Table 4.4), simulated",
        "",
        _setup_text(bench, len(results), wall_time, kept),
        "",
        *planner_notes(bench, results),
        "",
        "## Success rates",
        "",
        "Each cell: success rate and its 95 % Wilson interval.",
        "",
        *rates_table(bench, results),
    ]
    ablation = ablation_table(bench, results)
    if ablation:
        lines += ["", "## Ablation: paper to default", "",
                  "Each step adds default's value of one group of options to the step above (overall success, its "
                  "95 % Wilson interval, and failures by cause).", "", *ablation]
    for planner in bench.planners:
        lines += ["", f"## {planner}", "", *trial_table(bench, results, planner), "",
                  f"Causes of failure ({planner}):", "", *cause_table(bench, results, planner)]
    lines += attempts_section(bench, results) + clearing_section(bench, results)
    lines += ["", "✓ success; ✗ failure and its cause: " + _cause_legend(bench) + ". " + _success_text(bench)]
    return "\n".join(lines) + "\n"


def _simulated(bench: Bench) -> str:
    """How the bench's hand is simulated, for the report's first paragraph."""
    if bench.hand_model is None:
        return "one tendon, the thesis's finger timing"
    return f"the MuJoCo model {Path(bench.hand_model.path).name} simulated as itself, closed by one synergy"


def _cause_legend(bench: Bench) -> str:
    return ", ".join(f"{SHORT_CAUSES[c]} = {c}" for c in bench.causes)


def _success_text(bench: Bench) -> str:
    if bench.protocol == "clear":
        return ("Success: every object of the scene cleared (taken off the table by a grasp the hand told held); "
                "the cause is the last attempt's.")
    text = "Success: lifted at least 0.10 m and moved less than 0.02 m in the hand during the 2 s hold."
    if bench.scene_kind == "single":
        return text
    return (text[:-1] + ", without the hand touching a neighbour or a bin wall while descending or closing, and "
            "no neighbour lifted or knocked off the table (out of the bin).")


def _trials_text(bench: Bench, n_trials: int, wall_time: float, kept: int) -> str:
    resumed = f" ({kept} of them run earlier and kept by --resume)" if kept else ""
    return (f"{len(bench.objects)} object(s) x {bench.trials} trial(s) x {len(bench.planners)} planner(s) = "
            f"{n_trials} trials in {wall_time:.0f} s wall time{resumed}. Hand `{bench.hand.name}` ({_simulated(bench)}"
            f"); depth sensor `{bench.sensor}`{_tilt_text(bench)}; trial t uses seed {bench.seed} "
            f"+ t, the same scene for every planner.{_scene_text(bench)}")


def _tilt_text(bench: Bench) -> str:
    tilt = "" if bench.tilt is None else f", the camera tilted {math.degrees(bench.tilt):.0f} deg"
    return tilt + (", a robot arm in view (seen, never touched)" if bench.robot else "")


def _scene_text(bench: Bench) -> str:
    """What a ``clutter`` or ``bin`` scene is (nothing for ``single``)."""
    if bench.scene_kind == "single":
        return ""
    what = ("2-4 objects on the table" if bench.scene_kind == "clutter" else
            "1-3 objects in a bin (walls 10 cm, floor 40 x 30 cm)")
    tilt = '0-25 deg' if bench.tilt is None else f'{math.degrees(bench.tilt):.0f} deg'
    if bench.protocol == "clear":
        return (f" Scene `{bench.scene_kind}`: {what}, each object in turn the first placed among neighbours drawn "
                f"from the other objects of its split, touching or up to 4 cm apart; the camera tilted {tilt}. "
                "Protocol `clear`: pick until the table is empty, nothing can be planned or two attempts in a row "
                "fail, the planner choosing what to pick (docs/bench.md, 'Clearing a table').")
    return (f" Scene `{bench.scene_kind}`: {what}, each object in turn the target among neighbours drawn from the "
            f"other objects of its split, touching or up to 4 cm apart; the camera tilted {tilt}; the planner is "
            "given the pixel deepest inside the target's exact mask, as a user's click.")


def _setup_text(bench: Bench, n_trials: int, wall_time: float, kept: int = 0) -> str:
    return (f"{_trials_text(bench, n_trials, wall_time, kept)} The thesis's rates are from a real arm and hand, "
            f"ours from the simulation; with {bench.trials} trial(s) per object a rate's standard error is up to "
            f"{50 / math.sqrt(bench.trials):.0f} points.")


def _rate_cell(own) -> str:
    return _rate_cell_of([r.success for r in own])


def rates_table(bench: Bench, results) -> list[str]:
    """Success rate and its 95 % Wilson interval per planner (rows) and object (columns), Table 4.4's first."""
    objects = [o.name for o in bench.objects]
    lines = [*_header("planner", [label(o) for o in objects] + ["all"]),
             _row(["thesis, real robot (Table 4.4)", *map(_percent, thesis_rates(objects).values())])]
    for planner in bench.planners:
        name = planner + (" (baseline)" if planner in BASELINES else "")
        cells = [_rate_cell(records(results, planner, o)) for o in objects] + [_rate_cell(records(results, planner))]
        lines.append(_row([name, *cells]))
    return lines


def ablation_table(bench: Bench, results) -> list[str]:
    """The ablation from ``paper`` to ``default`` (rows in step order, those the bench ran): rates and causes."""
    steps = [p.name for p in ablation_planners()]
    names = {name: name for name in steps[:-1]} | {steps[-1]: "default"}
    rows = [(step, planner) for step, planner in names.items() if planner in bench.planners]
    lines = _header("step", ["all", *(SHORT_CAUSES[c] for c in bench.causes)])
    for step, planner in rows:
        own = records(results, planner)
        shown = step if planner == step else f"{step} = `default`"
        lines.append(_row([shown, _rate_cell(own), *(sum(r.cause == c for r in own) for c in bench.causes)]))
    return lines if rows else []


def planner_notes(bench: Bench, results) -> list[str]:
    """One bullet per planner: what it is, its settings, its median planning time."""
    notes = []
    for planner in bench.planners:
        times = [r.plan_time for r in records(results, planner)]
        timing = f" Median planning time {statistics.median(times):.2f} s."
        settings = synthesis_planner(planner)
        if settings is None:
            notes.append(f"- `{planner}` (baseline): {BASELINES[planner]}.{timing}")
            continue
        text = ", ".join(f"{k}={_option(k, v)}" for k, v in settings.settings) or "the library's defaults"
        notes.append(f"- `{planner}`: `plan_grasp` with {text}.{timing}")
    return notes


def _option(name: str, value) -> str:
    if name == "yaw_step":
        return f"{math.degrees(value):g}°"
    return f"{value}"


def trial_table(bench: Bench, results, planner: str) -> list[str]:
    """Table 4.4's layout for one planner: a row per trial, a column per object, rates last."""
    objects = [o.name for o in bench.objects]
    own = {(r.record.object, r.trial): r.record for r in results if r.planner == planner}
    lines = _header("trial", [label(o) for o in objects])
    for trial in range(bench.trials):
        cells = ["✓" if own[o, trial].success else f"✗ {SHORT_CAUSES[own[o, trial].cause]}" for o in objects]
        lines.append(_row([trial + 1, *cells]))
    rates = success_rates(results, planner, objects)
    thesis = thesis_rates(objects)
    lines.append(_row(["**success rate**", *(f"**{_percent(rates[o])}**" for o in objects)]))
    lines.append(_row(["thesis (Table 4.4)", *(_percent(thesis[o]) for o in objects)]))
    return lines


def cause_table(bench: Bench, results, planner: str) -> list[str]:
    """Failures of one planner by cause (rows) and object (columns)."""
    objects = [o.name for o in bench.objects]
    own = records(results, planner)
    lines = _header("cause", [label(o) for o in objects] + ["all"])
    for cause in bench.causes:
        counts = [sum(r.cause == cause for r in own if r.object == o) for o in objects]
        lines.append(_row([cause, *counts, sum(counts)]))
    return lines


def split_markdown(bench: Bench, results, *, wall_time: float, kept: int = 0) -> str:
    """table.md of a bench with splits: setup, planners, per split, per object, the ablation."""
    splits = ", ".join(f"{name} ({len(members)} objects)" for name, members in bench.splits)
    scene = "" if bench.scene_kind == "single" else f", scene `{bench.scene_kind}`"
    lines = [
        f"# contourgrasp bench: {splits}{scene}, simulated",
        "",
        _split_setup_text(bench, len(results), wall_time, kept),
        "",
        *planner_notes(bench, results),
        "",
        "## Per split",
        "",
        "Each cell: success rate, its 95 % Wilson interval, and successes / trials.",
        "",
        *split_table(bench, results),
        "",
        "Failures by cause:",
        "",
        *split_cause_table(bench, results),
        "",
        "## Per object",
        "",
        f"Sorted by `{sort_planner(bench)}`'s rate, highest first; each cell: success rate and its 95 % Wilson "
        f"interval; last, `{sort_planner(bench)}`'s failures by cause.",
        "",
        *object_table(bench, results),
    ]
    lines += attempts_section(bench, results) + clearing_section(bench, results)
    families = family_table(bench, results)
    if families:
        lines += ["", "## Per family (procedural objects)", "",
                  "Each cell: success rate, its 95 % Wilson interval, and successes / trials, every split's "
                  f"objects of the family together; last, `{sort_planner(bench)}`'s failures by cause.", "",
                  *families]
    ablation = ablation_table(bench, results)
    if len(ablation) > 3:  # more than one step ran
        lines += ["", "## Ablation: paper to default", "", *ablation]
    lines += ["", _success_text(bench) + " Causes: " + _cause_legend(bench) + "."]
    return "\n".join(lines) + "\n"


def _split_setup_text(bench: Bench, n_trials: int, wall_time: float, kept: int = 0) -> str:
    return (f"{_trials_text(bench, n_trials, wall_time, kept)} With {bench.trials} trial(s) per object an object's rate has a standard "
            f"error of up to {50 / math.sqrt(bench.trials):.0f} points; a split's intervals are below.")


def _groups(bench: Bench) -> list[tuple[str, tuple[str, ...]]]:
    """The splits, then objects in none of them ("other"), then every object ("all")."""
    named = {m for _, members in bench.splits for m in members}
    other = tuple(o.name for o in bench.objects if o.name not in named)
    groups = [*bench.splits, *((("other", other),) if other else ())]
    everything = tuple(o.name for o in bench.objects)
    return groups if len(groups) == 1 and set(groups[0][1]) == set(everything) else [*groups, ("all", everything)]


def _groups_or_all(bench: Bench) -> list[tuple[str, tuple[str, ...]]]:
    """:func:`_groups` of a bench with splits; every object as one group, "all", of one without."""
    return _groups(bench) if bench.splits else [("all", tuple(o.name for o in bench.objects))]


def _of(results, planner: str, members) -> list:
    return [r for r in records(results, planner) if r.object in members]


def split_table(bench: Bench, results) -> list[str]:
    """Success rate, its 95 % Wilson interval and the counts per planner (rows) and split (columns)."""
    groups = _groups(bench)
    lines = _header("planner", [name for name, _ in groups])
    for planner in bench.planners:
        name = planner + (" (baseline)" if planner in BASELINES else "")
        cells = []
        for _, members in groups:
            own = _of(results, planner, members)
            cells.append(_counted_cell([r.success for r in own]))
        lines.append(_row([name, *cells]))
    return lines


def split_cause_table(bench: Bench, results) -> list[str]:
    """Failures per planner and split (rows) by cause (columns)."""
    lines = _header("planner", ["split", *(SHORT_CAUSES[c] for c in bench.causes)], left=1)
    for planner in bench.planners:
        for split, members in _groups(bench):
            own = _of(results, planner, members)
            lines.append(_row([planner, split, *(sum(r.cause == c for r in own) for c in bench.causes)]))
    return lines


def object_table(bench: Bench, results) -> list[str]:
    """A row per object, sorted by :func:`sort_planner`'s rate (highest first): split, every planner's rate, causes."""
    planner = sort_planner(bench)
    names = [o.name for o in bench.objects]
    rates = success_rates(results, planner, names)
    lines = _header("object", ["split", *bench.planners, f"{planner}'s failures"], left=1)
    for name in sorted(names, key=lambda o: (-rates[o], names.index(o))):
        causes = [r.cause for r in records(results, planner, name) if r.cause is not None]
        failures = ", ".join(f"{SHORT_CAUSES[c]} {causes.count(c)}" for c in bench.causes if c in causes)
        cells = [_rate_cell(records(results, p, name)) for p in bench.planners]
        lines.append(_row([label(name), bench.split_of(name) or "—", *cells, failures or "—"]))
    return lines


def family_table(bench: Bench, results) -> list[str]:
    """A row per procedural family present (:data:`~contourgrasp.sim.procedural.FAMILIES`' order): every planner's rate
    on its objects, and :func:`sort_planner`'s failures by cause; empty without procedural objects."""
    members = {}
    for o in bench.objects:
        family = procedural_family(o.name)
        if family is not None:
            members.setdefault(family, []).append(o.name)
    if not members:
        return []
    planner = sort_planner(bench)
    lines = _header("family", ["objects", *bench.planners, f"{planner}'s failures"], left=1)
    for family in (f for f in FAMILIES if f in members):
        cells = []
        for p in bench.planners:
            own = _of(results, p, members[family])
            cells.append(_counted_cell([r.success for r in own]))
        causes = [r.cause for r in _of(results, planner, members[family]) if r.cause is not None]
        failures = ", ".join(f"{SHORT_CAUSES[c]} {causes.count(c)}" for c in bench.causes if c in causes)
        lines.append(_row([family, len(members[family]), *cells, failures or "—"]))
    return lines


def attempts_section(bench: Bench, results) -> list[str]:
    """With several attempts per trial: per planner and group, success at the first attempt and within the
    bench's attempts and the attempts made, and how the hand told each attempt's outcome; [] with one."""
    if bench.attempts == 1:
        return []
    lines = ["", f"## Attempts (at most {bench.attempts})", "",
             "Per trial: success at the first attempt, success within the attempts (the last attempt's: the "
             "trial stops when the hand tells it holds the object), and the attempts made. Then every attempt "
             "made, its outcome as the hand told it (detected) against the simulator's (true).", ""]
    lines += _header("planner", ["group", "first attempt", f"within {bench.attempts}", "attempts per trial"], left=1)
    groups = _groups_or_all(bench)
    for planner in bench.planners:
        for group, members in groups:
            own = _of(results, planner, members)
            first = [r.outcomes[0] if r.outcomes else r.success for r in own]
            made = [max(len(r.outcomes), 1) for r in own]
            lines.append(_row([planner, group, _counted_cell(first), _counted_cell([r.success for r in own]),
                               f"{statistics.fmean(made):.2f}" if made else "-"]))
    return lines + detection_table(results)


def detection_table(results) -> list[str]:
    """Every attempt made, its outcome as the hand told it (detected) against the simulator's (true)."""
    pairs = [(d, t) for r in results for d, t in zip(r.record.detected, r.record.outcomes)]
    told = {(d, t): sum(1 for p in pairs if p == (d, t)) for d in (True, False) for t in (True, False)}
    return ["", *_header("detected \\ true", ["succeeded", "failed"]),
            _row(["succeeded", told[True, True], told[True, False]]),
            _row(["failed", told[False, True], told[False, False]]),
            "", f"False success: {told[True, False]} of {len(pairs)} attempts "
            f"({100 * told[True, False] / max(len(pairs), 1):.1f} %)."]


def clearing_section(bench: Bench, results) -> list[str]:
    """With the ``clear`` protocol: per planner and group, success per attempt, objects cleared, attempts per
    object and tables cleared; how the runs ended; how the hand told each attempt. [] otherwise."""
    if bench.protocol != "clear":
        return []
    lines = ["", "## Clearing the table", "",
             "Per planner and group: every attempt's true outcome (an object taken off the table), the objects "
             "cleared of all objects in the scenes, attempts made per object, and the scenes cleared entirely; "
             "each with its 95 % Wilson interval.", ""]
    lines += _header("planner", ["group", "success per attempt", "objects cleared", "attempts per object",
                                 "tables cleared"], left=1)
    groups = _groups_or_all(bench)
    for planner in bench.planners:
        for group, members in groups:
            own = _of(results, planner, members)
            objects, cleared = sum(r.scene_objects or 0 for r in own), sum(r.cleared or 0 for r in own)
            made = sum(len(r.outcomes) for r in own)
            lines.append(_row([planner, group, _counted_cell([o for r in own for o in r.outcomes]),
                               _counted_cell([True] * cleared + [False] * (objects - cleared)),
                               f"{made / objects:.2f}" if objects else "-", _counted_cell([r.success for r in own])]))
    lines += ["", *_header("planner", list(ENDINGS))]
    for planner in bench.planners:
        own = records(results, planner)
        lines.append(_row([planner, *(sum(r.ended == ending for r in own) for ending in ENDINGS)]))
    return lines + detection_table(results)


def _counted_cell(successes) -> str:
    """:func:`_rate_cell_of` and the counts: ``"50 % (15–85) 2/4"``."""
    return f"{_rate_cell_of(successes)} {int(sum(successes))}/{len(successes)}"


def _rate_cell_of(successes) -> str:
    """:func:`_rate_cell` of a list of booleans."""
    n, k = len(successes), int(sum(successes))
    if not n:
        return "-"
    low, high = wilson_interval(k, n)
    return f"{100 * k / n:.0f} % ({100 * low:.0f}–{100 * high:.0f})"
