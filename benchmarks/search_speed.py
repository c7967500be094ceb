"""Search-speed benchmark: the library's grid search against the thesis's nested optimisation.

For every example contour and hand preset, in one process, on one core:

(a) the reference (``contourgrasp.synthesis.reference.reference_search``: scipy L-BFGS-B per finger per pose) on the
    thesis grid (xy_step 0.05 m, yaw_step 2 deg, D_max 0.15 m: 7 x 7 x 180 = 8820 poses), one run;
(b) the library (``contourgrasp.synthesis.search``) on the thesis grid;
(c) the library on the dense grid (xy_step 0.01 m, yaw_step 1 deg, D_max 0.15 m: 31 x 31 x 360 =
    345,960 poses);
(d) the library on the dense grid followed by its continuous refinement (``synthesize(refine=True)``:
    a bounded compass search in x, y, yaw from the best distinct grid poses on the exact cost); the
    row gives the refined cost and its gain over the dense grid's best.

Library times are the median of ``--runs`` calls after one untimed warm-up call per grid (so numba's
JIT compilation / cache loading is excluded); the reference is run once (it takes minutes per case).
A plan's time includes the EFD fit, the grid screen and the exact re-evaluation of the best poses (and,
for (d), the refinement); the median of each stage (``timing_ms``) of the thesis-grid plans is printed
per case.
Peak memory of a library call is measured by ``tracemalloc`` in a separate, untimed call (it traces
Python, numpy and numba-runtime allocations, not the interpreter's or the libraries' static memory);
the process's ``ru_maxrss`` is printed at the end as well.

Where the library's best cost and the reference's differ by more than 1e-6 (relative), both are
evaluated at the other's best pose, finger by finger, to tell whether the reference's local solver got
stuck (library better) or the library missed the pose (library worse).

The targets are printed with the measured figures; the benchmark is not tuned to them.

Usage::

    python benchmarks/search_speed.py [--contours can,stone1] [--hands three-finger]
        [--reference-hands five-finger-linear|all|none|LIST] [--runs 7] [--out table.md]
"""

from __future__ import annotations

import os

# One core: set before numpy (and numba) are imported, so BLAS pools and numba's thread pool see it.
THREAD_VARS = ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS", "NUMBA_NUM_THREADS")
for _var in THREAD_VARS:
    os.environ[_var] = "1"

import argparse  # noqa: E402
import math  # noqa: E402
import platform  # noqa: E402
import resource  # noqa: E402
import statistics  # noqa: E402
import sys  # noqa: E402
import time  # noqa: E402
import tracemalloc  # noqa: E402
from dataclasses import dataclass, field  # noqa: E402
from pathlib import Path  # noqa: E402

import numba  # noqa: E402
import numpy as np  # noqa: E402
import scipy  # noqa: E402
from matplotlib.path import Path as MplPath  # noqa: E402

import contourgrasp as cg  # noqa: E402
from contourgrasp import synthesis  # noqa: E402
from contourgrasp.contour import clean_polygon, efd  # noqa: E402
from contourgrasp import tolerances as tol  # noqa: E402
from contourgrasp.hand import to_image  # noqa: E402

from contourgrasp.synthesis.reference import CURVE_SAMPLES, pose_cost, reference_search, solve_inner  # noqa: E402

THESIS = {"xy_step": 0.05, "yaw_step": math.radians(2.0), "d_max": (0.15, 0.15)}
DENSE = {"xy_step": 0.01, "yaw_step": math.radians(1.0), "d_max": (0.15, 0.15)}
D_MIN = 0.015
REL_TOL = 1e-6
TARGET_THESIS_MS = 10.0
TARGET_DENSE_MS = 300.0
TARGET_SPEEDUP = 5000.0


def log(*args):
    print(*args, file=sys.stderr, flush=True)


def grid_size(grid: dict) -> int:
    g = synthesis.SearchGrid(d_min=D_MIN, **grid)
    return int(np.prod([len(a) for a in g.axes((0.0, 0.0))]))


def machine_line() -> str:
    cpu = "unknown CPU"
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                cpu = line.split(":", 1)[1].strip()
                break
    except OSError:
        pass
    try:
        usable = len(os.sched_getaffinity(0))
    except AttributeError:
        usable = os.cpu_count()
    return (f"{cpu}, {os.cpu_count()} cores ({usable} usable), run on 1 core; "
            f"Python {platform.python_version()}, numpy {np.__version__}, numba {numba.__version__}, "
            f"scipy {scipy.__version__}; {platform.system()} {platform.machine()}")


