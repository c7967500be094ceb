"""Telling a failed grasp as a robot tells it: from the hand's readings and a new picture.

After an attempt the closed hand carries what it holds out of the camera's view
(:func:`contourgrasp.sim.trial.run_trial` with several attempts). :func:`hand_holds` reads the hand as
its encoders and a wrist force-torque sensor would -- a finger stopped short of where it closes on
nothing, or a load on the wrist. :func:`seen_lifted` reads a new picture as a robot's camera would --
whether the object still stands where it stood. :func:`told_lifted` combines them; neither reads the
simulator's truth (docs/regrasp.md).
"""

from __future__ import annotations

import cv2
import numpy as np

from .. import perception
from ..errors import SegmentationError
from ..perception.table import heights
from ..tolerances import (DETECT_COLOUR, DETECT_CONTRAST, DETECT_REACH, DETECT_RISE, DETECT_SHARE, HOLD_LOAD,
                          HOLD_READING, LIGHTNESS_WEIGHT, MIN_HEIGHT)


def told_lifted(planned, before, after, reading, free_closure, *, anywhere: bool = False) -> bool:
    """Whether an attempt is told a success: the hand holds something (:func:`hand_holds`) and, in a scene of
    several objects, the new picture no longer shows the target where it stood (:func:`seen_lifted`); with
    ``anywhere`` (one object: whatever the hand holds is it) the hand alone tells, and ``after`` is not read."""
    return hand_holds(reading, free_closure) and (anywhere or seen_lifted(planned, before, after))


def hand_holds(reading, free_closure) -> bool:
    """Whether a closed hand holds something: a finger joint of ``reading``
    (:class:`~contourgrasp.sim.scene.HandReading`) stopped at least ``tolerances.HOLD_READING`` short of where it
    stops closed on nothing (``free_closure``'s) -- a finger on an object --, or the wrist carries at least
    ``tolerances.HOLD_LOAD`` more than the empty hand -- an object caged in the closed hand, its fingers at
    their limits, still weighs."""
    joints, free = np.asarray(reading.joints, dtype=float), np.asarray(free_closure.joints, dtype=float)
    stopped = joints.size and float(np.max(np.abs(joints - free))) >= HOLD_READING
    return bool(stopped or reading.load - free_closure.load >= HOLD_LOAD)


def seen_lifted(planned, before, after, *, anywhere: bool = False) -> bool:
    """Whether a new picture says a grasp lifted its object: the picture taken after the hand carried what it holds
    out of view (:func:`contourgrasp.sim.trial.run_trial`) no longer shows the object standing where it stood.

    ``before`` and ``after`` are the (rgb, depth) pictures of the attempt's plan and after it. The
    object stood on the pixels that saw it before (``planned.segmentation.mask``; ``planned.seen`` where that
    is a tilted camera's footprint), its top ``h0`` above the
    support. It is still there when at least ``tolerances.DETECT_SHARE`` of those pixels show the same
    colour after (CIELAB within ``tolerances.DETECT_COLOUR``: it has not moved; a thin object depth
    does not see is told so too) -- when its colour differs from what surrounds it by at least
    ``tolerances.DETECT_CONTRAST``, or the table would look the same --, or when, within
    ``tolerances.DETECT_REACH`` (m, on the table) of those pixels, at least that share as many pixels belong to objects standing on the support
    (:func:`~contourgrasp.perception.find_candidates`) whose top is lower than
    ``h0 + tolerances.DETECT_RISE``: an object pushed a few centimetres, or dropped back, is still
    there; one carried away leaves the table where it was. With ``anywhere`` (a scene of one object:
    whatever stands on the table is it) the standing pixels are counted over the whole picture, and so
    are the pixels of the object's colour (its former pixels' median; its lightness weighted as the flat
    parts' colour evidence weighs it, since the table's shading changes the table's) on or above the
    support (not the floor beyond the table), where that weighted colour stands out from what
    surrounded the object: an object pushed or rolled farther, thin or not, is still there too.
    """
    intrinsics = planned.camera
    try:
        plane = perception.fit_table_plane(after[1], intrinsics)
    except SegmentationError:
        return False  # no table in view: nothing told
    seen = getattr(planned, "seen", None)
    footprint = getattr(planned.segmentation, "on_table", False) and seen is not None
    mask = np.asarray(seen if footprint else planned.segmentation.mask, dtype=bool)
    return not (_colour_still_there(before[0], after, mask, intrinsics, plane, anywhere)
                or _still_standing(before[1], after[1], mask, intrinsics, plane, anywhere))


