"""The thesis's grasping experiment (4.2.4, Table 4.4) as a benchmark: objects x trials x planners.

Trial ``t`` (0-based) of every object and planner runs :func:`~contourgrasp.sim.trial.run_trial`
with seed ``seed + t``: every planner faces the same placements and the same
sensor noise, so their rates compare paired scenes, and any trial can be rerun
alone from its record. The ``random`` baseline draws from the trial seed too.

Outputs (:func:`write_outputs`, all written atomically into one folder):

* ``table.md`` -- success rates of every planner beside the thesis's, then per
  planner a table laid out like Table 4.4 (trial rows, object columns, success
  rate row, the thesis's rates) and its causes of failure;
* ``trials.json`` -- one record per trial (:func:`trial_to_dict`);
* ``success.png`` -- success rate per object and planner, the thesis's beside;
* ``trials.png`` -- per planner its first success and first failure with a plan:
  the camera's picture with the plan drawn on it, and the hand at the end of the
  hold seen from the side (:func:`~contourgrasp.sim.bench_figures.trials_figure`).
"""

from __future__ import annotations

import contextlib
import importlib.util
import math
import statistics
import sys
from dataclasses import asdict, dataclass, field
from pathlib import Path

import numpy as np

from ..errors import InputError
from ..hand import Hand
from ..io.hand_file import load_hand
from ..io.plan_file import atomic_outputs, write_json
from .hand_model import build_hand
from .objects import THESIS_OBJECTS, ObjectSpec, object_spec
from .planners import BASELINES, PlannedGrasp, ablation_planners, make_planner, synthesis_planner
from .render import render_view
from .scene import Camera, Workspace
from .trial import DROPPED, FAILURE_CAUSES, NO_PLAN, PUSHED, SLIPPED, STRUCK, TrialRecord, run_trial

#: Success rates of Table 4.4 (real arm and qbHand, 10 trials per object).
THESIS_SUCCESS = {"can": 0.8, "case": 0.4, "bottle": 0.7, "stone1": 0.2, "stone2": 0.6}
#: Column headings of Table 4.4 for the simulated objects.
LABELS = {"can": "can", "case": "glasses case", "bottle": "bottle", "stone1": "stone 1", "stone2": "stone 2"}
#: Short failure causes for the trial tables.
SHORT_CAUSES = {NO_PLAN: "no plan", STRUCK: "struck", PUSHED: "pushed", SLIPPED: "slipped", DROPPED: "dropped"}
#: z of the 95 % Wilson interval.
WILSON_Z = 1.959963984540054
#: Output file names.
TABLE, TRIALS, CHART, PICTURE = "table.md", "trials.json", "success.png", "trials.png"
#: Side view of the end of the hold: distance from the point looked at (m) and the view's elevation (rad).
VIEW_DISTANCE, VIEW_ELEVATION = 0.6, math.radians(19.0)


@dataclass(frozen=True)
class Bench:
    """What to run: objects x trials x planners, and the scene.

    Attributes
    ----------
    objects : tuple of ObjectSpec
        Distinct names; they head the table's columns.
    planners : tuple of str
        Planner names (:func:`~contourgrasp.sim.planners.make_planner`).
    trials : int
        Per object and planner.
    seed : int
        Trial ``t`` uses seed ``seed + t``.
    hand : Hand
        Simulated, and planned for.
    noise : bool
        Depth noise in the planner's picture.
    camera, workspace
        Scene parameters (:mod:`contourgrasp.sim.scene`).
    """

    objects: tuple[ObjectSpec, ...]
    planners: tuple[str, ...] = ("paper", "default", *BASELINES)
    trials: int = 20
    seed: int = 0
    hand: Hand = field(default_factory=lambda: load_hand("five-finger-linear"))
    noise: bool = True
    camera: Camera = field(default_factory=Camera)
    workspace: Workspace = field(default_factory=Workspace)

    def __post_init__(self):
        object.__setattr__(self, "objects", tuple(self.objects))
        object.__setattr__(self, "planners", tuple(self.planners))
        names = [o.name for o in self.objects]
        if not names:
            raise InputError("no object to grasp")
        if len(set(names)) != len(names):
            raise InputError(f"object names must differ, got {', '.join(names)}")
        if not self.planners or len(set(self.planners)) != len(self.planners):
            raise InputError(f"planners must be distinct names, got {', '.join(self.planners) or 'none'}")
        for planner in self.planners:
            synthesis_planner(planner)  # refuses an unknown name before any trial runs
        if self.trials < 1 or self.seed < 0:
            raise InputError(f"trials must be >= 1 and seed >= 0, got {self.trials} and {self.seed}")
        build_hand(self.hand)  # refuses a hand the simulation cannot build before any trial runs

    @property
    def size(self) -> int:
        """Number of trials."""
        return len(self.objects) * self.trials * len(self.planners)

    def object(self, name: str) -> ObjectSpec:
        """The object called ``name``."""
        return next(o for o in self.objects if o.name == name)

    def run(self, planner: str, obj: ObjectSpec, trial: int, *, plan=None, observe=None) -> TrialRecord:
        """Run one trial; ``plan`` replaces the named planner's callable (same answers), ``observe`` see run_trial."""
        seed = self.seed + trial
        return run_trial(obj, seed=seed, planner=plan or make_planner(planner, self.hand, seed=seed), hand=self.hand,
                         noise=self.noise, camera=self.camera, workspace=self.workspace, observe=observe)


