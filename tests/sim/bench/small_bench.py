"""The small bench the parallel, Ray and resume tests run, its serial run, and how they compare trials."""

import json

import pytest

from contourgrasp.cli import main

#: 2 objects x 2 trials x 2 planners; the cheap planners keep it a few seconds.
SMALL = ["bench", "--objects", "can,case", "--trials", "2", "--planners", "paper,centroid-principal-axis"]
TIMING = ("plan_time", "wall_time")
_serial = {}


def trials_without_times(out) -> list[dict]:
    """trials.json of a bench folder, the timing fields left out."""
    return [{k: v for k, v in r.items() if k not in TIMING} for r in json.loads((out / "trials.json").read_text())]


@pytest.fixture(scope="session")
def serial_bench(tmp_path_factory):
    """The output folder of :data:`SMALL` run in this process (``--workers 1``), once per session."""
    if "out" not in _serial:
        out = tmp_path_factory.mktemp("serial") / "out"
        assert main([*SMALL, "--workers", "1", "--out", str(out)]) == 0
        _serial["out"] = out
    return _serial["out"]
