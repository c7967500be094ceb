"""Every equation of the thesis's chapter 3 (eq 3.1-3.41) has exactly one owner.

An owner is the function or class whose docstring says ``Implements eq 3.N``
(or ``Implements eqs 3.N-3.M``, ``Implements eqs 3.N, 3.M``); other places
may cite an equation ("see eq 3.N") but not claim it. ``docs/equations.md``
maps each equation to its owner; the two must agree.
"""

import ast
import functools
import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
PACKAGE = ROOT / "src" / "contourgrasp"
TABLE = ROOT / "docs" / "equations.md"
EQUATIONS = [f"3.{n}" for n in range(1, 42)]

_CLAIM = re.compile(r"Implements eqs?\.?\s+((?:3\.\d+(?:\s*(?:[-–,]|and)\s*)?)+)")
_NUMBER = re.compile(r"3\.(\d+)(?:\s*[-–]\s*3\.(\d+))?")


def claimed(text: str) -> list[str]:
    """The equations a docstring claims: 'Implements eqs 3.9-3.11, 3.14' -> 3.9, 3.10, 3.11, 3.14."""
    numbers = []
    for claim in _CLAIM.findall(text):
        for first, last in _NUMBER.findall(claim):
            numbers += [f"3.{n}" for n in range(int(first), int(last or first) + 1)]
    return numbers


@functools.cache
def owners() -> dict[str, list[str]]:
    """Equation -> the qualified names (module:Class.function) whose docstrings claim it."""
    found = {eq: [] for eq in EQUATIONS}
    for path in sorted(PACKAGE.rglob("*.py")):
        module = ".".join(path.relative_to(PACKAGE.parent).with_suffix("").parts).removesuffix(".__init__")
        for name, doc in _docstrings(ast.parse(path.read_text())):
            for eq in claimed(doc):
                found.setdefault(eq, []).append(f"{module}:{name}")
    return found


def _docstrings(tree, prefix=""):
    for node in tree.body:
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)):
            doc = ast.get_docstring(node)
            if doc:
                yield prefix + node.name, doc
            if isinstance(node, ast.ClassDef):
                yield from _docstrings(node, prefix + node.name + ".")


def table() -> dict[str, str]:
    """docs/equations.md: equation -> owner, from rows '| 3.N | `module:name` | ... |'."""
    rows = re.findall(r"^\|\s*3\.(\d+)\s*\|\s*`([^`]+)`", TABLE.read_text(), flags=re.M)
    return {f"3.{n}": owner for n, owner in rows}


def test_claims_parse_ranges_and_lists():
    assert claimed("Implements eqs 3.9-3.11, 3.14 and 3.16.") == ["3.9", "3.10", "3.11", "3.14", "3.16"]
    assert claimed("Implements eq 3.18 (the ray). See eq 3.19.") == ["3.18"]


@pytest.mark.parametrize("eq", EQUATIONS)
def test_every_equation_has_exactly_one_owner(eq):
    assert len(owners()[eq]) == 1, f"eq {eq} is claimed by {owners()[eq] or 'no function'}"


def test_no_claim_outside_chapter_3_range():
    assert set(owners()) == set(EQUATIONS)


def test_equations_md_names_each_owner():
    found, listed = owners(), table()
    assert sorted(listed, key=lambda e: int(e[2:])) == EQUATIONS
    for eq in EQUATIONS:
        assert found[eq] == [listed[eq]], f"docs/equations.md says eq {eq} is {listed[eq]}, code says {found[eq]}"