@dataclass(frozen=True)
class BenchTrial:
    """One trial of the bench: which planner, which trial (0-based), and its record."""

    planner: str
    trial: int
    record: TrialRecord


@dataclass(frozen=True, eq=False)
class Snapshot:
    """A trial rerun for the pictures.

    Attributes
    ----------
    result : BenchTrial
    rgb : (H, W, 3) uint8
        The planner's picture.
    planned : PlannedGrasp
    view, hit : (h, w, 3) uint8, (h, w) bool
        The scene at the end of the trial seen from the side, and where it shows something.
    """

    result: BenchTrial
    rgb: np.ndarray
    planned: PlannedGrasp
    view: np.ndarray
    hit: np.ndarray


def thesis_objects(names) -> tuple[ObjectSpec, ...]:
    """The objects of :data:`~contourgrasp.sim.objects.THESIS_OBJECTS` called ``names``.

    Raises
    ------
    InputError
        An unknown name.
    """
    unknown = [n for n in names if n not in THESIS_OBJECTS]
    if unknown:
        raise InputError(f"unknown object {unknown[0]!r}: choose from {', '.join(THESIS_OBJECTS)} or pass --mesh FILE")
    return tuple(object_spec(n) for n in names)


def run_bench(bench: Bench, progress=None) -> tuple[BenchTrial, ...]:
    """Every trial, planner by planner, object by object; ``progress(label)`` is called after each."""
    results = []
    for planner in bench.planners:
        for obj in bench.objects:
            for trial in range(bench.trials):
                results.append(BenchTrial(planner, trial, bench.run(planner, obj, trial)))
                if progress is not None:
                    progress(f"{planner} {obj.name} {trial + 1}/{bench.trials}")
    return tuple(results)


@contextlib.contextmanager
def console_progress(total: int, stream=None):
    """Yield ``update(label)``, to call after each trial: a tqdm bar when tqdm is installed, else a counter.

    Both write to ``stream`` (default stderr); the counter rewrites one line on a
    terminal and prints every twentieth of the run otherwise.
    """
    stream = stream or sys.stderr
    if importlib.util.find_spec("tqdm") is None:
        yield _counter(total, stream)
        return
    from tqdm import tqdm

    with tqdm(total=total, desc="bench", unit="trial", file=stream) as bar:
        def update(label):
            bar.set_postfix_str(label, refresh=False)
            bar.update()
        yield update


