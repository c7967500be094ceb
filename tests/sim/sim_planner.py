"""Test helpers for the simulation: the shared-data path.

(A plain module, not a conftest: ``tests/conftest.py`` is imported as ``conftest`` by other tests.)
The trials' planners are the real ones, :mod:`contourgrasp.sim.planners`.
"""

from pathlib import Path

import pytest

SHARED_DATA = Path(__file__).resolve().parents[2].parent / "shared" / "data"


def require_shared_data() -> Path:
    """``<repo>/../shared/data``, or skip the test when it is absent."""
    if not SHARED_DATA.is_dir():
        pytest.skip(f"shared test data not found at {SHARED_DATA}")
    return SHARED_DATA
