"""A memory of failed grasps: the next plan of the same object avoids them, in the object's frame.

A grasp that failed is kept as its hand pose (x, y, yaw) in the object's frame (:func:`object_frame`):
the outline's centroid, and its principal axis -- the outline's second moments of area. The object
may have moved or turned since (a grasp that pushed it); a later plan maps every failure into the
object's frame as it is then seen, and excludes the poses within ``tolerances.MEMORY_REACH`` (m) and
``tolerances.MEMORY_TURN`` (rad) of one. An axis has no sign, so a failure is mapped both ways round
it; an outline whose axes differ by less than ``tolerances.MEMORY_ROUND`` (a can seen from above, a
ball) has no axis that turns with it, and its frame keeps the planning frame's orientation.

:func:`contourgrasp.pipeline.plan_frame` takes a :class:`GraspMemory` (``memory=``), which
:func:`~contourgrasp.synthesis.search` applies to its screened poses (``exclude=``).

A scene of several objects, seen by a camera that stays put (a lab's table, a bin), keeps one memory per object:
:class:`SceneMemory` finds an object's memory again by where the object is seen, the pixel deepest inside it at
its last failure lying within ``tolerances.MEMORY_SAME_OBJECT_PX`` of the pixels that see it now, so that a
failure on one object excludes nothing on its neighbour. ``plan_frame`` takes either.

A grasp approached from the side or tilted (:mod:`contourgrasp.perception.view_along`) is kept as its
kind of approach and its direction: the next plan tries the kinds that failed fewer times first
(:func:`contourgrasp.pipeline.approach_order`), and of a kind, no direction within
``tolerances.MEMORY_TURN`` of one that failed, in the object's frame (its azimuth relative to the principal
axis, mapped both ways round it as a pose is). Its pose is not kept: the approach frame is the object's as
seen along that approach, so the same direction seen again plans the same grasp.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import cv2
import numpy as np

from .. import validation
from ..errors import PlannerError
from ..perception import deepest_pixel
from ..perception.view_along import APPROACH_KINDS, Approach
from ..tolerances import (MAX_MEMORY_FAILURES, MAX_MEMORY_OBJECTS, MEMORY_REACH, MEMORY_ROUND, MEMORY_SAME_OBJECT_PX,
                          MEMORY_TURN)


@dataclass(frozen=True)
class GraspMemory:
    """The failed grasps of one object in the object's frame (module docstring): a top-down one as its pose
    (x, y, yaw) in ``failures``, a side or tilted one as its kind and azimuth (rad; NaN: not known) in
    ``directions``; ``kinds`` every failure's kind, oldest first.

    Immutable: :meth:`with_failure` returns a new memory. At most ``tolerances.MAX_MEMORY_FAILURES``
    are kept, the oldest dropped first.

    Examples
    --------
    >>> square = np.array([[0.0, 0.0], [0.04, 0.0], [0.04, 0.02], [0.0, 0.02]])
    >>> memory = GraspMemory().with_failure(square, (0.02, 0.05, 0.0))
    >>> moved = square + [0.1, 0.0]  # the object pushed 10 cm along x
    >>> memory.excluded(moved, [[0.12, 0.05, 0.0], [0.02, 0.05, 0.0]]).tolist()
    [True, False]
    """

    failures: tuple[tuple[float, float, float], ...] = ()
    kinds: tuple[str, ...] = ()
    directions: tuple[tuple[str, float], ...] = ()

    def __len__(self) -> int:
        return len(self.kinds)

    def with_failure(self, contour_xy, pose, *, approach: str | Approach = "top") -> GraspMemory:
        """This memory and the failed grasp ``pose`` (x, y, yaw) planned on the outline ``contour_xy`` ((n, 2) m),
        approached as ``approach`` says: the plan's :class:`~contourgrasp.perception.Approach` (a side or tilted one's
        direction is kept), or its kind, "top", "side" or "tilted" (of the latter two only the kind is kept)."""
        x, y, yaw = validation.finite_array("pose", pose, (3,), error=PlannerError)
        kind = approach.kind if isinstance(approach, Approach) else validation.choice(
            "approach", approach, APPROACH_KINDS, error=PlannerError)
        kinds, failures, directions = (*self.kinds, kind)[-MAX_MEMORY_FAILURES:], self.failures, self.directions
        centre, angle = object_frame(contour_xy)
        if kind == "top":
            local = _rotation(-angle) @ (np.array([x, y]) - centre)
            failures = (*failures, (float(local[0]), float(local[1]), float(_wrapped(yaw - angle))))
        else:
            azimuth = float(_wrapped(approach.azimuth - angle)) if isinstance(approach, Approach) else math.nan
            directions = (*directions, (kind, azimuth))
        others = len(kinds) - kinds.count("top")  # the failures of each sort still kept
        return GraspMemory(failures[len(failures) - kinds.count("top"):], kinds, directions[len(directions) - others:])

    def failures_by_kind(self) -> dict[str, int]:
        """How many grasps failed per kind of approach."""
        return {kind: self.kinds.count(kind) for kind in dict.fromkeys(self.kinds)}

    def excluded(self, contour_xy, poses) -> np.ndarray:
        """(n,) bool: the poses (n, 3) near a failure, the failures mapped onto the outline ``contour_xy`` ((m, 2) m)."""
        poses = validation.finite_array("poses", poses, (None, 3), error=PlannerError)
        out = np.zeros(len(poses), dtype=bool)
        if not self.failures:
            return out
        centre, angle = object_frame(contour_xy)
        for turn in (angle, angle + np.pi):  # the axis has no sign
            local = np.asarray(self.failures)
            xy = local[:, :2] @ _rotation(turn).T + centre
            yaw = local[:, 2] + turn
            near = np.linalg.norm(poses[:, None, :2] - xy[None], axis=-1) <= MEMORY_REACH
            near &= np.abs(_wrapped(poses[:, None, 2] - yaw[None])) <= MEMORY_TURN
            out |= near.any(axis=1)
        return out

    def avoids(self, contour_xy, approach: Approach) -> bool:
        """Whether a grasp failed along ``approach`` (side or tilted) or within ``MEMORY_TURN`` of it, the failed
        directions mapped onto the outline ``contour_xy`` ((m, 2) m) as it is seen now (module docstring)."""
        failed = [azimuth for kind, azimuth in self.directions if kind == approach.kind and math.isfinite(azimuth)]
        if not failed:
            return False
        _, angle = object_frame(contour_xy)
        turns = np.add.outer(np.asarray(failed), [angle, angle + np.pi])  # the axis has no sign
        return bool((np.abs(_wrapped(approach.azimuth - turns)) <= MEMORY_TURN).any())


@dataclass(frozen=True)
class SceneMemory:
    """The failed grasps of the objects of one scene, seen by a camera that stays put: each object's own
    :class:`GraspMemory`, found again by where the object is seen (module docstring).

    ``objects`` holds per object the pixel (u, v) deepest inside it as seen at its last failure and its memory,
    the one that failed longest ago first; at most ``tolerances.MAX_MEMORY_OBJECTS``. Immutable.

    Examples
    --------
    >>> left, right = np.zeros((40, 60), bool), np.zeros((40, 60), bool)
    >>> left[10:30, 5:25] = right[10:30, 35:55] = True
    >>> square = np.array([[0.0, 0.0], [0.04, 0.0], [0.04, 0.02], [0.0, 0.02]])
    >>> memory = SceneMemory().with_failure(left, square, (0.02, 0.05, 0.0))
    >>> len(memory.of(left)), len(memory.of(right))
    (1, 0)
    """

    objects: tuple[tuple[tuple[int, int], GraspMemory], ...] = ()

    def __len__(self) -> int:
        """The failures remembered, on every object."""
        return sum(len(memory) for _, memory in self.objects)

    def of(self, seen) -> GraspMemory:
        """The memory of the object whose pixels are ``seen`` ((H, W) bool); empty when no failure lies on it."""
        near = _near(validation.pixel_mask("seen", seen, error=PlannerError), self.objects)
        return next((memory for (_, memory), on in zip(reversed(self.objects), near[::-1]) if on), GraspMemory())

    def with_failure(self, seen, contour_xy, pose, *, approach: str | Approach = "top") -> SceneMemory:
        """This memory and a failed grasp on the object whose pixels are ``seen`` ((H, W) bool, the plan's
        ``seen``), added to that object's memory (:meth:`GraspMemory.with_failure`, the other arguments)."""
        seen = validation.pixel_mask("seen", seen, error=PlannerError)
        near = _near(seen, self.objects)
        same = [memory for (_, memory), on in zip(self.objects, near) if on]
        memory = (same[-1] if same else GraspMemory()).with_failure(contour_xy, pose, approach=approach)
        others = tuple(entry for entry, on in zip(self.objects, near) if not on)
        return SceneMemory((*others, (deepest_pixel(seen), memory))[-MAX_MEMORY_OBJECTS:])

    def without(self, seen) -> SceneMemory:
        """This memory without the object whose pixels are ``seen`` ((H, W) bool): it was taken away."""
        near = _near(validation.pixel_mask("seen", seen, error=PlannerError), self.objects)
        return SceneMemory(tuple(entry for entry, on in zip(self.objects, near) if not on))


