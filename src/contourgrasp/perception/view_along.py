"""The scene seen along an approach direction: the outline the fingers close around and the map they descend on.

The thesis's hand approaches along the camera's axis and closes around the object's outline as the
camera sees it (3.1); its outlook (6.1) asks for other viewpoints. Seen along any approach direction
the hand is the same hand: its palm plane is perpendicular to the approach and its fingers close in
that plane around the object's outline *as seen along the approach*. :func:`view_along` gives that
outline and a :class:`~contourgrasp.perception.HeightMap` in the approach's own frame, so the search,
the descent check, the grasp height and the closing sweeps run unchanged on it.

What occupies the scene
-----------------------
The camera sees each object from its side; what lies behind what it sees is bounded as the height map
bounds it: every cell of the map is a column from the table up to the cell's height (its
:meth:`~contourgrasp.perception.HeightMap.conservative` layer, so an unseen cell is as tall as the rays
allow). An object seen from above is thus filled down to the table, the bound a side approach must
respect (a mug's handle shadows the space under it). The table is the half-space below its plane.

The approach frame
------------------
z along the approach (into the scene), x along the table (``approach × normal``), y completing a right-handed
frame (down the table's normal for a side approach, as a camera's image y). Its origin is the target's
centroid (the mean of its columns' points). "Height" in the approach frame is distance toward the hand
from the plane through that centroid perpendicular to the approach: the reference plane plays the
table's part (the open fingertips stop above it, so they close at most as deep as the object's middle),
and everything the hand meets in front of it is in the map: the target, its neighbours, and the real
table, as an obstacle wherever the approach's rays meet it in front of the reference plane (for a
horizontal approach: everywhere below the table's line, at :data:`BLOCKED` height).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from functools import cached_property

import cv2
import numpy as np

from .. import validation
from ..errors import PerceptionError
from ..tolerances import MIN_HEIGHT, VIEW_CELL, VIEW_MARGIN
from ._view_kernels import least_depths, target_extent
from .height_map import HeightMap

#: The kinds of approach (:attr:`Approach.kind`): top-down, horizontal, tilted.
APPROACH_KINDS = ("top", "side", "tilted")

#: Height (m) of an approach-frame cell the hand cannot enter at all: the real table's half-space seen along
#: a horizontal approach. Finite, so that clearances stay numbers.
BLOCKED = 1.0


@dataclass(frozen=True)
class Approach:
    """A direction the hand approaches along, in the planning frame of a height map.

    Attributes
    ----------
    elevation : float
        Angle of the approach below the table's plane, rad, in [0, pi/2]: pi/2 is top-down (along the
        table's normal, into it), 0 horizontal.
    azimuth : float
        Direction of its horizontal part, rad, from the planning frame's x axis toward its y axis
        (about the approach axis of a top-down camera).
    """

    elevation: float
    azimuth: float = 0.0

    def __post_init__(self):
        elevation = validation.finite("Approach.elevation", self.elevation, error=PerceptionError)
        azimuth = validation.finite("Approach.azimuth", self.azimuth, error=PerceptionError)
        if not 0.0 <= elevation <= math.pi / 2:
            raise PerceptionError(f"Approach.elevation must be in [0, pi/2] rad, got {elevation!r}")
        object.__setattr__(self, "elevation", elevation)
        object.__setattr__(self, "azimuth", azimuth % (2 * math.pi))

    @property
    def top_down(self) -> bool:
        return self.elevation >= math.pi / 2 - 1e-9

    def direction(self, table_normal) -> np.ndarray:
        """(3,) float: the unit approach direction in planning coordinates, ``table_normal`` pointing up."""
        n = np.asarray(table_normal, dtype=float)
        n = n / np.linalg.norm(n)
        if self.top_down:
            return -n
        along = np.array([math.cos(self.azimuth), math.sin(self.azimuth), 0.0])
        along = along - (along @ n) * n
        along /= np.linalg.norm(along)
        return math.cos(self.elevation) * along - math.sin(self.elevation) * n

    @property
    def kind(self) -> str:
        """"top" (top-down), "side" (less than 15 deg below the horizontal) or "tilted"."""
        return "top" if self.top_down else "side" if self.elevation < math.radians(15) else "tilted"

    def describe(self) -> str:
        """"top-down", or e.g. "side (elevation 0 deg, azimuth 90 deg)"."""
        if self.top_down:
            return "top-down"
        return (f"{self.kind} (elevation {math.degrees(self.elevation):.0f} deg, "
                f"azimuth {math.degrees(self.azimuth):.0f} deg)")


@dataclass(frozen=True, eq=False)
class ApproachView:
    """The scene seen along an :class:`Approach` (:func:`view_along`).

    Attributes
    ----------
    approach : Approach
    heights : HeightMap
        In the approach frame (module docstring): heights toward the hand above the reference plane
        through the target's centroid; ``object`` the target's cells, ``obstacles`` everything else the
        hand may meet (neighbours and the table) standing ``MIN_HEIGHT`` above it; no unseen cell.
    contour_xy : (n, 2) float
        The target's outline seen along the approach, approach-frame (x, y), m.
    R_plane_view : (3, 3) float
        Columns: the approach frame's x, y, z axes in the height map's planning coordinates.
    origin : (3,) float
        Planning-frame position of the approach frame's origin (the target's centroid), m.
    """

    approach: Approach
    heights: HeightMap
    contour_xy: np.ndarray
    R_plane_view: np.ndarray
    origin: np.ndarray

    def to_plane(self, points) -> np.ndarray:
        """(n, 3) float: planning-frame points of approach-frame points (n, 3)."""
        return np.asarray(points, dtype=float).reshape(-1, 3) @ self.R_plane_view.T + self.origin


def view_axes(approach: Approach, table_normal) -> np.ndarray:
    """(3, 3) float: the approach frame's x, y, z axes (columns) in planning coordinates (module docstring)."""
    d = approach.direction(table_normal)
    x = np.cross(d, np.asarray(table_normal, dtype=float))
    x /= np.linalg.norm(x)
    return np.column_stack([x, np.cross(d, x), d])