def _counter(total: int, stream):
    done = 0
    every = 1 if stream.isatty() else max(1, total // 20)

    def update(label):
        nonlocal done
        done += 1
        if done % every == 0 or done == total:
            end = "\r" if stream.isatty() and done < total else "\n"
            print(f"bench: {done}/{total} trials ({label})".ljust(60), end=end, file=stream, flush=True)
    return update


def snapshot(bench: Bench, result: BenchTrial) -> Snapshot:
    """Rerun a trial that had a plan, keeping the planner's picture, its plan and a side view of the end.

    Raises
    ------
    RuntimeError
        The rerun's record differs from ``result``'s: the trial is not reproducible.
    """
    planner = make_planner(result.planner, bench.hand, seed=bench.seed + result.trial)
    seen = {}

    def recording(rgb, depth, intrinsics):
        seen["rgb"], seen["planned"] = rgb, planner.plan(rgb, depth, intrinsics)
        return seen["planned"].T_camera_hand, seen["planned"].approach_depth

    def observe(scene):
        palm, _ = scene.palm_pose()
        target = np.array([palm[0], palm[1], 0.5 * palm[2]])
        eye = target + VIEW_DISTANCE * np.array([0.0, -math.cos(VIEW_ELEVATION), math.sin(VIEW_ELEVATION)])
        seen["view"] = render_view(scene, eye, target)

    again = bench.run(result.planner, bench.object(result.record.object), result.trial, plan=recording,
                      observe=observe)
    if again != result.record:
        raise RuntimeError(f"trial {result.trial} of {result.planner} on {again.object} did not reproduce")
    return Snapshot(result, seen["rgb"], seen["planned"], *seen["view"])


def picked_trials(results) -> list[BenchTrial]:
    """Per planner, its first success and its first failure with a plan (either may be missing)."""
    picked = []
    for planner in dict.fromkeys(r.planner for r in results):
        own = [r for r in results if r.planner == planner and r.record.pose is not None]
        for wanted in (True, False):
            picked += [r for r in own if r.record.success == wanted][:1]
    return picked


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


def write_outputs(bench: Bench, results, out, *, wall_time: float) -> list[Path]:
    """Write table.md, trials.json, success.png and trials.png into ``out`` (created if missing); their paths."""
    from .bench_figures import success_figure, trials_figure

    snapshots = [snapshot(bench, r) for r in picked_trials(results)]
    out = Path(out)
    out.mkdir(parents=True, exist_ok=True)
    paths = [out / name for name in (TABLE, TRIALS, CHART, PICTURE)]
    with atomic_outputs(*paths) as (table, trials, chart, picture):
        Path(table).write_text(markdown(bench, results, wall_time=wall_time), encoding="utf-8")
        write_json([trial_to_dict(r) for r in results], trials)
        success_figure(bench, results).savefig(chart, dpi=110, format="png")
        trials_figure(bench, snapshots).savefig(picture, dpi=90, format="png")
    return paths


def _own(results, planner: str, obj: str | None = None) -> list[TrialRecord]:
    """The records of ``planner``'s trials (on ``obj`` only, when given)."""
    return [r.record for r in results if r.planner == planner and (obj is None or r.record.object == obj)]


def success_rates(results, planner: str, objects) -> dict[str, float]:
    """Success rate per object name of ``planner``'s trials, and over all of them (key ``"all"``)."""
    own = _own(results, planner)
    rates = {o: float(np.mean([r.success for r in own if r.object == o])) for o in objects}
    return rates | {"all": float(np.mean([r.success for r in own]))}


def label(name: str) -> str:
    """Column heading of an object."""
    return LABELS.get(name, name)


def _percent(rate: float | None) -> str:
    return "—" if rate is None else f"{100 * rate:.0f} %"


def _row(cells) -> str:
    return "| " + " | ".join(str(c) for c in cells) + " |"


def _header(first: str, columns) -> list[str]:
    return [_row([first, *columns]), _row(["---", *["---:"] * len(columns)])]


def thesis_rates(objects) -> dict[str, float | None]:
    """Table 4.4's rate per object name (None where it has none), and their mean over these objects (``"all"``)."""
    rates = {o: THESIS_SUCCESS.get(o) for o in objects}
    known = [r for r in rates.values() if r is not None]
    return rates | {"all": float(np.mean(known)) if known else None}


def markdown(bench: Bench, results, *, wall_time: float) -> str:
    """The whole of table.md."""
    lines = [
        "# contourgrasp bench: the grasping experiment of thesis 4.2.4 (Table 4.4), simulated",
        "",
        _setup_text(bench, len(results), wall_time),
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
    lines += ["", "✓ success; ✗ failure and its cause: " + ", ".join(f"{v} = {k}" for k, v in SHORT_CAUSES.items())
              + ". Success: lifted at least 0.10 m and moved less than 0.02 m in the hand during the 2 s hold."]
    return "\n".join(lines) + "\n"


def _setup_text(bench: Bench, n_trials: int, wall_time: float) -> str:
    return (f"{len(bench.objects)} object(s) x {bench.trials} trial(s) x {len(bench.planners)} planner(s) = "
            f"{n_trials} trials in {wall_time:.0f} s wall time. Hand `{bench.hand.name}` (one tendon, the thesis's "
            f"finger timing); depth noise {'on' if bench.noise else 'off'}; trial t uses seed {bench.seed} + t, the "
            f"same scene for every planner. The thesis's rates are from a real arm and hand, ours from the "
            f"simulation; with {bench.trials} trial(s) per object a rate's standard error is up to "
            f"{50 / math.sqrt(bench.trials):.0f} points.")


def wilson_interval(successes: int, trials: int, z: float = WILSON_Z) -> tuple[float, float]:
    """The Wilson score interval of a success rate (95 % for the default ``z``): (low, high) in [0, 1]."""
    if trials < 1:
        raise ValueError(f"trials must be >= 1, got {trials}")
    rate = successes / trials
    shrink = 1 + z * z / trials
    centre = (rate + z * z / (2 * trials)) / shrink
    half = z * math.sqrt(rate * (1 - rate) / trials + z * z / (4 * trials * trials)) / shrink
    return max(0.0, centre - half), min(1.0, centre + half)


def _rate_cell(records) -> str:
    wins = sum(r.success for r in records)
    low, high = wilson_interval(wins, len(records))
    return f"{100 * wins / len(records):.0f} % ({100 * low:.0f}–{100 * high:.0f})"


def rates_table(bench: Bench, results) -> list[str]:
    """Success rate and its 95 % Wilson interval per planner (rows) and object (columns), Table 4.4's first."""
    objects = [o.name for o in bench.objects]
    lines = [*_header("planner", [label(o) for o in objects] + ["all"]),
             _row(["thesis, real robot (Table 4.4)", *map(_percent, thesis_rates(objects).values())])]
    for planner in bench.planners:
        name = planner + (" (baseline)" if planner in BASELINES else "")
        cells = [_rate_cell(_own(results, planner, o)) for o in objects] + [_rate_cell(_own(results, planner))]
        lines.append(_row([name, *cells]))
    return lines


def ablation_table(bench: Bench, results) -> list[str]:
    """The ablation from ``paper`` to ``default`` (rows in step order, those the bench ran): rates and causes."""
    steps = [p.name for p in ablation_planners()]
    names = {name: name for name in steps[:-1]} | {steps[-1]: "default"}
    rows = [(step, planner) for step, planner in names.items() if planner in bench.planners]
    lines = _header("step", ["all", *(SHORT_CAUSES[c] for c in FAILURE_CAUSES)])
    for step, planner in rows:
        own = _own(results, planner)
        shown = step if planner == step else f"{step} = `default`"
        lines.append(_row([shown, _rate_cell(own), *(sum(r.cause == c for r in own) for c in FAILURE_CAUSES)]))
    return lines if rows else []


def planner_notes(bench: Bench, results) -> list[str]:
    """One bullet per planner: what it is, its settings, its median planning time."""
    notes = []
    for planner in bench.planners:
        times = [r.plan_time for r in _own(results, planner)]
        timing = f" Median planning time {statistics.median(times):.2f} s."
        settings = synthesis_planner(planner)
        if settings is None:
            notes.append(f"- `{planner}` (baseline): {BASELINES[planner]}.{timing}")
            continue
        text = ", ".join(f"{k}={_option(k, v)}" for k, v in settings.options) or "the library's defaults"
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
    own = _own(results, planner)
    lines = _header("cause", [label(o) for o in objects] + ["all"])
    for cause in FAILURE_CAUSES:
        counts = [sum(r.cause == cause for r in own if r.object == o) for o in objects]
        lines.append(_row([cause, *counts, sum(counts)]))
    return lines