def _colour_still_there(rgb_before, after, mask, intrinsics, plane, anywhere: bool) -> bool:
    """:func:`seen_lifted`'s colour tests: the object's pixels unmoved, or (``anywhere``) its colour elsewhere."""
    lab_before, lab_after = (cv2.cvtColor(np.ascontiguousarray(image), cv2.COLOR_RGB2Lab).astype(float)
                             for image in (rgb_before, after[0]))
    colour, around = np.median(lab_before[mask], axis=0), _surroundings(lab_before, mask)
    if np.linalg.norm(colour - around) >= DETECT_CONTRAST and \
            np.mean(np.linalg.norm(lab_before[mask] - lab_after[mask], axis=1) < DETECT_COLOUR) >= DETECT_SHARE:
        return True  # unmoved
    # elsewhere, the table's shading changes its lightness as much as a grey object differs from it: hue tells
    return anywhere and np.linalg.norm(_hued(colour - around)) >= DETECT_CONTRAST and \
        _seen_elsewhere(lab_after, colour, after[1], intrinsics, plane, mask.sum())


def _still_standing(depth_before, depth_after, mask, intrinsics, plane, anywhere: bool) -> bool:
    """:func:`seen_lifted`'s depth test: as many pixels of objects standing on the support, no taller than it was,
    near its former pixels beyond what stood there besides it before (its neighbours) -- ``anywhere``: in the whole
    picture."""
    with np.errstate(invalid="ignore"):
        former = heights(depth_before, intrinsics, plane)[mask]
    top = float(np.nanmax(former)) if np.isfinite(former).any() else 0.0
    after = _standing(depth_after, intrinsics, plane, top + DETECT_RISE)
    if anywhere:
        return int(after.sum()) >= DETECT_SHARE * int(mask.sum())
    z = float(np.nanmedian(np.where(depth_before[mask] > 0, depth_before[mask], np.nan))) if mask.any() else 1.0
    reach = max(1, int(round(DETECT_REACH * intrinsics.fx / max(z, 1e-3))))
    near = cv2.dilate(mask.astype(np.uint8), cv2.getStructuringElement(cv2.MORPH_ELLIPSE, (2 * reach + 1,) * 2)) > 0
    besides = _standing(depth_before, intrinsics, plane, np.inf) & near & ~mask
    return int((after & near).sum()) - int(besides.sum()) >= DETECT_SHARE * int(mask.sum())


def _standing(depth, intrinsics, plane, below: float) -> np.ndarray:
    """(H, W) bool: the pixels of the objects perception finds standing on ``plane`` whose top is below ``below`` (m)
    -- candidates, so no speckle."""
    standing = np.zeros(depth.shape[:2], dtype=bool)
    for candidate in perception.find_candidates(depth, intrinsics, plane):
        if candidate.height < below:
            standing |= candidate.mask
    return standing


def _seen_elsewhere(lab, colour, depth, intrinsics, plane, count) -> bool:
    """Whether at least ``DETECT_SHARE * count`` pixels on or above the support (not the floor beyond the table)
    show ``colour`` within ``DETECT_COLOUR``, lightness weighted (:func:`_hued`)."""
    with np.errstate(invalid="ignore"):
        on_support = heights(depth, intrinsics, plane) > -MIN_HEIGHT
    return int(((np.linalg.norm(_hued(lab - colour), axis=-1) < DETECT_COLOUR) & on_support).sum()) >= \
        DETECT_SHARE * count


def _hued(lab_difference):
    """CIELAB differences with the lightness weighted by ``LIGHTNESS_WEIGHT`` (as the flat parts' colour evidence)."""
    return np.asarray(lab_difference) * [LIGHTNESS_WEIGHT, 1.0, 1.0]


def _surroundings(lab, mask) -> np.ndarray:
    """(3,) the median colour of a ring 3-10 px around ``mask`` in the image ``lab`` (what the object stands on)."""
    outer, inner = (cv2.dilate(mask.astype(np.uint8), cv2.getStructuringElement(cv2.MORPH_ELLIPSE, (n, n))) > 0
                    for n in (21, 7))
    ring = outer & ~inner
    return np.median(lab[ring], axis=0) if ring.any() else np.full(3, np.inf)