@dataclass(frozen=True, eq=False)
class Columns:
    """The scene's seen cells as columns of points from the table up (:func:`column_points`), planning frame.

    Attributes
    ----------
    points : (p, 3) float
        One point per ``VIEW_CELL`` cell sides of height, each column's top included.
    target : (p,) bool
        The point is in a cell of the target object.
    """

    points: np.ndarray
    target: np.ndarray

    @cached_property
    def centroid(self) -> np.ndarray:
        """(3,) float: the mean of the target's points, the same along every approach."""
        return self.points[self.target].mean(axis=0)


def column_points(heights: HeightMap) -> Columns:
    """Points filling every standing seen cell's column from the table to its height (:class:`Columns`).

    Only seen cells make columns: the unseen ones (the occlusion shadows behind tall objects, holes,
    cells outside the camera's view) are left out, neither target nor obstacle. Our reading: the seen
    top and near sides bound an object, so the fingers close on what was seen, and a shadow hides no
    object of its own (bounded by the line of sight as the top-down descent bounds it, a tall target's
    shadow hid its lower half from every approach on that side, and the target from some).
    """
    layer = np.nan_to_num(heights.heights, nan=0.0)
    target_cells = heights.object & heights.seen
    rows, cols = np.nonzero((target_cells | (~heights.object & (layer >= MIN_HEIGHT))) & (layer > 0))
    tops = layer[rows, cols]
    spacing = heights.cell * VIEW_CELL
    counts = np.ceil(tops / spacing).astype(int) + 1
    cell_of = np.repeat(np.arange(len(rows)), counts)
    step = np.arange(len(cell_of)) - np.repeat(np.cumsum(counts) - counts, counts)
    h = np.minimum(step * spacing, tops[cell_of])
    xs, ys = heights.centres()
    x, y = xs[cols[cell_of]], ys[rows[cell_of]]
    n, offset = np.asarray(heights.table_normal, dtype=float), float(heights.table_offset)
    z = (h - offset - n[0] * x - n[1] * y) / n[2]
    return Columns(np.column_stack([x, y, z]), target_cells[rows, cols][cell_of])


