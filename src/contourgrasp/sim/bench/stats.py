"""Success rates of a bench's trials, the thesis's beside them, and their Wilson intervals."""

from __future__ import annotations

import math

import numpy as np

from ...errors import SimulationError
from ...validation import integer
from ..trial import TrialRecord
from .config import THESIS_SUCCESS

#: z of the 95 % Wilson interval.
WILSON_Z = 1.959963984540054


def records(results, planner: str, obj: str | None = None) -> list[TrialRecord]:
    """The records of ``planner``'s trials (on ``obj`` only, when given)."""
    return [r.record for r in results if r.planner == planner and (obj is None or r.record.object == obj)]


def success_rates(results, planner: str, objects) -> dict[str, float]:
    """Success rate per object name of ``planner``'s trials, and over all of them (key ``"all"``)."""
    own = records(results, planner)
    rates = {o: float(np.mean([r.success for r in own if r.object == o])) for o in objects}
    return rates | {"all": float(np.mean([r.success for r in own]))}


def sort_planner(bench) -> str:
    """The planner objects are ranked by: ``default`` when the bench runs it, else its first."""
    return "default" if "default" in bench.planners else bench.planners[0]


def thesis_rates(objects) -> dict[str, float | None]:
    """Table 4.4's rate per object name (None where it has none), and their mean over these objects (``"all"``)."""
    rates = {o: THESIS_SUCCESS.get(o) for o in objects}
    known = [r for r in rates.values() if r is not None]
    return rates | {"all": float(np.mean(known)) if known else None}


def wilson_interval(successes: int, trials: int, z: float = WILSON_Z) -> tuple[float, float]:
    """The Wilson score interval of a success rate (95 % for the default ``z``).

    Parameters
    ----------
    successes : int
        In ``[0, trials]``.
    trials : int
        At least 1.
    z : float
        Standard normal quantile of the interval.

    Returns
    -------
    (float, float)
        (low, high) in [0, 1].

    Raises
    ------
    SimulationError
        ``trials`` below 1 or ``successes`` outside ``[0, trials]``.

    Examples
    --------
    >>> low, high = wilson_interval(8, 10)
    >>> round(low, 3), round(high, 3)
    (0.49, 0.943)
    """
    trials = integer("trials", trials, 1, error=SimulationError)
    successes = integer("successes", successes, 0, maximum=trials, error=SimulationError)
    rate = successes / trials
    shrink = 1 + z * z / trials
    centre = (rate + z * z / (2 * trials)) / shrink
    half = z * math.sqrt(rate * (1 - rate) / trials + z * z / (4 * trials * trials)) / shrink
    return max(0.0, centre - half), min(1.0, centre + half)
