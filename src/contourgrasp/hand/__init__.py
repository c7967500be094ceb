"""Hand model (thesis 3.3): fingertips moving on rays or elliptic arcs in the image plane, and the hand's 3-D body.

:mod:`~contourgrasp.hand.trajectory` holds the fingers' 2-D trajectories and the hand frame's pose
(eq 3.18-3.21, 3.37), :mod:`~contourgrasp.hand.chain` the optional 3-D body (finger chains and the
palm); :class:`Hand` gathers them. A :class:`Hand` without chains (``chains = None``) is a 2-D hand
and plans as one.
"""

from __future__ import annotations

import functools
from dataclasses import dataclass, field

import numpy as np

from .. import tolerances as tol
from .. import validation as check
from ..errors import HandError
from .chain import (
    FingerChain,
    Palm,
    SampledChain,
    chain_angles,
    chain_capsules,
    chain_deviation,
    chain_joints,
    chain_plane,
    chain_tip,
    check_chain,
    interpolate_samples,
    link_names,
)
from .trajectory import (
    Arc,
    Finger,
    Ray,
    polyline_distance,
    rotation,
    to_image,
    trajectory_polyline,
)

__all__ = ["SLICE_CONTOUR", "Arc", "Finger", "FingerChain", "Hand", "HandSegments", "Palm", "Ray", "SampledChain",
           "chain_angles", "chain_capsules", "chain_deviation", "chain_joints", "chain_plane", "chain_tip",
           "check_chain", "interpolate_samples", "link_names",
           "polyline_distance", "rotation", "to_image", "trajectory_polyline"]


#: The outlines a 3-D hand may be planned on (:attr:`Hand.slice_contour`; ``plan_frame``'s ``slice_contour``).
SLICE_CONTOUR = (False, True, "unbalanced")


