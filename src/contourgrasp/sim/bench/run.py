"""Running a bench: every trial (here, in processes or on Ray) with progress, and reruns of trials for the pictures.

Trial ``t`` (0-based) of every object and planner runs :func:`~contourgrasp.sim.trial.run_trial`
with seed ``seed + t``: every planner faces the same placements and the same
sensor noise, so their rates compare paired scenes, and any trial can be rerun
alone from its record (:func:`snapshot`). The ``random`` baseline draws from
the trial seed too.
"""

from __future__ import annotations

import contextlib
import math
import sys
import time
from dataclasses import dataclass

import numpy as np

from ..planners import PlannedGrasp, make_planner
from ..render import render_view
from .config import Bench, BenchTrial
from .parallel import serial

#: Side view of the end of the hold: distance from the point looked at (m) and the view's elevation (rad).
VIEW_DISTANCE, VIEW_ELEVATION = 0.6, math.radians(19.0)


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


def run_bench(bench: Bench, progress=None, *, execute=None, done=(), record=None) -> tuple[BenchTrial, ...]:
    """Every trial of ``bench``, planner by planner, object by object, trial by trial.

    Parameters
    ----------
    bench : Bench
    progress, record : callable, optional
        ``progress(result)`` and ``record(result)`` (the journal's
        :meth:`~contourgrasp.sim.bench.journal.Journal.append`) are called with each
        :class:`BenchTrial` as it finishes.
    execute : callable, optional
        ``execute(tasks)``, an iterator of finished trials
        (:mod:`~contourgrasp.sim.bench.parallel`); default: one after another here.
    done : iterable of BenchTrial
        Trials already run (a resumed bench): kept, not run again.
    """
    finished = {_key(r): r for r in done}
    tasks = [task for task in bench.tasks() if (task[0], bench.objects[task[1]].name, task[2]) not in finished]
    with contextlib.ExitStack() as stack:
        for result in (execute or stack.enter_context(serial(bench)))(tasks):
            finished[_key(result)] = result
            for call in (record, progress):
                if call is not None:
                    call(result)
    return tuple(finished[p, o.name, t] for p in bench.planners for o in bench.objects for t in range(bench.trials))


def _key(result: BenchTrial) -> tuple[str, str, int]:
    return result.planner, result.record.object, result.trial


@contextlib.contextmanager
def console_progress(bench: Bench, stream=None, *, done=()):
    """Yield ``update(result)``, to call after each trial, writing to ``stream`` (default stderr).

    On a terminal a tqdm bar (trials per second, ETA); in a log (not a
    terminal) one line per finished object: its successes per planner, then
    objects and trials done, the rate and the ETA. ``done``: trials of a
    resumed bench, counted as finished.
    """
    stream = stream or sys.stderr
    done = tuple(done)
    if stream.isatty():
        from tqdm import tqdm

        with tqdm(total=bench.size, initial=len(done), desc="bench", unit="trial", file=stream) as bar:
            def update(result):
                bar.set_postfix_str(f"{result.planner} {result.record.object} {result.trial + 1}/{bench.trials}",
                                    refresh=False)
                bar.update()
            yield update
        return
    yield _object_lines(bench, stream, done)


def _object_lines(bench: Bench, stream, done):
    per_object = len(bench.planners) * bench.trials
    results = {o.name: [] for o in bench.objects}
    for r in done:
        results[r.record.object].append(r)
    finished = sum(len(own) == per_object for own in results.values())
    started, ran = time.perf_counter(), 0

    def update(result):
        nonlocal finished, ran
        own = results[result.record.object]
        own.append(result)
        ran += 1
        if len(own) < per_object:
            return
        finished += 1
        rate = ran / max(time.perf_counter() - started, 1e-9)
        left = bench.size - sum(map(len, results.values()))
        wins = ", ".join(f"{p} {sum(r.record.success for r in own if r.planner == p)}/{bench.trials}"
                         for p in bench.planners)
        print(f"bench: {result.record.object} done ({wins}); {finished}/{len(bench.objects)} objects, "
              f"{bench.size - left}/{bench.size} trials, {rate:.2f} trials/s, ETA {_duration(left / rate)}",
              file=stream, flush=True)
    return update


def _duration(seconds: float) -> str:
    minutes, seconds = divmod(round(seconds), 60)
    hours, minutes = divmod(minutes, 60)
    return f"{hours}:{minutes:02d}:{seconds:02d}" if hours else f"{minutes}:{seconds:02d}"


def snapshot(bench: Bench, result: BenchTrial) -> Snapshot:
    """Rerun a trial that had a plan, keeping the planner's picture, its plan and a side view of the end.

    Raises
    ------
    RuntimeError
        The rerun's record differs from ``result``'s: the trial is not reproducible.
    """
    recording = _Recording(make_planner(result.planner, bench.hand, seed=bench.seed + result.trial))
    seen = recording.seen

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


class _Recording:
    """A trial's planner that keeps its last picture and plan in ``seen`` (``rgb``, ``planned``); its ``options``
    and ``hand`` are the planner's (they tell the trial whether its hand needs a wrist, and clearing how wide
    an object the hand spans)."""

    def __init__(self, planner):
        self.planner, self.seen = planner, {}
        self.options, self.hand = getattr(planner, "options", None), planner.hand

    def plan(self, rgb, depth, intrinsics, **options) -> PlannedGrasp:
        self.seen["rgb"], self.seen["planned"] = rgb, self.planner.plan(rgb, depth, intrinsics, **options)
        return self.seen["planned"]

    def __call__(self, rgb, depth, intrinsics, **target):
        planned = self.plan(rgb, depth, intrinsics, **target)
        return planned.T_camera_hand, planned.approach_depth, planned.grasp_height


def picked_trials(results) -> list[BenchTrial]:
    """Per planner, its first success and its first failure with a plan (either may be missing)."""
    picked = []
    for planner in dict.fromkeys(r.planner for r in results):
        own = [r for r in results if r.planner == planner and r.record.pose is not None]
        for wanted in (True, False):
            picked += [r for r in own if r.record.success == wanted][:1]
    return picked