def view_along(heights: HeightMap, approach: Approach, *, points=None) -> ApproachView:
    """The target's outline and the scene's height map seen along ``approach`` (module docstring).

    Parameters
    ----------
    heights : HeightMap
        The scene in its planning frame (:func:`contourgrasp.perception.height_map`), target cells marked.
    approach : Approach
        Not top-down: the top-down view is the height map itself.
    points : Columns, optional
        :func:`column_points` of ``heights``, when several approaches share them.

    Returns
    -------
    ApproachView

    Raises
    ------
    PerceptionError
        A top-down ``approach``; no target cell in ``heights``.
    """
    if approach.top_down:
        raise PerceptionError("view_along needs an approach other than top-down: the top-down view is the map itself")
    columns = column_points(heights) if points is None else points
    if not columns.target.any():
        raise PerceptionError("the height map has no cell of the target object to view")
    n = np.asarray(heights.table_normal, dtype=float)
    n = n / np.linalg.norm(n)
    R = view_axes(approach, n)
    centroid = columns.centroid
    origin = centroid + target_extent(columns.points, columns.target, centroid, R)[5] * R[:, 2]  # the target's back
    x0, x1, y0, y1, z0, _ = target_extent(columns.points, columns.target, origin, R)
    cell = heights.cell * VIEW_CELL
    low, high = np.array([x0, y0]) - VIEW_MARGIN, np.array([x1, y1]) + VIEW_MARGIN
    shape = tuple((np.ceil((high - low) / cell).astype(int) + 1)[::-1])
    least, least_target = least_depths(columns.points, columns.target, origin, R, low, cell, *shape,
                                       z0 - VIEW_MARGIN)  # what stands on the hand's way, over its reach
    near, near_target = _fill_gaps(least), _fill_gaps(least_target)
    centres = [low[k] + (np.arange(shape[1 - k]) + 0.5) * cell for k in (0, 1)]
    table = _table_depth(R, origin, n, float(heights.table_offset), *centres)
    object_cells = np.isfinite(near_target) & (near_target <= np.minimum(near, table))  # the target, seen first
    if not object_cells.any():
        raise PerceptionError(f"the target is hidden by the table seen {approach.describe()}")
    in_front = np.clip(np.nan_to_num(-np.minimum(near, table), nan=0.0, posinf=BLOCKED, neginf=0.0), 0.0, BLOCKED)
    view = HeightMap(
        heights=in_front, cell=cell, origin=low.copy(), object=object_cells,
        obstacles=~object_cells & (in_front >= MIN_HEIGHT),
        max_height=float(max(-near_target[object_cells].min(), 0.0)), in_view=np.ones(shape, dtype=bool),
        table_normal=np.array([0.0, 0.0, -1.0]), table_offset=0.0, camera_xy=np.zeros(2), camera_height=BLOCKED)
    return ApproachView(approach, view, _outline(object_cells, low, cell), R, origin)


def _fill_gaps(least) -> np.ndarray:
    """``least`` (a map of :func:`~contourgrasp.perception._view_kernels.least_depths`) where an empty cell between two filled ones (left and right, or above and
    below: a gap between columns seen slantwise) takes the least of theirs."""
    padded = np.pad(least, 1, constant_values=np.inf)
    pairs = ((padded[1:-1, :-2], padded[1:-1, 2:]), (padded[:-2, 1:-1], padded[2:, 1:-1]))
    gap = np.full(least.shape, np.inf)
    for a, b in pairs:
        gap = np.where(np.isfinite(a) & np.isfinite(b), np.minimum(gap, np.minimum(a, b)), gap)
    return np.where(np.isinf(least), gap, least)


def _table_depth(R, origin, n, offset, xs, ys) -> np.ndarray:
    """(ny, nx) float: depth along the approach at which each approach-frame cell's ray meets the table
    (-inf: the ray starts inside it, +inf: never)."""
    start = origin @ n + offset + xs[None, :] * (R[:, 0] @ n) + ys[:, None] * (R[:, 1] @ n)  # height at depth 0
    fall = -(R[:, 2] @ n)  # height lost per metre along the approach
    if fall < 1e-9:
        return np.where(start < 0.0, -np.inf, np.inf)
    return start / fall


def _outline(mask, low, cell) -> np.ndarray:
    """(n, 2) float: the largest outer outline of ``mask`` through its border cells' centres, approach frame."""
    contours, _ = cv2.findContours(mask.astype(np.uint8), cv2.RETR_EXTERNAL, cv2.CHAIN_APPROX_NONE)
    if not contours:
        raise PerceptionError("the target has no outline along this approach")
    pixels = max(contours, key=cv2.contourArea)[:, 0, :].astype(float)
    return low + (pixels + 0.5) * cell
