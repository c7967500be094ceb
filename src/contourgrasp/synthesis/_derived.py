"""Values every stage of a plan derives from the same model or hand, computed once and shared.

Every stage of a plan (screening, exact re-evaluation, each round of the refinement) needs the
same polygon of its EFD model and the same arrays of its hand; they are cached by the identity of
their owner and go with it. Callers must not modify them (they are read-only).
"""

from __future__ import annotations

import weakref
from dataclasses import dataclass

import numpy as np

from ..contour import sample
from .. import tolerances as tol
from ..contour import EFD
from ..hand import Hand, HandSegments, Ray

#: Values derived from an object (a model, a hand) by :func:`cached`: id -> (weak reference, {kind: value}).
_DERIVED: dict = {}


def cached(owner, kind, build):
    """``build()``, computed once per ``owner`` (by identity) and ``kind``; the entry goes with its owner."""
    key = id(owner)
    entry = _DERIVED.get(key)
    if entry is None or entry[0]() is not owner:
        entry = _DERIVED[key] = (weakref.ref(owner, lambda _, key=key: _DERIVED.pop(key, None)), {})
    values = entry[1]
    if kind not in values:
        values[kind] = build()
    return values[kind]


def polygon(model: EFD, samples: int = tol.EFD_SAMPLES) -> tuple[np.ndarray, np.ndarray]:
    """:func:`contourgrasp.contour.sample` of ``model``, computed once per model and count (:func:`cached`)."""
    return cached(model, ("polygon", samples), lambda: read_only(*sample(model, samples)))


def read_only(*arrays: np.ndarray) -> tuple[np.ndarray, ...]:
    """The arrays, made read-only: cached values are shared, and a write to one would leak into later plans."""
    for a in arrays:
        a.setflags(write=False)
    return arrays


@dataclass(frozen=True, eq=False)
class HandArrays:
    """A hand's fingers as the arrays the search needs (:func:`hand_arrays`); rows are fingers.

    ``rays``: closing directions, NaN for fingers on arcs; ``first``: (s,) bool, the chord is its finger's first.
    """

    segments: HandSegments
    first: np.ndarray
    starts: np.ndarray
    virtual_starts: np.ndarray
    alpha: np.ndarray
    beta: np.ndarray
    required: np.ndarray
    travel: np.ndarray
    rays: np.ndarray


def hand_arrays(hand: Hand) -> HandArrays:
    """The :class:`HandArrays` of ``hand``, built once (:func:`cached`)."""
    return cached(hand, "arrays", lambda: _build_hand_arrays(hand))


def _build_hand_arrays(hand: Hand) -> HandArrays:
    """The :class:`HandArrays` of ``hand``, from its fingers."""
    segments = hand.segments()
    fingers = hand.fingers
    return HandArrays(segments, *read_only(
        first_chords(segments, len(fingers)),
        np.array(hand.starts, dtype=float),
        np.array(hand.virtual_starts, dtype=float),
        np.array([f.alpha for f in fingers], dtype=float),
        np.array([f.beta for f in fingers], dtype=float),
        np.array([f.required for f in fingers]),
        np.array([f.travel for f in fingers], dtype=float),
        np.array([f.trajectory.closing_direction if isinstance(f.trajectory, Ray) else (np.nan, np.nan)
                  for f in fingers]),
    ))


def first_chords(segments: HandSegments, n_fingers: int) -> np.ndarray:
    """(s,) bool: the chord is its finger's first (its half-line decides whether the finger starts inside)."""
    first = np.zeros(len(segments.finger), bool)
    first[np.searchsorted(segments.finger, np.arange(n_fingers))] = True
    return first
