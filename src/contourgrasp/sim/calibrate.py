"""Virtual start points (lambda_virt) from the simulated hand's closing speeds (thesis 3.4, eq 3.35-3.37).

The ratio cost wants every finger to reach the object at the same time. It
compares ``dist_i``, the distance from finger i's *virtual* start to its grasp
point; with one tendon the fingers close at different rates, and lambda_virt
moves each virtual start along the trajectory so that equal ``dist`` means
equal arrival time. The thesis estimated the values by eye (chapter 5); this
module measures them on the simulated hand of :mod:`contourgrasp.sim.tendon_hand`.

Derivation
----------
Close the hand on nothing with the trials' actuation (the tendon force ramps
over ``Execution.close_time``, then holds for ``Execution.squeeze_time``). Let
``s_i(t)`` be the distance finger i's tip has travelled along its trajectory
``t`` seconds after the ramp began, and ``T_i(d)`` the first time it reaches
``d``. A grasp point ``d_i`` along finger i's trajectory is reached at
``T_i(d_i)``. The grasp point lies on the trajectory, so (while the virtual
start lies behind it) the ratio cost's distance is ``dist_i = d_i - lambda_i``
(:mod:`contourgrasp.hand`: positive lambda lies ahead along the closing
motion). Equal ``dist`` is to mean equal arrival: with a reference finger r
(``lambda_r = 0``), finger i touching at ``d`` arrives together with the
reference touching at ``s_r(T_i(d))``, hence

    lambda_i(d) = d - s_r(T_i(d)).

This varies with ``d`` when the fingers start at different times or their
speeds are not in a constant ratio; the one number the hand file holds is its
mean over the finger's travel (the least-squares constant for a contact
distance spread evenly over ``[0, F_i']``, ``F_i' = F_i - CLOSED_WITHIN``)::

    lambda_i = 1 / F_i' * integral_0^F_i' (d - s_r(T_i(d))) dd.

For constant speeds ``v_i``, ``v_r`` and a common start, ``s_r(T_i(d)) = d v_r / v_i``
and ``lambda_i = F_i' / 2 * (1 - v_r / v_i)``: positive for a finger faster than
the reference (its virtual start lies ahead, so the cost leaves it farther
from the object), negative for a slower one, whose virtual start lies
"further away to the closed finger position" (thesis 3.4).

The reference is by default the finger that closes last. Every other finger
then reaches its full travel before the reference does, so ``s_r(T_i(d))`` is
always a distance the reference can still touch at; against a faster
reference a slow finger's late contacts map to the reference's end stop and
bias the mean. Another reference shifts all values by about a constant, which
the ratio cost (each ``dist_i`` against the mean of the others) ignores as long
as no virtual start passes its grasp point.

Free-space closing stands for a grasp because the tendon is force-controlled:
each finger's spring balances the tendon force alone, so a finger stopped by
the object does not slow the others.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from ..errors import SimulationError
from ..hand import Hand
from ..io.hand_file import load_hand
from ..tolerances import CLOSED_WITHIN, CLOSING_TIE, FINGER_MOVED, TRAVEL_SAMPLES
from .tendon_hand import HandDesign
from .measure import fingertip_paths
from .mjcf import TIMESTEP
from .trial import Execution

#: Decimals of a meter kept in calibrated virtual starts (0.1 mm): finer digits mean nothing to a 2-D hand model.
DECIMALS = 4


@dataclass(frozen=True, eq=False)
class FingerTravel:
    """Fingertips closing in free space: distance travelled along each trajectory over time.

    Attributes
    ----------
    names : tuple of str
    travel : (n,) float
        F_i: full travel of each finger, m.
    times : (k,) float
        Seconds since the tendon force began to ramp; increasing, from 0.
    travelled : (n, k) float
        s_i(t): distance along the trajectory from the open fingertip, m.
    """

    names: tuple[str, ...]
    travel: np.ndarray
    times: np.ndarray
    travelled: np.ndarray

    def __post_init__(self):
        travel, times = np.asarray(self.travel, dtype=float), np.asarray(self.times, dtype=float)
        travelled = np.asarray(self.travelled, dtype=float)
        if travel.shape != (len(self.names),) or travelled.shape != (len(self.names), len(times)):
            raise SimulationError(f"closing of {len(self.names)} fingers needs travel (n,) and travelled (n, k), "
                             f"got {travel.shape} and {travelled.shape} for {len(times)} times")
        if len(times) < 2 or times[0] != 0 or np.any(np.diff(times) <= 0):
            raise SimulationError("closing times must increase from 0")
        object.__setattr__(self, "names", tuple(self.names))
        object.__setattr__(self, "travel", travel)
        object.__setattr__(self, "times", times)
        object.__setattr__(self, "travelled", travelled)

    @property
    def progress(self) -> np.ndarray:
        """(n, k) float: travelled distance clipped to [0, F_i] and never decreasing, m.

        The tip's overshoot at the joint limit and its rebound are not progress;
        monotone progress gives every distance a first arrival time.
        """
        return np.maximum.accumulate(np.clip(self.travelled, 0.0, self.travel[:, None]), axis=1)

    def arrival_times(self, i: int, d) -> np.ndarray:
        """T_i(d): first time finger ``i`` has travelled ``d`` (m), linear between samples, s."""
        return _first_passage(self.times, self.progress[i], np.asarray(d, dtype=float))

    @property
    def closing_times(self) -> np.ndarray:
        """(n,) float: time each finger reaches its full travel (within :data:`~contourgrasp.tolerances.CLOSED_WITHIN`), s.

        Raises
        ------
        SimulationError
            A finger does not close that far while recorded.
        """
        closed = self.travel - CLOSED_WITHIN
        short = self.progress[:, -1] < closed
        if short.any():
            name = self.names[int(np.argmax(short))]
            raise SimulationError(f"finger {name!r} does not close to within {CLOSED_WITHIN * 1e3:g} mm of its travel "
                             f"in {self.times[-1]:g} s")
        return np.array([self.arrival_times(i, c)[()] for i, c in enumerate(closed)])

    @property
    def start_times(self) -> np.ndarray:
        """(n,) float: time each fingertip has moved :data:`~contourgrasp.tolerances.FINGER_MOVED`, s."""
        return np.array([self.arrival_times(i, FINGER_MOVED)[()] for i in range(len(self.names))])

    @property
    def mean_speeds(self) -> np.ndarray:
        """(n,) float: distance to full closure over the closing time (delay included), m/s."""
        return (self.travel - CLOSED_WITHIN) / self.closing_times


def _first_passage(times: np.ndarray, progress: np.ndarray, d: np.ndarray) -> np.ndarray:
    """Earliest time a non-decreasing ``progress`` (k,) reaches each ``d``, interpolated within the step."""
    k = np.clip(np.searchsorted(progress, d, side="left"), 1, len(progress) - 1)
    before, after = progress[k - 1], progress[k]
    step = after - before
    w = np.clip(np.divide(d - before, step, out=np.zeros_like(step), where=step > 0), 0.0, 1.0)
    return times[k - 1] + w * (times[k] - times[k - 1])


def derive_virtual_starts(closing: FingerTravel, *, reference: str | None = None) -> dict[str, float]:
    """lambda_virt of every finger from its closing (module docstring: the derivation).

    Parameters
    ----------
    closing : FingerTravel
    reference : str, optional
        Finger whose lambda_virt is 0; default the one that reaches its full travel last.

    Returns
    -------
    dict of str to float
        Finger name to lambda_virt, m (positive: virtual start ahead along the closing motion).

    Raises
    ------
    SimulationError
        An unknown reference, or a finger that never closes (see :attr:`FingerTravel.closing_times`).
    """
    r = _reference_index(closing, reference)
    ends = closing.travel - CLOSED_WITHIN
    starts = {}
    for i, name in enumerate(closing.names):
        d = np.linspace(0.0, ends[i], TRAVEL_SAMPLES)
        together = np.interp(closing.arrival_times(i, d), closing.times, closing.progress[r])
        starts[name] = 0.0 if i == r else float(np.trapezoid(d - together, d) / ends[i])
    return starts


def _reference_index(closing: FingerTravel, reference: str | None) -> int:
    closing_times = closing.closing_times  # also refuses a record in which some finger never closes
    if reference is None:  # the first of the last, ties within CLOSING_TIE (mirror fingers: ring and little)
        return int(np.flatnonzero(closing_times >= closing_times.max() - CLOSING_TIE)[0])
    if reference not in closing.names:
        raise SimulationError(f"reference finger {reference!r} is not one of {', '.join(closing.names)}")
    return closing.names.index(reference)


@dataclass(frozen=True)
class Calibration:
    """Measured closing of a simulated hand and the virtual starts derived from it.

    Attributes
    ----------
    hand : Hand
        The hand as loaded (its virtual starts unchanged).
    reference : str
        The finger with lambda_virt 0.
    start_time, closing_time, mean_speed, virtual_start : dict of str to float
        Per finger: when it starts to move (s), reaches full travel (s), its
        mean speed up to then (m/s) and the derived lambda_virt (m).
    """

    hand: Hand
    reference: str
    start_time: dict[str, float]
    closing_time: dict[str, float]
    mean_speed: dict[str, float]
    virtual_start: dict[str, float]

    def calibrated_hand(self) -> Hand:
        """The hand with the derived virtual starts, rounded to :data:`DECIMALS`."""
        fingers = tuple(replace(f, virtual_start=_round(self.virtual_start[f.name])) for f in self.hand.fingers)
        return replace(self.hand, fingers=fingers)


def _round(value: float) -> float:
    return round(value, DECIMALS) + 0.0  # + 0.0 turns -0.0 into 0.0


def measure_closing(hand, *, timing: str = "thesis", design: HandDesign = HandDesign(),
                    execution: Execution = Execution()) -> FingerTravel:
    """Close the simulated hand on nothing, as a trial closes it, and record every fingertip's progress.

    Parameters
    ----------
    hand : Hand or str
        A preset name, hand TOML path or :class:`Hand` with ray fingers.
    timing, design
        See :func:`~contourgrasp.sim.tendon_hand.build_hand`.
    execution : Execution
        Its ``close_time`` (force ramp) and ``squeeze_time`` (full force) are simulated.

    Raises
    ------
    SimulationError
        A hand the simulation cannot build (arc fingers, unreachable travel, unknown timing).
    """
    hand = load_hand(hand)
    paths = fingertip_paths(hand, timing=timing, design=design, close_time=execution.close_time,
                            hold_time=execution.squeeze_time)
    # The recorded tips are after each step; at time 0 the hand is open, every tip at its start.
    travelled = [np.concatenate([[0.0], (paths[f.name] - f.start) @ np.asarray(f.trajectory.closing_direction)])
                 for f in hand.fingers]
    times = TIMESTEP * np.arange(len(travelled[0]))
    return FingerTravel(names=tuple(f.name for f in hand.fingers), travel=np.array([f.travel for f in hand.fingers]),
                   times=times, travelled=np.array(travelled))


def calibrate_virtual_starts(hand, *, reference: str | None = None, timing: str = "thesis",
                             design: HandDesign = HandDesign(), execution: Execution = Execution()) -> Calibration:
    """Measure the simulated hand's closing and derive every finger's lambda_virt from it.

    Parameters
    ----------
    hand : Hand or str
        A preset name, hand TOML path or :class:`Hand` with ray fingers.
    reference : str, optional
        Finger whose lambda_virt is 0; default the one that closes last.
    timing, design, execution
        The simulated hand and its actuation (defaults: those of the trials).

    Returns
    -------
    Calibration
        ``calibration.virtual_start`` maps finger names to lambda_virt (m).

    Raises
    ------
    SimulationError
        A hand the simulation cannot build, an unknown reference finger, or a
        finger that does not close fully.
    """
    hand = load_hand(hand)
    closing = measure_closing(hand, timing=timing, design=design, execution=execution)
    reference = closing.names[_reference_index(closing, reference)]
    return Calibration(hand=hand, reference=reference, start_time=_per_finger(closing, closing.start_times),
                       closing_time=_per_finger(closing, closing.closing_times),
                       mean_speed=_per_finger(closing, closing.mean_speeds),
                       virtual_start=derive_virtual_starts(closing, reference=reference))


def _per_finger(closing: FingerTravel, values) -> dict[str, float]:
    return dict(zip(closing.names, map(float, values), strict=True))


def calibration_table(calibration: Calibration) -> list[str]:
    """Lines of a plain-text table: per finger the measured closing and lambda_virt, derived and in the hand file."""
    lines = [f"{'finger':8s} {'starts s':>9s} {'closed s':>9s} {'speed m/s':>10s} {'lambda_virt m':>14s} "
             f"{'hand file m':>12s}"]
    for f in calibration.hand.fingers:
        name = f.name + (" *" if f.name == calibration.reference else "")
        lines.append(f"{name:8s} {calibration.start_time[f.name]:9.3f} {calibration.closing_time[f.name]:9.3f} "
                     f"{calibration.mean_speed[f.name]:10.4f} {_round(calibration.virtual_start[f.name]):+14.4f} "
                     f"{f.virtual_start:+12.4f}")
    lines.append("* reference finger (lambda_virt 0); positive: virtual start ahead along the closing motion")
    return lines
