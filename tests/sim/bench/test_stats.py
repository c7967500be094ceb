"""contourgrasp.sim.bench.stats: success rates and Wilson intervals."""

import pytest

from contourgrasp.errors import SimulationError
from contourgrasp.sim.bench import wilson_interval


@pytest.mark.parametrize("wins, n, low, high", [(0, 10, 0.0, 0.2775), (10, 10, 0.7225, 1.0), (5, 10, 0.2366, 0.7634),
                                                (18, 20, 0.6990, 0.9721)])
def test_wilson_interval_matches_its_closed_form(wins, n, low, high):
    assert wilson_interval(wins, n) == pytest.approx((low, high), abs=1e-4)


@pytest.mark.parametrize("wins, n", [(0, 0), (3, 2), (-1, 5), (1.5, 3)])
def test_wilson_interval_refuses_impossible_counts(wins, n):
    with pytest.raises(SimulationError):
        wilson_interval(wins, n)