@dataclass(frozen=True)
class Hand:
    """A hand: its fingers and the feasibility rules for missed fingers.

    Attributes
    ----------
    name : str
    fingers : tuple of Finger
    min_touching : int
        A pose is feasible only when at least this many fingers touch the object.
    miss_penalty : float
        Cost added per finger that closes on air (the ``miss`` part of the cost).
    max_imbalance : float
        The squeeze's balance this hand is planned with when the planner asks for the hand's own
        (``max_imbalance="hand"``, as ``default`` does; :class:`~contourgrasp.synthesis.Safeguards`):
        in [0, 1], 1 off. How unbalanced a squeeze a hand can hold depends on how its fingers are
        driven, which no trajectory shows: a tendon hand is pushed off an unbalanced squeeze, fingers
        holding their own positions stop the object against the others. Default
        ``tolerances.HAND_MAX_IMBALANCE``.
    tips_brush_table : bool
        For a 3-D hand, the grasp height the planner asks for
        (:func:`~contourgrasp.synthesis.grasp_height`, rule ``"auto"``): True, the open fingertips
        just above the table, so a finger that swings lower as it closes may brush it; False (the
        default), high enough that no closing fingertip reaches it. Whether a hand grasps low
        objects better brushing the table depends on how its fingers give way and curl on them,
        which no trajectory shows, so it is chosen on the bench, as ``max_imbalance`` is.
    grasp_height_fraction : float
        For a 3-D hand, the least grasp height the planner asks for (rule ``"auto"``), as a fraction
        of the object's height, in [0, ``tolerances.MAX_GRASP_HEIGHT_FRACTION``]; default
        ``tolerances.GRASP_HEIGHT_FRACTION`` (0.4). The open tips' height is not where they meet
        the object: a finger that curls lifts its tip toward the palm as it closes (the Inspire's by
        50-65 mm), and from lower down it wraps more of the object's underside. Which height holds
        best depends on how its fingers curl around objects, which no trajectory shows: chosen on the
        bench, as ``max_imbalance`` is.
    slice_contour : bool or "unbalanced"
        For a 3-D hand, the outline the planner plans on when it asks for the hand's own
        (``slice_contour="hand"``, as ``default`` does; :func:`~contourgrasp.pipeline.plan_frame`):
        ``"unbalanced"`` (the default), the object's cross-section at the grasp height where the outline
        seen has no balanced squeeze; False, the outline seen always; True, the cross-section always.
        A hand whose fingertips meet the object near the height they start at closes on the
        cross-section there; one that wraps the object with its curling links over a range of heights
        meets it where it is widest, the outline seen. Which holds better depends on how its fingers
        curl round objects, which no trajectory shows: chosen on the bench, as ``max_imbalance`` is.
    chains : tuple of FingerChain or SampledChain, optional
        The fingers' bodies, one per finger in the order of ``fingers``; None (the default) for a
        2-D hand. Given together with ``palm``.
    palm : Palm, optional

    Raises
    ------
    HandError
        No fingers or more than ``tolerances.MAX_FINGERS``, a finger that is not a :class:`Finger`, names not unique, ``min_touching``
        not in 1..number of fingers, ``miss_penalty`` not in [0, ``tolerances.MAX_GAIN``], ``max_imbalance``
        not in [0, 1], ``tips_brush_table`` not a bool, ``grasp_height_fraction`` out of range or
        ``slice_contour`` not one of :data:`SLICE_CONTOUR`;
        chains without a palm or the reverse, not one chain per finger, or a chain that does not
        realise its finger's trajectory (:func:`check_chain`, naming the finger).
    """

    name: str
    fingers: tuple[Finger, ...]
    min_touching: int
    miss_penalty: float = 250.0
    max_imbalance: float = tol.HAND_MAX_IMBALANCE
    tips_brush_table: bool = False
    grasp_height_fraction: float = tol.GRASP_HEIGHT_FRACTION
    slice_contour: bool | str = "unbalanced"
    description: str = field(default="", compare=False)
    chains: tuple[FingerChain | SampledChain, ...] | None = None
    palm: Palm | None = None

    def __post_init__(self):
        if not isinstance(self.name, str) or not isinstance(self.description, str):
            raise HandError(f"hand name and description must be strings, got {self.name!r}, {self.description!r}")
        if not isinstance(self.fingers, (tuple, list)) or not all(isinstance(f, Finger) for f in self.fingers):
            raise HandError(f"hand {self.name!r}: fingers must be a sequence of Finger")
        object.__setattr__(self, "fingers", tuple(self.fingers))
        n = len(self.fingers)
        if n == 0:
            raise HandError(f"hand {self.name!r} has no fingers")
        check.at_most(f"hand {self.name!r}: number of fingers", n, tol.MAX_FINGERS, error=HandError)
        if isinstance(self.min_touching, bool) or not isinstance(self.min_touching, (int, np.integer)) or not (
                1 <= self.min_touching <= n):
            raise HandError(f"hand {self.name!r}: min_touching must be in 1..{n}, got {self.min_touching!r}")
        check.bounded(f"hand {self.name!r}: miss_penalty", self.miss_penalty, tol.MAX_GAIN, error=HandError)
        share = check.bounded(f"hand {self.name!r}: max_imbalance", self.max_imbalance, 1.0, "", error=HandError)
        object.__setattr__(self, "max_imbalance", share)
        if not isinstance(self.tips_brush_table, (bool, np.bool_)):
            raise HandError(f"hand {self.name!r}: tips_brush_table must be true or false, "
                            f"got {self.tips_brush_table!r}")
        object.__setattr__(self, "tips_brush_table", bool(self.tips_brush_table))
        fraction = check.bounded(f"hand {self.name!r}: grasp_height_fraction", self.grasp_height_fraction,
                                 tol.MAX_GRASP_HEIGHT_FRACTION, "", error=HandError)
        object.__setattr__(self, "grasp_height_fraction", fraction)
        object.__setattr__(self, "slice_contour", check.choice(f"hand {self.name!r}: slice_contour",
                                                               self.slice_contour, SLICE_CONTOUR, error=HandError))
        if len({f.name for f in self.fingers}) != n:
            raise HandError(f"hand {self.name!r}: finger names must be unique")
        self._check_body()

    def _check_body(self) -> None:
        if (self.chains is None) != (self.palm is None):
            raise HandError(f"hand {self.name!r}: a 3-D hand needs both a chain for every finger and a palm")
        if self.chains is None:
            return
        if not isinstance(self.palm, Palm):
            raise HandError(f"hand {self.name!r}: palm must be a Palm, got {type(self.palm).__name__}")
        if not isinstance(self.chains, (tuple, list)) or not all(isinstance(c, (FingerChain, SampledChain))
                                                                 for c in self.chains):
            raise HandError(f"hand {self.name!r}: chains must be a sequence of FingerChain or SampledChain")
        object.__setattr__(self, "chains", tuple(self.chains))
        if len(self.chains) != len(self.fingers):
            raise HandError(f"hand {self.name!r}: {len(self.chains)} chains for {len(self.fingers)} fingers")
        for finger, chain in zip(self.fingers, self.chains, strict=True):
            _check_chain_once(finger, chain)

    @property
    def is_3d(self) -> bool:
        """True when the hand carries its bodies (chains and palm)."""
        return self.chains is not None

    @property
    def open_tip_depth(self) -> float | None:
        """Depth of the open hand's lowest fingertip (tip centre) below the palm's underside, m; None in 2-D."""
        return None if self.chains is None else max(float(chain_tip(c, 0.0)[0, 2]) for c in self.chains)

    @property
    def closing_tip_depth(self) -> float | None:
        """Deepest any fingertip (tip centre) goes below the palm's underside while closing, m; None in 2-D.

        Sampled at ``tolerances.CHAIN_SAMPLES`` closing progresses: a finger leaning outward swings its
        tip lower on the way in before it rises again.
        """
        if self.chains is None:
            return None
        s = np.linspace(0.0, 1.0, tol.CHAIN_SAMPLES)
        return max(float(chain_tip(c, s)[:, 2].max()) for c in self.chains)

    @property
    def starts(self) -> np.ndarray:
        """(n_fingers, 2) float: open-hand fingertips, hand frame."""
        return np.array([f.start for f in self.fingers])

    @property
    def ends(self) -> np.ndarray:
        """(n_fingers, 2) float: closed-hand fingertips, hand frame."""
        return np.array([f.end for f in self.fingers])

    @property
    def virtual_starts(self) -> np.ndarray:
        """(n_fingers, 2) float: virtual start points p_virt, hand frame."""
        return np.array([f.virtual_start_point for f in self.fingers])

    @property
    def grasp_centre(self) -> np.ndarray:
        """(2,) float: mean of the fully closed fingertips, hand frame."""
        return self.ends.mean(axis=0)

    @property
    def thumb_index(self) -> int:
        """The thumb's index in ``fingers``: the first required finger, else the first."""
        return next((i for i, f in enumerate(self.fingers) if f.required), 0)

    @property
    def pinch_centre(self) -> np.ndarray:
        """(2,) float: midway between the thumb's closed tip (:attr:`thumb_index`) and the closed tip nearest it,
        hand frame.

        Where the lifting poses of a brute-force search put the object's
        centre, on our five-finger hand and the Inspire alike (README, "The object between thumb
        and index"); the thumb and the finger opposite it hold what the others only touch.
        """
        thumb = self.thumb_index
        ends = self.ends
        others = np.delete(np.arange(len(ends)), thumb)
        if len(others) == 0:
            return ends[thumb]
        nearest = others[np.argmin(np.linalg.norm(ends[others] - ends[thumb], axis=1))]
        return (ends[thumb] + ends[nearest]) / 2

    def segments(self) -> HandSegments:
        """All fingers' trajectory chords, stacked for vectorised intersection."""
        starts, ends, finger, lam0 = [], [], [], []
        for i, f in enumerate(self.fingers):
            pts, lam = f.polyline()
            starts.append(pts[:-1])
            ends.append(pts[1:])
            finger.append(np.full(len(lam) - 1, i))
            lam0.append(lam[:-1])
        return HandSegments(
            start=np.vstack(starts), end=np.vstack(ends), finger=np.concatenate(finger), lam0=np.concatenate(lam0)
        )


@dataclass(frozen=True, eq=False)
class HandSegments:
    """Trajectory chords of all fingers, hand frame.

    Attributes
    ----------
    start, end : (s, 2) float
    finger : (s,) int
        Index of the finger each chord belongs to; chords of a finger are in closing order.
    lam0 : (s,) float
        Distance travelled at each chord's start, m.
    """

    start: np.ndarray
    end: np.ndarray
    finger: np.ndarray
    lam0: np.ndarray

    @property
    def length(self) -> np.ndarray:
        return np.linalg.norm(self.end - self.start, axis=1)


@functools.lru_cache(maxsize=64)
def _check_chain_once(finger: Finger, chain: FingerChain | SampledChain) -> None:
    """:func:`check_chain`, remembered: the search copies its hand per attempt (``min_touching``), 1 ms each."""
    check_chain(finger, chain)