def load() -> str:
    return " ".join(f"{v:.2f}" for v in os.getloadavg())


@dataclass
class LibResult:
    times: list[float] = field(default_factory=list)  # s
    plan: synthesis.GraspPlan | None = None
    infeasible: str | None = None
    peak_bytes: int = 0
    size: int = 0
    stages: list[dict] = field(default_factory=list)  # timing_ms of the timed runs

    def stage_medians(self) -> str:
        if not self.stages:
            return "no plan"
        return ", ".join(f"{k} {statistics.median(s[k] for s in self.stages):.2f}" for k in self.stages[0]) + " ms"

    @property
    def median(self) -> float:
        return statistics.median(self.times)


@dataclass
class RefResult:
    time: float
    pose: np.ndarray | None
    cost: float
    feasible: int
    size: int


def run_library(contour, hand, grid: dict, runs: int, refine: bool = False) -> LibResult:
    out = LibResult(size=grid_size(grid))

    def call():
        return cg.synthesize(contour, hand, d_min=D_MIN, refine=refine, **grid)

    try:  # warm-up: numba compilation / cache loading, first-touch of every code path
        out.plan = call()
    except cg.NoFeasibleGrasp as exc:
        out.infeasible = exc.reason if hasattr(exc, "reason") else str(exc)
    for _ in range(runs):
        start = time.perf_counter()
        try:
            plan = call()
            out.stages.append(plan.timing_ms)
        except cg.NoFeasibleGrasp:
            pass
        out.times.append(time.perf_counter() - start)
    tracemalloc.start()
    tracemalloc.reset_peak()
    try:
        call()
    except cg.NoFeasibleGrasp:
        pass
    out.peak_bytes = tracemalloc.get_traced_memory()[1]
    tracemalloc.stop()
    return out


def run_reference(contour, hand) -> RefResult:
    start = time.perf_counter()
    pose, cost, feasible = reference_search(contour, hand, d_min=D_MIN, **THESIS)
    return RefResult(time.perf_counter() - start, pose, float(cost), int(feasible), grid_size(THESIS))


# --------------------------------------------------------------------------- diagnosis of disagreements


class Probe:
    """Library (exact) and reference evaluation of single poses, finger by finger."""

    def __init__(self, contour, hand):
        self.hand = hand
        self.model = efd.fit(clean_polygon(contour), 4)
        self.curve_t, self.curve = efd.sample(self.model, CURVE_SAMPLES)
        self.outline = MplPath(self.curve)

    def reference_cost(self, pose):
        return pose_cost(self.model, self.hand, np.asarray(pose, float), self.outline, self.curve, self.curve_t,
                         "paper", D_MIN)

    def library(self, pose):
        return synthesis.evaluate_poses(self.model, self.hand, np.asarray(pose, float)[None], d_min=D_MIN)

    def fingers(self, pose) -> list[str]:
        """One line per finger: library exact contact vs reference solver's answer at ``pose``."""
        pose = np.asarray(pose, float)
        lib = self.library(pose)
        lines = []
        for f, finger in enumerate(self.hand.fingers):
            ok, t, lam, point = solve_inner(self.model, finger, pose, self.outline, self.curve, self.curve_t)
            ref_res = float(np.linalg.norm(point - to_image(finger.points([lam]), pose)[0]))
            if lib.touching[0, f]:
                lp = to_image(finger.points([lib.lam[0, f]]), pose)[0]
                lib_res = float(np.linalg.norm(efd.evaluate(self.model, [lib.t[0, f]])[0] - lp))
                lib_txt = f"touch lam={lib.lam[0, f]:.6f} t={lib.t[0, f]:.6f} |r-p|={lib_res:.1e}"
            else:
                lib_txt = "miss"
            ref_txt = (f"touch lam={lam:.6f} t={t:.6f}" if ok else f"MISS (stopped at lam={lam:.6f} t={t:.6f}, "
                       f"|r-p|={ref_res:.1e} > TOUCH)")
            lines.append(f"      {finger.name:>7}: library {lib_txt}; reference {ref_txt}")
        return lines


