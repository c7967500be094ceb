"""One frame's derived images, computed once while the frame is perceived.

Perception's stages each need the depth image's valid readings and its heights above the support
plane, and each computed them again (11 and 9 times a frame). Inside :func:`one_frame`
(:func:`contourgrasp.pipeline.plan_frame` perceives in one) :func:`memoised` keeps each result for the
rest of the frame, keyed by the depth array itself -- perception never writes to its depth images --
and hands it out read-only, so that a caller changing it would fail rather than change it for the
others. Outside a frame nothing is kept.
"""

from __future__ import annotations

from contextlib import contextmanager
from contextvars import ContextVar

import numpy as np

_MEMO: ContextVar[dict | None] = ContextVar("contourgrasp_perception_frame", default=None)


@contextmanager
def one_frame():
    """Keep the derived images of the frame being perceived until the block ends.

    Its depth images must not change inside the block: their derived images are kept by the
    array, not by its values.

    Examples
    --------
    >>> from contourgrasp.perception import valid_depth
    >>> depth = np.full((2, 2), 0.7)
    >>> with one_frame():
    ...     valid_depth(depth) is valid_depth(depth)
    True
    >>> valid_depth(depth) is valid_depth(depth)
    False
    """
    token = _MEMO.set({})
    try:
        yield
    finally:
        _MEMO.reset(token)


def memoised(depth: np.ndarray, key, compute) -> np.ndarray:
    """``compute()``, once per ``depth`` array and hashable ``key`` inside :func:`one_frame` (read-only there)."""
    memo = _MEMO.get()
    if memo is None:
        return compute()
    found = memo.get((id(depth), key))
    if found is None or found[0] is not depth:  # the array is held with its result, so its id is not reused
        value = compute()
        value.flags.writeable = False
        found = memo[(id(depth), key)] = (depth, value)
    return found[1]
