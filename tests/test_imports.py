"""The package's import graph: every module imports alone, no module imports one that imports it back, and the
planning path needs no simulation package (the ``[sim]`` extra)."""

import ast
import os
import subprocess
import sys
from pathlib import Path

import contourgrasp

ROOT = Path(contourgrasp.__file__).parent
#: Modules of the ``[sim]`` extra's packages: what planning must not import.
SIMULATION = ("mujoco", "trimesh", "coacd", "tqdm")


def _module_name(path: Path) -> str:
    parts = path.relative_to(ROOT.parent).with_suffix("").parts
    return ".".join(parts[:-1] if parts[-1] == "__init__" else parts)


MODULES = {_module_name(p): p for p in sorted(ROOT.rglob("*.py"))}


def _imported(module: str, path: Path) -> set[str]:
    """The package's modules ``module`` imports anywhere in its file (in functions and TYPE_CHECKING blocks too)."""
    package = module if path.name == "__init__.py" else module.rpartition(".")[0]
    found = set()
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.Import):
            found |= {a.name for a in node.names}
        elif isinstance(node, ast.ImportFrom):
            base = package.split(".")[:len(package.split(".")) - node.level + 1] if node.level else []
            source = ".".join(base + ([node.module] if node.module else []))
            found |= {f"{source}.{a.name}" if f"{source}.{a.name}" in MODULES else source for a in node.names}
    return {name for name in found if name in MODULES and name != module}


def _cycle(graph: dict[str, set[str]]) -> list[str] | None:
    """One cycle of ``graph`` as the list of its modules, or None."""
    state, stack = {}, []

    def visit(node):
        state[node] = "open"
        stack.append(node)
        for nxt in sorted(graph[node]):
            if state.get(nxt) == "open":
                return stack[stack.index(nxt):] + [nxt]
            if nxt not in state and (found := visit(nxt)):
                return found
        stack.pop()
        state[node] = "done"
        return None

    for node in sorted(graph):
        if node not in state and (found := visit(node)):
            return found
    return None


def test_the_cycle_finder_finds_a_cycle():
    assert _cycle({"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": set()}) == ["a", "b", "c", "a"]
    assert _cycle({"a": {"b"}, "b": set()}) is None


def test_no_module_imports_one_that_imports_it_back():
    graph = {name: _imported(name, path) for name, path in MODULES.items()}
    assert graph["contourgrasp.pipeline"]  # the graph is read: the pipeline imports its stages
    assert _cycle(graph) is None, " -> ".join(_cycle(graph))


def test_every_module_imports_alone():
    """Each module in a fresh interpreter state of the package (third-party modules stay loaded, for speed)."""
    code = ("import importlib, sys\n"
            f"for name in {sorted(MODULES)!r}:\n"
            "    for loaded in [m for m in sys.modules if m == 'contourgrasp' or m.startswith('contourgrasp.')]:\n"
            "        del sys.modules[loaded]\n"
            "    importlib.import_module(name)\n")
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, done.stderr[-2000:]


def test_planning_imports_no_simulation_package():
    code = ("import sys, contourgrasp as cg, contourgrasp.cli, contourgrasp.pipeline, contourgrasp.visualize\n"
            "cg.synthesize(cg.example_contour('can'), 'three-finger', yaw_step=0.5)\n"
            f"print(sorted(m for m in {SIMULATION!r} if m in sys.modules))")
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, done.stderr[-2000:]
    assert done.stdout.strip() == "[]"


def _stage(module: str) -> str:
    """The pipeline stage a module belongs to: its package below contourgrasp, or the top-level module itself."""
    return ".".join(module.split(".")[:2])


def test_no_stage_imports_one_that_imports_it_back():
    """Between stages too (io and ros, sim and handmodels): the layers import one way."""
    graph = {}
    for name, path in MODULES.items():
        graph.setdefault(_stage(name), set()).update(_stage(m) for m in _imported(name, path) if _stage(m) != _stage(name))
    assert graph["contourgrasp.ros"] >= {"contourgrasp.io"}  # the graph is read
    assert _cycle(graph) is None, " -> ".join(_cycle(graph))


def test_every_benchmark_and_tool_answers_help():
    """A fresh clone's user reads what a script does before running it: ``--help`` writes nothing and exits 0."""
    repo = Path(__file__).resolve().parents[1]
    scripts = sorted(repo.glob("benchmarks/*.py")) + sorted(repo.glob("tools/*.py"))
    assert len(scripts) >= 10
    for script in scripts:
        done = subprocess.run([sys.executable, str(script), "--help"], capture_output=True, text=True, timeout=300,
                              cwd=repo, env=os.environ | {"MPLBACKEND": "Agg"})
        assert done.returncode == 0 and "usage:" in done.stdout, (script.name, done.stderr[-500:])