def diagnose(contour, hand, lib: synthesis.GraspPlan, ref: RefResult) -> list[str]:
    """Explain a disagreement beyond REL_TOL between the library's and the reference's best cost."""
    probe = Probe(contour, hand)
    lines = []
    lib_pose, ref_pose = lib.pose, ref.pose
    if lib.cost.total < ref.cost:
        at_lib = probe.reference_cost(lib_pose)
        lines.append(f"    library better: its pose {fmt_pose(lib_pose)} costs {lib.cost.total:.9g}; the reference "
                     f"scores that pose {'infeasible' if at_lib is None else f'{at_lib:.9g}'} "
                     f"(its own best {ref.cost:.9g} at {fmt_pose(ref_pose)})")
        lines += probe.fingers(lib_pose)
    else:
        exact = probe.library(ref_pose)
        screen = synthesis.screen_grid(probe.model, hand, synthesis.SearchGrid(d_min=D_MIN, **THESIS))
        k = int(np.flatnonzero(np.all(np.isclose(screen.poses, ref_pose, atol=1e-12), axis=1))[0])
        feas = np.flatnonzero(screen.feasible)
        rank = (int(np.sum(screen.cost[feas] < screen.cost[k])) + 1) if screen.feasible[k] else None
        n = max(tol.REFINE_CANDIDATES, 4 * 10)
        lines.append(f"    library worse: the reference's pose {fmt_pose(ref_pose)} costs {ref.cost:.9g}; "
                     f"evaluated exactly by the library it is "
                     f"{'infeasible' if not exact.feasible[0] else f'{exact.cost[0]:.9g}'}; in the screen it is "
                     + (f"feasible, cost {screen.cost[k]:.9g}, rank {rank} of {feas.size} "
                        f"({'inside' if rank <= n else 'outside'} the {n} re-evaluated)" if rank else
                        "infeasible") + f"; library's best {lib.cost.total:.9g} at {fmt_pose(lib_pose)}")
        lines += probe.fingers(ref_pose)
    return lines


# --------------------------------------------------------------------------- formatting


def fmt_pose(pose) -> str:
    return f"(x {pose[0]:+.3f} m, y {pose[1]:+.3f} m, yaw {math.degrees(pose[2]):.0f} deg)"


def fmt_time(seconds: float) -> str:
    if seconds >= 10:
        return f"{seconds:.0f} s"
    if seconds >= 1:
        return f"{seconds:.1f} s"
    return f"{seconds * 1e3:.1f} ms" if seconds >= 0.01 else f"{seconds * 1e3:.2f} ms"


def fmt_rate(poses: int, seconds: float) -> str:
    rate = poses / seconds
    if rate >= 1e6:
        return f"{rate / 1e6:.1f} M"
    if rate >= 1e3:
        return f"{rate / 1e3:.0f} k"
    return f"{rate:.0f}"


def rel_diff(lib: float, ref: float) -> float:
    return (lib - ref) / abs(ref)


@dataclass
class Case:
    contour: str
    hand: str
    thesis: LibResult
    dense: LibResult
    refined: LibResult
    ref: RefResult | None
    verdict: str = ""
    notes: list[str] = field(default_factory=list)


def compare(case: Case, contour, hand) -> None:
    lib, ref = case.thesis, case.ref
    if ref is None:
        case.verdict = "reference not run"
        return
    ref_nf = ref.pose is None
    if lib.infeasible and ref_nf:
        case.verdict = "both: no feasible grasp"
        return
    if lib.infeasible or ref_nf:
        case.verdict = "DISAGREE on feasibility"
        case.notes.append(f"    library: {lib.infeasible or 'feasible'}; reference: "
                          f"{'no feasible pose' if ref_nf else f'{ref.feasible} feasible poses'}")
        return
    d = rel_diff(lib.plan.cost.total, ref.cost)
    same_pose = np.allclose(lib.plan.pose, ref.pose, atol=1e-9)
    if abs(d) <= REL_TOL:
        case.verdict = "equal" + ("" if same_pose else f" (tie: library pose {fmt_pose(lib.plan.pose)}, "
                                  f"reference pose {fmt_pose(ref.pose)})")
    else:
        case.verdict = "library BETTER" if d < 0 else "library WORSE"
        case.notes += diagnose(contour, hand, lib.plan, ref)
    if lib.plan.feasible_poses != ref.feasible:
        case.notes += count_mismatch(contour, hand, lib.plan, ref)


