"""Pairing colour and depth images by stamp (no ROS import)."""

from __future__ import annotations

from collections import deque

#: Default largest stamp difference of a colour and a depth image planned as one frame, s.
PAIR_TOLERANCE = 0.02
#: A pair stamped more than this before the newest is a jump of the clock (a driver's reset, sim time against
#: wall time, a bag played again), s: it becomes the newest. Within it, it is a pair completed out of order.
STAMP_JUMP = 5.0


def nearest(stamps, t: float, tolerance: float) -> int | None:
    """Index of the stamp nearest ``t`` within ``tolerance`` (s), the later one on a tie; None if none.

    >>> nearest([1.0, 1.03, 1.1], 1.02, 0.02)
    1
    >>> nearest([1.0], 1.5, 0.02) is None
    True
    """
    best = None
    for i, s in enumerate(stamps):
        if abs(s - t) <= tolerance and (best is None or abs(s - t) <= abs(stamps[best] - t)):
            best = i
    return best


class Pairer:
    """The newest colour and depth messages whose stamps agree within ``tolerance`` seconds.

    :meth:`add_colour` and :meth:`add_depth` take ``(stamp, message)`` and
    return the pair ``(colour, depth)`` the message completes, or None; the
    last ``keep`` unpaired messages of each stream wait for a partner, and a
    message is paired once.

    ``newest`` is the pair completed last, unless it is stamped at most :data:`STAMP_JUMP` before the
    newest so far (completed out of order: the newer frame stays). A pair stamped further back is a
    jump of the camera's clock, not an old frame: it becomes the newest, and ``jumped`` says by how
    much the stamps went back (s; None after a pair without a jump), for the caller to warn.
    """

    def __init__(self, tolerance: float = PAIR_TOLERANCE, keep: int = 10):
        self.tolerance = tolerance
        self.colour: deque = deque(maxlen=keep)
        self.depth: deque = deque(maxlen=keep)
        self.newest = None
        self.newest_stamp: float | None = None
        self.jumped: float | None = None

    def add_colour(self, stamp: float, msg):
        """Keep a colour message; the pair it completes with the nearest waiting depth, or None."""
        return self._add(stamp, msg, self.colour, self.depth, colour_first=True)

    def add_depth(self, stamp: float, msg):
        """Keep a depth message; the pair it completes with the nearest waiting colour, or None."""
        return self._add(stamp, msg, self.depth, self.colour, colour_first=False)

    def _add(self, stamp, msg, own: deque, other: deque, *, colour_first: bool):
        own.append((stamp, msg))
        i = nearest([s for s, _ in other], stamp, self.tolerance)
        if i is None:
            return None
        partner_stamp, partner = other[i]
        del other[i]
        own.pop()
        pair = (msg, partner) if colour_first else (partner, msg)
        pair_stamp = stamp if colour_first else partner_stamp
        back = 0.0 if self.newest_stamp is None else self.newest_stamp - pair_stamp
        self.jumped = back if back > STAMP_JUMP else None
        if back <= 0 or self.jumped is not None:
            self.newest, self.newest_stamp = pair, pair_stamp
        return pair