def _near(seen, objects) -> list[bool]:
    """Per object of a :class:`SceneMemory`, whether its pixel lies within ``MEMORY_SAME_OBJECT_PX`` of the pixels
    ``seen``: the same object, moved a little by the grasp that failed."""
    grown = cv2.dilate(seen.astype(np.uint8), cv2.getStructuringElement(
        cv2.MORPH_ELLIPSE, (2 * MEMORY_SAME_OBJECT_PX + 1,) * 2)) > 0
    height, width = grown.shape
    return [0 <= v < height and 0 <= u < width and bool(grown[v, u]) for (u, v), _ in objects]


def object_frame(contour_xy) -> tuple[np.ndarray, float]:
    """The object's frame in the planning plane: its outline's centroid ((2,) m) and principal axis's angle (rad).

    The axis is that of the outline's largest second moment of area; 0 for an outline whose two
    moments differ by less than ``tolerances.MEMORY_ROUND`` of the larger (round: no axis turns with it).
    """
    contour = validation.finite_array("contour_xy", contour_xy, (None, 2), error=PlannerError)
    if len(contour) < 3:
        raise PlannerError(f"contour_xy needs at least 3 points, got {len(contour)}")
    moments = cv2.moments(contour.astype(np.float32))
    if moments["m00"] == 0:
        raise PlannerError("contour_xy encloses no area")
    centre = np.array([moments["m10"], moments["m01"]]) / moments["m00"]
    a, b, c = moments["mu20"], moments["mu11"], moments["mu02"]
    spread = np.hypot(a - c, 2 * b)  # the difference of the two principal moments
    if spread < MEMORY_ROUND * 0.5 * (a + c + spread):
        return centre, 0.0
    return centre, float(0.5 * np.arctan2(2 * b, a - c))


def _rotation(angle: float) -> np.ndarray:
    c, s = np.cos(angle), np.sin(angle)
    return np.array([[c, -s], [s, c]])


def _wrapped(angle):
    """Angles wrapped into [-pi, pi)."""
    return (np.asarray(angle) + np.pi) % (2 * np.pi) - np.pi