def count_mismatch(contour, hand, plan: synthesis.GraspPlan, ref: RefResult) -> list[str]:
    """Locate the poses the library counts feasible and the reference does not (the cheap direction).

    ``reference_search`` returns only a count; the reference is re-run here on the library's feasible poses
    (screened or exact), a few dozen, not on the whole grid.
    """
    probe = Probe(contour, hand)
    grid = synthesis.SearchGrid(d_min=D_MIN, **THESIS)
    screen = synthesis.screen_grid(probe.model, hand, grid)
    exact = synthesis.evaluate_poses(probe.model, hand, screen.poses, d_min=D_MIN)
    lines = [f"    feasible poses differ: library screen {plan.feasible_poses}, library exact (every grid pose "
             f"re-evaluated on the curve) {int(exact.feasible.sum())}, reference {ref.feasible}"]
    rejected = []
    for k in np.flatnonzero(screen.feasible | exact.feasible):
        if probe.reference_cost(screen.poses[k]) is None:
            rejected.append(k)
    both = int((screen.feasible | exact.feasible).sum()) - len(rejected)
    lines.append(f"    of the library's {int((screen.feasible | exact.feasible).sum())} feasible poses the reference "
                 f"rejects {len(rejected)}; {ref.feasible - both} poses are feasible for the reference only "
                 "(not located: that needs the per-pose reference over the whole grid)")
    for k in rejected[:3]:
        lines.append(f"    rejected by the reference: {fmt_pose(screen.poses[k])} (screen "
                     f"{'feasible' if screen.feasible[k] else 'infeasible'}, exact "
                     f"{'feasible' if exact.feasible[k] else 'infeasible'})")
        lines += probe.fingers(screen.poses[k])
    return lines


def table(cases: list[Case], machine_tag: str, runs: int) -> list[str]:
    rows = [
        "| machine | case | method (grid) | time | poses/s | best cost | vs reference | speed-up | peak mem |",
        "|---|---|---|---:|---:|---:|---|---:|---:|",
    ]
    thesis_n, dense_n = grid_size(THESIS), grid_size(DENSE)
    for c in cases:
        name = f"{c.contour} / {c.hand}"
        if c.ref is not None:
            cost = "no feasible grasp" if c.ref.pose is None else f"{c.ref.cost:.6f}"
            rows.append(f"| {machine_tag} | {name} | reference, thesis ({thesis_n}), 1 run | {fmt_time(c.ref.time)} "
                        f"| {fmt_rate(thesis_n, c.ref.time)} | {cost} | — | 1 | — |")
        for label, res, n in (("library, thesis", c.thesis, thesis_n), ("library, dense", c.dense, dense_n)):
            cost = "no feasible grasp" if res.infeasible else f"{res.plan.cost.total:.6f}"
            diff, speed = "—", "—"
            if label == "library, thesis" and c.ref is not None:
                speed = f"{c.ref.time / res.median:,.0f}x"
                if res.infeasible or c.ref.pose is None:
                    diff = "both infeasible" if (res.infeasible and c.ref.pose is None) else "**feasibility differs**"
                else:
                    d = rel_diff(res.plan.cost.total, c.ref.cost)
                    diff = f"{d:+.1e}" + (" equal" if abs(d) <= REL_TOL else " **better**" if d < 0 else " **worse**")
            rows.append(f"| {machine_tag} | {name} | {label} ({n}), median of {runs} | {fmt_time(res.median)} "
                        f"| {fmt_rate(n, res.median)} | {cost} | {diff} | {speed} | "
                        f"{res.peak_bytes / 2**20:.1f} MiB |")
        res = c.refined
        if res.infeasible:
            cost = "no feasible grasp"
        else:
            r = res.plan.refinement
            cost = f"{r.cost:.6f} (gain {r.gain:.6f} over the dense grid's {r.grid_cost:.6f})"
        rows.append(f"| {machine_tag} | {name} | library, dense ({dense_n}) + refinement, median of {runs} "
                    f"| {fmt_time(res.median)} | {fmt_rate(dense_n, res.median)} | {cost} | — | — | "
                    f"{res.peak_bytes / 2**20:.1f} MiB |")
    return rows


