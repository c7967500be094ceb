"""The documentation: every relative link resolves, the README stays a front door, and the product speaks of the
present (no session, issue number or date of an experiment in the docs, the code or the tests)."""

import re
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[1]
PAGES = [REPO / "README.md", REPO / "CHANGELOG.md", REPO / "benchmarks" / "README.md", *sorted((REPO / "docs").glob("*.md"))]
#: Where the product's words are: its pages, code, data files, tests, tools and Makefile (this file names the
#: patterns it looks for, so it is left out).
PRODUCT = [*PAGES, *sorted(REPO.glob("src/contourgrasp/**/*.py")), *sorted(REPO.glob("src/contourgrasp/data/**/*.toml")),
           *sorted(REPO.glob("src/contourgrasp/data/**/*.md")), *sorted(REPO.glob("benchmarks/*.py")),
           *sorted(REPO.glob("tools/*.py")), *(p for p in sorted(REPO.glob("tests/**/*.py")) if p.name != "test_docs.py"),
           REPO / "Makefile"]
PROCESS = re.compile(r"\b[Ss]essions? \d|\b[Ii]ssues? \d|\b20\d\d-[01]\d-[0-3]\d\b|before the change of|since the change of")


@pytest.mark.parametrize("page", PAGES, ids=lambda p: str(p.relative_to(REPO)))
def test_every_relative_link_resolves(page):
    links = re.findall(r"\]\(([^)#\s]+)(?:#[^)]*)?\)", page.read_text(encoding="utf-8"))
    missing = [target for target in links if "://" not in target and not (page.parent / target).exists()]
    assert not missing, f"{page.name} links to {missing}"


def test_the_readme_is_a_front_door():
    lines = (REPO / "README.md").read_text(encoding="utf-8").splitlines()
    assert len(lines) <= 250
    assert lines[3].startswith("make demo") and lines[4].startswith("make test")  # the two commands, first


def test_the_product_speaks_of_the_present():
    found = [f"{path.relative_to(REPO)}:{n}: {line.strip()[:80]}" for path in PRODUCT if path.is_file()
             for n, line in enumerate(path.read_text(encoding="utf-8").splitlines(), 1) if PROCESS.search(line)]
    assert not found, "\n".join(found)


def test_the_process_pattern_finds_what_it_is_for():
    for text in ("session 14's run", "issue 16, item 1.2", "measured on 2026-12-04", "before the change of friction"):
        assert PROCESS.search(text), text
    for text in ("the planner's sessionless node", "tissue 3", "version 0.2.0", "Table 4.4"):
        assert not PROCESS.search(text), text
