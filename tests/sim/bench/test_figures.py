"""contourgrasp.sim.bench.figures, and the bench package's import graph (no cycle, matplotlib only for figures)."""

import ast
import importlib
import subprocess
import sys
from pathlib import Path

import pytest
from matplotlib.figure import Figure

import contourgrasp.sim.bench as bench_package
from contourgrasp.sim.bench import Bench, BenchTrial, thesis_objects
from contourgrasp.sim.bench.figures import _outcome, failures_figure, objects_figure, success_figure, trials_figure
from contourgrasp.sim.trial import TrialRecord

MODULES = ("config", "parallel", "run", "stats", "report", "journal", "figures")
RECORD = dict(seed=0, fingers_in_contact=(), first_contact=(), push=0.0, lift=0.0, hold_drift=0.0, pose=None,
              approach_depth=None, grasp_height=None, plan_error=None, sim_time=1.0, plan_time=0.1, wall_time=1.0)


def test_figures_are_drawn_from_results():
    bench = Bench(objects=thesis_objects(["can"]), planners=("paper",), trials=2)
    results = [BenchTrial("paper", t, TrialRecord(object="can", success=t == 0, cause=None if t == 0 else
                                                  "dropped", **RECORD)) for t in range(2)]
    assert isinstance(success_figure(bench, results), Figure)
    assert isinstance(trials_figure(bench, []), Figure)  # no trial with a plan: one panel saying so


def test_split_figures_are_drawn_from_results():
    bench = Bench(objects=thesis_objects(["can", "case"]), planners=("default", "random"), trials=2,
                  splits=(("train", ("can",)),))  # the case is in no split: an "other" panel
    results = [BenchTrial(p, t, TrialRecord(object=o, success=t == 0, cause=None if t == 0 else "dropped", **RECORD))
               for p in bench.planners for o in ("can", "case") for t in range(2)]
    figure = objects_figure(bench, results)
    assert [ax.get_title().split(" (")[0] for ax in figure.axes] == ["train", "other"]
    assert isinstance(failures_figure(bench, []), Figure)


@pytest.mark.parametrize("lift, said", [(0.12, "lifted 12.0 cm, moved 3 mm in the hand"),
                                         (-0.004, "lifted -0.4 cm, moved 3 mm in the hand"),
                                         (-31.1, "knocked off the table")])
def test_a_trial_s_outcome_says_how_far_the_object_rose_or_that_it_left_the_table(lift, said):
    record = TrialRecord(object="can", success=False, cause="object pushed away before all fingers touched",
                         **{**RECORD, "lift": lift, "hold_drift": 0.003, "fingers_in_contact": ("thumb",)})
    assert _outcome(record) == f"failed: pushed; {said}; touching: thumb"


def _bench_imports(module: str) -> set[str]:
    """The bench modules ``module`` imports at its top level (relative imports within the package)."""
    tree = ast.parse((Path(bench_package.__file__).parent / f"{module}.py").read_text())
    return {node.module for node in tree.body if isinstance(node, ast.ImportFrom) and node.level == 1}


def test_the_bench_package_has_no_import_cycle():
    graph = {m: _bench_imports(m) for m in MODULES}
    assert set().union(*graph.values()) <= set(MODULES)
    visiting, done = set(), set()

    def visit(module):
        assert module not in visiting, f"import cycle through {module}"
        if module not in done:
            visiting.add(module)
            for imported in graph[module]:
                visit(imported)
            visiting.discard(module)
            done.add(module)

    for module in MODULES:
        visit(module)
    assert "figures" not in set().union(*graph.values())  # figures are imported only when drawn


@pytest.mark.parametrize("module", MODULES)
def test_each_bench_module_imports_alone(module):
    code = f"import contourgrasp.sim.bench.{module}"
    subprocess.run([sys.executable, "-c", code], check=True, capture_output=True)
    assert importlib.import_module(f"contourgrasp.sim.bench.{module}")


def test_importing_the_bench_does_not_import_matplotlib():
    code = "import sys, contourgrasp.sim, contourgrasp.sim.bench; print('matplotlib' in sys.modules)"
    out = subprocess.run([sys.executable, "-c", code], check=True, capture_output=True, text=True).stdout
    assert out.strip() == "False"