def targets(cases: list[Case]) -> list[str]:
    out = ["Targets (measured, not tuned):"]

    def worst(key):
        c = max(cases, key=key)
        return c, key(c)

    c, t = worst(lambda c: c.thesis.median)
    n_ok = sum(c.thesis.median <= TARGET_THESIS_MS / 1e3 for c in cases)
    out.append(f"- thesis grid <= {TARGET_THESIS_MS:.0f} ms per plan: {'MET' if n_ok == len(cases) else 'NOT MET'} "
               f"(met in {n_ok}/{len(cases)} cases; slowest {c.contour} / {c.hand}: {t * 1e3:.2f} ms; "
               f"median over cases {statistics.median(x.thesis.median for x in cases) * 1e3:.2f} ms)")
    c, t = worst(lambda c: c.dense.median)
    n_ok = sum(c.dense.median <= TARGET_DENSE_MS / 1e3 for c in cases)
    out.append(f"- dense grid <= {TARGET_DENSE_MS:.0f} ms per plan: {'MET' if n_ok == len(cases) else 'NOT MET'} "
               f"(met in {n_ok}/{len(cases)} cases; slowest {c.contour} / {c.hand}: {t * 1e3:.1f} ms; "
               f"median over cases {statistics.median(x.dense.median for x in cases) * 1e3:.1f} ms)")
    gained = [c for c in cases if not c.refined.infeasible]
    if gained:
        gains = [c.refined.plan.refinement.gain for c in gained]
        relative = [c.refined.plan.refinement.gain / abs(c.refined.plan.refinement.grid_cost) for c in gained]
        c, t = worst(lambda c: c.refined.median)
        out.append(f"- (d) dense grid + continuous refinement (no target): gains in {sum(g > 0 for g in gains)}/"
                   f"{len(gained)} cases, median {statistics.median(gains):.4g} ({statistics.median(relative):.2%} of "
                   f"the dense grid's best cost), largest {max(gains):.4g} ({max(relative):.2%}); time median "
                   f"{statistics.median(x.refined.median for x in cases) * 1e3:.1f} ms, slowest {c.contour} / "
                   f"{c.hand}: {t * 1e3:.1f} ms")
    with_ref = [c for c in cases if c.ref is not None]
    if with_ref:
        speedups = [(c.ref.time / c.thesis.median, c) for c in with_ref]
        lo, c = min(speedups, key=lambda s: s[0])
        n_ok = sum(s >= TARGET_SPEEDUP for s, _ in speedups)
        out.append(f"- >= {TARGET_SPEEDUP:.0f}x faster than the reference on the thesis grid: "
                   f"{'MET' if n_ok == len(with_ref) else 'NOT MET'} "
                   f"(met in {n_ok}/{len(with_ref)} cases; lowest {lo:,.0f}x on {c.contour} / {c.hand}; highest {max(s for s, _ in speedups):,.0f}x)")
        good = [c for c in with_ref if c.verdict.startswith(("equal", "both"))]
        better = [c for c in with_ref if c.verdict == "library BETTER"]
        bad = [c for c in with_ref if c not in good and c not in better]
        out.append(f"- best cost equal to the reference's within {REL_TOL:g} (or better where its solver got stuck): "
                   f"{'MET' if not bad else 'NOT MET'} — {len(good)} equal or both infeasible, {len(better)} library "
                   f"better, {len(bad)} worse or disagreeing" + (f" ({', '.join(f'{c.contour} / {c.hand}' for c in bad)})"
                                                                  if bad else ""))
    else:
        out.append("- speed-up and cost agreement: reference not run")
    return out


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--contours", default=",".join(cg.example_names()), help="comma list (default: every example)")
    ap.add_argument("--hands", default=",".join(cg.preset_names()), help="comma list (default: every preset)")
    ap.add_argument("--reference-hands", default="five-finger-linear",
                    help="hands the reference runs on: comma list, 'all' or 'none' (default five-finger-linear; "
                         "the reference takes minutes per case)")
    ap.add_argument("--runs", type=int, default=7, help="timed library runs per case after one warm-up (default 7)")
    ap.add_argument("--out", type=Path, help="also write the Markdown table to this file")
    args = ap.parse_args(argv)

    contours = [s.strip() for s in args.contours.split(",") if s.strip()]
    hands = [s.strip() for s in args.hands.split(",") if s.strip()]
    if args.reference_hands == "all":
        ref_hands = set(hands)
    elif args.reference_hands == "none":
        ref_hands = set()
    else:
        ref_hands = {s.strip() for s in args.reference_hands.split(",") if s.strip()}
    for kind, names, known in (("contour", contours, cg.example_names()), ("hand", hands, cg.preset_names()),
                               ("reference hand", ref_hands, cg.preset_names())):
        unknown = sorted(set(names) - set(known))
        if unknown:
            ap.error(f"unknown {kind}(s) {', '.join(unknown)}; known: {', '.join(known)}")
    if args.runs < 1:
        ap.error("--runs must be at least 1")

    machine = machine_line()
    cpu_tag = machine.split(",")[0]
    machine_tag = f"{cpu_tag}, 1 core"
    load_start = load()
    print("# contourgrasp search-speed benchmark")
    print()
    print(f"Machine: {machine}")
    print(f"Threads: {', '.join(f'{v}=1' for v in THREAD_VARS)} set before importing numpy (one core).")
    print(f"Load average (1/5/15 min) at start: {load_start} — other work shares this machine, so times are noisy.")
    print(f"Grids: thesis = xy 0.05 m, yaw 2 deg, D_max 0.15 m ({grid_size(THESIS)} poses); "
          f"dense = xy 0.01 m, yaw 1 deg, D_max 0.15 m ({grid_size(DENSE)} poses); D_min {D_MIN} m; 4 harmonics, "
          "paper curvature.")
    print(f"Library: contourgrasp.synthesis.search (EFD fit + compiled grid screen + exact re-evaluation of the "
          f"best {max(tol.REFINE_CANDIDATES, 40)} screened poses; (d) adds refine=True: compass search from the best "
          f"{tol.REFINE_STARTS} distinct poses), median of {args.runs} runs after 1 untimed warm-up "
          "call per grid (numba JIT / cache loading excluded).")
    print("Reference: contourgrasp.synthesis.reference.reference_search (scipy L-BFGS-B per finger per pose), 1 run, "
          f"thesis grid only, hands: {', '.join(sorted(ref_hands)) or 'none'}.")
    print("Peak mem: tracemalloc peak of one extra, untimed library call (Python + numpy + numba-runtime heap "
          "allocations during the call).")
    print(flush=True)

    cases: list[Case] = []
    for contour_name in contours:
        contour = cg.example_contour(contour_name)
        for hand_name in hands:
            hand = cg.load_hand(hand_name)
            log(f"[{time.strftime('%H:%M:%S')}] {contour_name} / {hand_name}: library (load {load()}) ...")
            thesis = run_library(contour, hand, THESIS, args.runs)
            dense = run_library(contour, hand, DENSE, args.runs)
            refined = run_library(contour, hand, DENSE, args.runs, refine=True)
            ref = None
            if hand_name in ref_hands:
                log(f"[{time.strftime('%H:%M:%S')}] {contour_name} / {hand_name}: reference (load {load()}) ...")
                ref = run_reference(contour, hand)
                log(f"    reference took {ref.time:.0f} s")
            case = Case(contour_name, hand_name, thesis, dense, refined, ref)
            compare(case, contour, hand)
            cases.append(case)

    rows = table(cases, machine_tag, args.runs)
    goals = targets(cases)
    load_end = load()
    maxrss_mib = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024

    print("## Results")
    print()
    print("\n".join(rows))
    print()
    print("\n".join(goals))
    print()
    print("## Per case")
    print()
    for c in cases:
        lib = c.thesis
        parts = []
        if lib.infeasible:
            parts.append(f"library thesis grid: no feasible grasp ({lib.infeasible})")
        else:
            parts.append(f"library thesis best {fmt_pose(lib.plan.pose)}, {lib.plan.feasible_poses} feasible poses "
                         f"(screen)")
        if c.dense.infeasible:
            parts.append("dense: no feasible grasp")
        else:
            parts.append(f"dense best {fmt_pose(c.dense.plan.pose)}, {c.dense.plan.feasible_poses} feasible")
        if not c.refined.infeasible:
            r = c.refined.plan.refinement
            parts.append(f"refinement gained {r.gain:.6g} ({r.grid_cost:.6f} -> {r.cost:.6f}), best "
                         f"{fmt_pose(c.refined.plan.pose)}")
        parts.append(f"thesis-grid stages (median): {lib.stage_medians()}")
        if c.ref is not None:
            parts.append("reference: no feasible pose" if c.ref.pose is None else
                         f"reference best {fmt_pose(c.ref.pose)}, {c.ref.feasible} feasible poses")
        parts.append(f"-> {c.verdict}")
        print(f"- {c.contour} / {c.hand}: " + "; ".join(parts))
        for note in c.notes:
            print(note)
    print()
    print(f"Load average at end: {load_end}. Process peak RSS (ru_maxrss, whole run incl. reference and imports): "
          f"{maxrss_mib:.0f} MiB.")

    if args.out:
        text = "\n".join([f"Machine: {machine}; load at start {load_start}, at end {load_end}.",
                          f"Library: median of {args.runs} runs after a warm-up call; reference: 1 run; "
                          "peak mem: tracemalloc.", "", *rows, "", *goals, ""])
        tmp = args.out.with_name(args.out.name + ".tmp")
        tmp.write_text(text)
        tmp.replace(args.out)
    return 0


if __name__ == "__main__":
    sys.exit(main())
