"""A height map of the scene: height above the table on a grid in the planning frame.

The planner sees the object as a 2-D outline; a hand descending onto it is 3-D. The height map is
what a descent check and a grasp height are judged against: for every cell of a regular grid in
the planning frame (the frame of :class:`~contourgrasp.perception.MetricContour`'s ``contour_xy``,
so that a planned pose (x, y, yaw) and a cell line up), the height above the table of the highest
surface the depth camera saw in that cell's column along the approach axis.

Frame and heights
-----------------
A cell is a column along the planning z axis, the hand's approach direction (the table's normal
for a tilted camera, the optical axis for a top-down one). Each valid depth pixel's point is put
in planning coordinates (x, y, z) and falls in the cell of its (x, y). Its height is its distance
above the table plane along the table's normal, toward the camera (:meth:`Plane.height`), so the
map is in the table's frame whatever the camera's tilt. Along a column, height and planning z
move together (the column crosses the table at the angle of at most the 2 deg that
:data:`~contourgrasp.tolerances.TILT_PLANE_THRESHOLD` lets the two axes differ by), so "a point of
the hand is below the map" is ``hand height < heights[cell]`` with the hand's height from
:meth:`HeightMap.height_of`.

Why the maximum per cell
------------------------
A hand descending along the approach axis must stay above *every* surface point of a column, not
above their mean: a cell that holds a rim and the table beside it is blocked at the rim's height.
The maximum is the conservative choice; it also keeps a flying pixel between an object's edge and
the table (a depth reading half-way between the two), which errs toward caution. Sensor noise
biases it up, by the largest of a cell's few noisy readings; ``max_height`` avoids that bias (see
:class:`HeightMap`).

The table at its plane
----------------------
A seen cell that is neither the object's nor an obstacle (standing less than ``MIN_HEIGHT`` above the
table) is the table itself and reads at most 0. The support plane is fitted to thousands of points
and known to about a millimetre, while a table cell's highest reading is its noise's extreme (on
the Lego brick's simulated frame the table cells' 90th percentile is 2.9 mm and their 99th 4.6 mm): kept, it
held the descent check's open hand that much above the table it asked for, and a fingertip meant
to pass just above the table passed 2-4 mm higher, over the edge of a flat object it was to close
on. The segmentation calls nothing lower than ``MIN_HEIGHT`` raised either; readings below the
plane keep their height.

A spike of noise is no obstacle: a cell stands up (``MIN_HEIGHT`` or more) only within
``STEADY_REACH_CELLS`` of a cell where a reading's 3 x 3 median stands up too
(:func:`~contourgrasp.perception.camera.denoised_depth`). A structured-light camera's noise, 2.5 mm
at 0.65 m, puts a few of a bin's hundred thousand table readings 1 cm up; read as walls they
blocked the fingers' way to an object beside them (the bin bench under ``structured-light``, 53 ->
67 of 123). An object's edge keeps its highest raw readings: its cells lie next to steady ones.

Unseen cells
------------
A cell that no valid reading falls in is NaN, not 0: it is unknown, not table. Single empty cells
between seen ones (where the pixels' spacing on a far or oblique surface exceeds a cell) are filled
with the largest of their seen neighbours; what stays NaN is the occlusion shadow behind a tall
object (on its side away from the camera), holes of missing readings (speckle, a projector's
shadow, a sensor's dropouts beside edges), and cells outside the camera's view. The descent check
must not take them as free space, nor as the tallest possible wall. :meth:`HeightMap.conservative`
bounds them by what the camera's rays show, from both sides along the line through the camera's
foot: toward the camera, the line of sight over the seen cells on the way (a surface higher would
have been seen over them); away from it, the rays that reached seen cells beyond (they passed over
the cell). Behind a tall object both are the line of sight over its rim; across a hole in the
table, about the table near either edge. A hole that no seen surface can have hidden (the line of
sight over every seen cell toward the camera passes below the table: a dropout beside an edge,
speckle) is bounded, within ``HOLE_BORDER_REACH`` (6 mm) of seen cells, by the highest of them: a
dropout band beside a 5 cm box is no higher than the box, whatever else stands in view (a robot's
arm raised every such band to its own height, and the bench with the arm in view lost 18 of 410
trials to it). Deeper inside such a hole, and where no bound reaches (a hole at the view's far
edge), the bound is the map's largest seen height; outside the camera's view +inf (a pose whose
hand passes there is not checkable and is refused).

For the descent check
---------------------
Sample each finger's capsules and the palm at the grasp depth in planning coordinates (the
hand's pose turned and placed as :func:`contourgrasp.pipeline.hand_pose` does), look up the cells
under them (:meth:`HeightMap.cell_index`, or :meth:`HeightMap.at` on :meth:`HeightMap.conservative`
for the bounded layer), and compare the body's lowest height there (:meth:`HeightMap.height_of`
minus the capsule's radius) with the cell's: a body below the map on the way down strikes.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import cv2
import numpy as np

from .. import validation
from ..errors import PerceptionError
from ..tolerances import (HEIGHT_MAP_CELL, HEIGHT_MAP_MARGIN, HEIGHT_MAP_OBJECT_BAND, MAX_HEIGHT_MAP_CELL, MAX_HEIGHT_MAP_CELLS,
                          HOLE_BORDER_REACH, MAX_HEIGHT_MAP_MARGIN, MIN_HEIGHT, SENSOR_RANGE, STEADY_REACH_CELLS)
from ._pixels import dilate
from ._ray_kernels import ray_bounds, shadow_bounds
from .camera import Intrinsics, as_depth, check_intrinsics, denoised_at, denoised_depth, pixel_points_at, valid_depth
from .metric import MetricContour
from .table import Plane, heights as plane_heights


@dataclass(frozen=True, eq=False)
class HeightMap:
    """Heights above the table on a regular grid in the planning frame.

    Cell ``[i, j]`` (row i along planning y, column j along planning x) covers
    ``x in [origin[0] + j cell, origin[0] + (j + 1) cell)`` and
    ``y in [origin[1] + i cell, origin[1] + (i + 1) cell)``: drawn with
    ``imshow(heights, extent=(x_min, x_max, y_max, y_min))`` and y pointing
    down, it looks as the camera sees it.

    Attributes
    ----------
    heights : (ny, nx) float
        Height above the table of the highest point seen in each cell's column, m; NaN where
        unseen (see the module's docstring, and :meth:`conservative`); at most 0 on the table's own
        cells (neither ``object`` nor ``obstacles``: the module's docstring, "The table at its plane").
    cell : float
        Side of a cell, m.
    origin : (2,) float
        Planning-frame (x, y) of the grid's corner: the low-x, low-y edge of cell ``[0, 0]``, m.
    object : (ny, nx) bool
        The target object's cells: inside its planning-frame contour (the outline the planner
        closes on), or holding a point of a mask pixel standing at least ``MIN_HEIGHT`` above
        the table, and the cells standing that high within ``HEIGHT_MAP_OBJECT_BAND`` (6 mm) of
        those (the band the mask's edge misses).
    obstacles : (ny, nx) bool
        Every other cell standing at least ``MIN_HEIGHT`` (10 mm, the segmentation's threshold)
        above the table: clutter, a bin's wall (today's scenes have none but the sensor's noise).
    max_height : float
        Height of the object's highest point, m: the largest height of the readings falling in
        object cells after a 3 x 3 median filter of the depth (:func:`denoised_depth`, as for the
        approach depth), since the largest raw reading is the sensor noise's extreme; NaN if no
        reading falls in an object cell. The cells themselves keep the raw maximum.
    in_view : (ny, nx) bool
        Cells whose column meets the table inside the camera's image.
    table_normal : (3,) float
        The table's unit normal (toward the camera) in planning coordinates.
    table_offset : float
        With ``table_normal``: the height of a planning-frame point q is ``table_normal @ q + table_offset``.
    camera_xy : (2,) float
        Planning-frame (x, y) of the camera's optical centre: its foot on the grid.
    camera_height : float
        The camera's height above the table, m.
    """

    heights: np.ndarray
    cell: float
    origin: np.ndarray
    object: np.ndarray
    obstacles: np.ndarray
    max_height: float
    in_view: np.ndarray
    table_normal: np.ndarray
    table_offset: float
    camera_xy: np.ndarray
    camera_height: float

    @property
    def shape(self) -> tuple[int, int]:
        """(ny, nx): rows along planning y, columns along planning x."""
        return self.heights.shape

    @property
    def extent(self) -> tuple[float, float, float, float]:
        """(x_min, x_max, y_min, y_max) of the grid in the planning frame, m."""
        ny, nx = self.shape
        x0, y0 = (float(v) for v in self.origin)
        return (x0, x0 + nx * self.cell, y0, y0 + ny * self.cell)

    @property
    def seen(self) -> np.ndarray:
        """(ny, nx) bool: cells holding a height."""
        return np.isfinite(self.heights)

    @property
    def obstacle_max_height(self) -> float:
        """The highest obstacle cell, m; 0.0 when there is none."""
        return float(self.heights[self.obstacles].max()) if self.obstacles.any() else 0.0

    def centres(self) -> tuple[np.ndarray, np.ndarray]:
        """(nx,) x and (ny,) y planning-frame coordinates of the cells' centres, m."""
        ny, nx = self.shape
        return (self.origin[0] + (np.arange(nx) + 0.5) * self.cell,
                self.origin[1] + (np.arange(ny) + 0.5) * self.cell)

    def cell_index(self, xy) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Cells of planning-frame points.

        Parameters
        ----------
        xy : (n, 2) float
            Planning-frame (x, y), m.

        Returns
        -------
        rows, cols : (n,) int
            The cell of each point (clipped to the grid).
        inside : (n,) bool
            The point lies on the grid.
        """
        xy = np.asarray(xy, dtype=float).reshape(-1, 2)
        with np.errstate(invalid="ignore"):
            index = np.floor((xy - self.origin) / self.cell)
        ny, nx = self.shape
        inside = (index[:, 0] >= 0) & (index[:, 0] < nx) & (index[:, 1] >= 0) & (index[:, 1] < ny)
        index = np.nan_to_num(index)
        cols = np.clip(index[:, 0], 0, nx - 1).astype(np.intp)
        rows = np.clip(index[:, 1], 0, ny - 1).astype(np.intp)
        return rows, cols, inside

    def at(self, xy, heights=None) -> np.ndarray:
        """(n,) float: the map's height at planning-frame points (n, 2); NaN off the grid.

        ``heights`` (ny, nx) reads another layer of the same grid instead, e.g. :meth:`conservative`.
        """
        rows, cols, inside = self.cell_index(xy)
        layer = self.heights if heights is None else heights
        return np.where(inside, layer[rows, cols], np.nan)

    def height_of(self, points) -> np.ndarray:
        """(n,) float: heights above the table of planning-frame points (n, 3), m (e.g. a hand's, at a depth z)."""
        return np.asarray(points, dtype=float).reshape(-1, 3) @ self.table_normal + self.table_offset

    def conservative(self) -> np.ndarray:
        """(ny, nx) float: the heights with every unseen cell replaced by an upper bound of its true height.

        With r the cell's distance from the camera's foot, H the camera's height and h a seen
        cell's height at distance s along the line through the foot, the smaller of:

        * toward the camera, the highest line of sight over the seen cells on the way,
          h - (H - h) s / (r - s): a surface above it would have been seen (at least 0; where no seen
          cell can hide the cell, the highest seen height within ``HOLE_BORDER_REACH`` of it, or
          farther inside the hole the map's highest seen height);
        * away from the camera, the lowest ray that reached a seen cell beyond,
          h + (H - h) s / (r + s): it passed over the cell.

        Either takes the two points a cell's diagonal toward its own side, since either may lie
        anywhere in its cell. The first assumes a hole is a shadow, speckle or a dropout beside an
        edge -- a surface that would return a reading where seen; the second holds for any hole,
        and is what bounds one wider than the first can reach. A cell outside the camera's view
        takes +inf.

        Returns
        -------
        (ny, nx) float
            No NaN; +inf outside the view. Computed once per map and read-only.
        """
        cached = self.__dict__.get("_conservative_layer")  # not "_conservative": that is the method computing it
        if cached is None:
            cached = self._conservative()
            cached.flags.writeable = False
            object.__setattr__(self, "_conservative_layer", cached)
        return cached

    def _conservative(self) -> np.ndarray:
        out = self.heights.copy()
        seen = self.seen
        if seen.all():
            return out
        top = float(out[seen].max()) if seen.any() else 0.0
        out[~seen & ~self.in_view] = np.inf
        rows, cols = np.nonzero(~seen & self.in_view)
        if not len(rows) or not seen.any():
            out[rows, cols] = top
            return out
        xs, ys = self.centres()
        start = np.c_[xs[cols], ys[rows]]
        toward = self.camera_xy - start
        r = np.hypot(toward[:, 0], toward[:, 1])
        unit = toward / np.maximum(r, 1e-12)[:, None]
        diagonal, origin, cell, height = math.sqrt(2.0) * self.cell, np.asarray(self.origin, dtype=float), \
            float(self.cell), float(self.camera_height)
        # Toward the camera: beyond s = top r / H (and the cells' diagonals) no seen height can hide the cell.
        reach = np.minimum(r, max(top, 0.0) * r / height + 2 * diagonal)
        span = min(float(np.hypot(*self.shape)) * self.cell, float(reach.max()))
        steps = np.arange(1, int(math.ceil(2 * span / self.cell)) + 1) * (0.5 * self.cell)  # half cells: no cell skipped
        across = np.arange(1, int(math.ceil(2 * np.hypot(*self.shape))) + 1) * (0.5 * self.cell)
        rays = np.maximum(ray_bounds(self.heights, start, -unit, r, across, origin, cell, height, diagonal,
                                     float(out[seen].min())), 0.0)
        shadow = shadow_bounds(self.heights, start, unit, r, reach, steps, origin, cell, height, diagonal, top, rays)
        shadow = np.where(shadow > -MIN_HEIGHT, np.maximum(shadow, 0.0), self._hole_tops(rows, cols, top))
        out[rows, cols] = np.minimum(shadow, rays)
        return out

    def _hole_tops(self, rows, cols, top: float) -> np.ndarray:
        """(n,) float: per unseen cell (rows, cols), the highest seen height within ``HOLE_BORDER_REACH`` of it;
        ``top`` for a cell farther from every seen cell (the inside of a wide hole)."""
        reach = max(int(math.ceil(HOLE_BORDER_REACH / self.cell - 1e-9)), 1)
        seen = np.where(self.seen, self.heights, -np.inf).astype(np.float32)
        near = cv2.dilate(seen, cv2.getStructuringElement(cv2.MORPH_ELLIPSE, (2 * reach + 1, 2 * reach + 1)),
                          borderType=cv2.BORDER_REPLICATE)[rows, cols].astype(float)
        return np.where(np.isfinite(near), near, top)


def height_map(
    depth,
    intrinsics: Intrinsics,
    plane: Plane,
    metric: MetricContour,
    mask,
    *,
    cell: float = HEIGHT_MAP_CELL,
    margin: float = HEIGHT_MAP_MARGIN,
    depth_range=SENSOR_RANGE,
) -> HeightMap:
    """The height map around the object: the highest point seen above the table per cell of the planning frame.

    Every valid depth pixel is back-projected, expressed in ``metric``'s planning frame (x, y)
    and given its height above ``plane`` along the table's normal; each cell of a grid covering
    the contour's bounding box grown by ``margin`` keeps the largest height falling in it
    (why the largest, and what unseen cells mean: the module's docstring).

    Parameters
    ----------
    depth : (H, W) or (H, W, 1) float
        Depth in meters (0 or NaN where missing), as the metric contour was computed on.
    intrinsics : Intrinsics
        Of the depth image.
    plane : Plane
        The table (e.g. ``Segmentation.plane``, or :func:`fit_table_plane`).
    metric : MetricContour
        The object's contour and its planning frame (:func:`contour_to_metric`).
    mask : (H, W) bool
        The object's pixels (``Segmentation.mask``: the region seen, or its footprint).
    cell : float
        Side of a cell, m, in (0, ``MAX_HEIGHT_MAP_CELL``].
    margin : float
        How far the grid reaches beyond the contour on every side, m, in [0, ``MAX_HEIGHT_MAP_MARGIN``];
        at least the hand's reach, so that every cell a planned hand passes over is on it.
    depth_range : (float, float)
        Valid readings, m.

    Returns
    -------
    HeightMap

    Raises
    ------
    PerceptionError
        Mismatched shapes, a depth image without a valid reading, a cell or margin out of
        bounds, or a grid of more than ``MAX_HEIGHT_MAP_CELLS`` cells.

    Examples
    --------
    >>> import numpy as np
    >>> from contourgrasp.perception import Intrinsics, Plane, contour_to_metric
    >>> camera = Intrinsics(fx=500.0, fy=500.0, cx=99.5, cy=99.5, width=200, height=200)
    >>> depth = np.full((200, 200), 0.5)                      # a table 0.5 m below a top-down camera
    >>> depth[80:120, 80:120] = 0.45                          # a box 5 cm high on it
    >>> mask = depth < 0.49
    >>> table = Plane(normal=np.array([0.0, 0.0, -1.0]), offset=0.5)
    >>> box = [(79.5, 79.5), (120.5, 79.5), (120.5, 120.5), (79.5, 120.5)]
    >>> metric = contour_to_metric(box, depth, camera, plane=table)
    >>> hm = height_map(depth, camera, table, metric, mask, margin=0.05)
    >>> round(hm.max_height, 4), round(float(np.nanmin(hm.heights)), 4)
    (0.05, 0.0)
    """
    d = as_depth(depth)
    check_intrinsics(intrinsics).check_shape(d.shape, "depth image")
    if not isinstance(plane, Plane):
        raise PerceptionError(f"plane must be a contourgrasp.perception.Plane, got {type(plane).__name__}")
    if not isinstance(metric, MetricContour):
        raise PerceptionError(f"metric must be a contourgrasp.perception.MetricContour, got {type(metric).__name__}")
    m = np.asarray(mask)
    validation.same_size(m.shape, d.shape, "mask", "depth image", error=PerceptionError)
    if m.ndim != 2 or not (m.dtype == bool or np.issubdtype(m.dtype, np.number)):
        raise PerceptionError(f"mask must be an (H, W) array of booleans, got shape {m.shape} of {m.dtype}")
    m = m.astype(bool)
    cell = validation.bounded("cell", cell, MAX_HEIGHT_MAP_CELL, " m", strict=True, error=PerceptionError)
    margin = validation.bounded("margin", margin, MAX_HEIGHT_MAP_MARGIN, " m", error=PerceptionError)
    valid = valid_depth(d, depth_range)
    if not valid.any():
        lo, hi = validation.depth_range("depth_range", depth_range, error=PerceptionError)
        raise PerceptionError(f"depth image has no valid reading for a height map: all are 0, NaN or outside [{lo}, {hi}] m")

    lo_xy = metric.contour_xy.min(axis=0) - margin
    size = (metric.contour_xy.max(axis=0) + margin - lo_xy) / cell
    if float(np.prod(np.ceil(size))) > MAX_HEIGHT_MAP_CELLS:
        raise PerceptionError(
            f"cell {cell:g} m makes a height map of {size[0]:.3g} x {size[1]:.3g} cells, more than "
            f"MAX_HEIGHT_MAP_CELLS = {MAX_HEIGHT_MAP_CELLS:,} (contourgrasp.tolerances): use a larger cell or a smaller margin"
        )
    nx, ny = (max(int(math.ceil(v)), 1) for v in size)

    # Cell coordinates of every pixel's point, separably: planning q = z (r @ R) - origin @ R with
    # r = ((u - cx) / fx, (v - cy) / fy, 1), a column term plus a row term per axis. float32 is
    # exact to 1e-5 of a cell here and halves the work on the image's 10^5-10^6 pixels.
    R, o = metric.R_camera_plane, metric.origin
    u = (np.arange(intrinsics.width) - intrinsics.cx) / intrinsics.fx
    v = (np.arange(intrinsics.height) - intrinsics.cy) / intrinsics.fy
    o_plane = o @ R
    with np.errstate(invalid="ignore"):
        z = np.where(valid, d, np.nan).astype(np.float32)
        index = []
        for k, n in enumerate((nx, ny)):
            across = ((u * R[0, k] + R[2, k]) / cell).astype(np.float32)
            down = ((v * R[1, k]) / cell).astype(np.float32)
            q = z * (across[None, :] + down[:, None])
            q -= np.float32((lo_xy[k] + o_plane[k]) / cell)
            index.append(np.floor(q, out=q))
        col_i, row_i = index
        on_grid = (col_i >= 0) & (col_i < nx) & (row_i >= 0) & (row_i < ny)
    flat = (row_i[on_grid] * nx + col_i[on_grid]).astype(np.intp)
    h = plane_heights(d, intrinsics, plane)[on_grid]

    grid = np.full(nx * ny, -np.inf)
    np.maximum.at(grid, flat, h)
    obj = np.zeros(nx * ny, dtype=bool)
    obj[flat[m[on_grid] & (h >= MIN_HEIGHT)]] = True
    steady = np.zeros(nx * ny, dtype=bool)
    steady[flat[plane_heights(denoised_depth(d, valid), intrinsics, plane)[on_grid] >= MIN_HEIGHT]] = True
    grid[np.isneginf(grid)] = np.nan
    grid = _fill_gaps(grid.reshape(ny, nx))
    obj = obj.reshape(ny, nx) | _inside(metric.contour_xy, lo_xy, cell, (ny, nx))
    seen = np.isfinite(grid)
    with np.errstate(invalid="ignore"):  # a spike of noise is no obstacle (module docstring)
        raised = seen & (grid >= MIN_HEIGHT) & dilate(steady.reshape(ny, nx), STEADY_REACH_CELLS)
    obj |= raised & dilate(obj, int(math.ceil(HEIGHT_MAP_OBJECT_BAND / cell - 1e-9)))
    grid = np.where(seen & ~raised & ~obj, np.minimum(grid, 0.0), grid)  # the table at its plane (module docstring)

    table_normal = R.T @ plane.normal
    table_offset = float(plane.normal @ o + plane.offset)
    return HeightMap(
        heights=grid,
        cell=cell,
        origin=lo_xy,
        object=obj,
        obstacles=raised & ~obj,
        max_height=_object_top(d, valid, intrinsics, plane, on_grid, obj.ravel()[flat]),
        in_view=_in_view(intrinsics, R, o, table_normal, table_offset, lo_xy, cell, (ny, nx)),
        table_normal=table_normal,
        table_offset=table_offset,
        camera_xy=-o_plane[:2],
        camera_height=float(plane.offset),
    )


def _object_top(depth, valid, intrinsics, plane, on_grid, picked):
    """Height (m) of the object's highest point: the pixels falling in object cells, on the 3 x 3 median-filtered depth.

    ``picked`` says, for each pixel of ``on_grid`` (in its order), whether its cell is the
    object's. The cells keep the largest raw reading (the descent's conservative choice), but
    the largest of the object's thousands of raw readings is the noise's extreme, several
    standard deviations above the surface; the filter (:func:`denoised_depth`, as for the
    approach depth) removes it. NaN when no pixel falls in an object cell.
    """
    if not picked.any():
        return math.nan
    pixels = np.zeros(on_grid.shape, dtype=bool)
    pixels[on_grid] = picked
    rows, cols = np.nonzero(pixels)
    points = pixel_points_at(denoised_at(depth, valid, rows, cols), intrinsics, rows, cols)
    return float(plane.height(points).max())


def _fill_gaps(grid):
    """``grid`` with each NaN cell between two seen ones (left and right, or above and below) set to its seen neighbours' max.

    Where the pixels' spacing on the surface exceeds a cell, single cells between readings get
    none; a shadow or a hole is wider than one cell and has seen cells on one side only.
    """
    missing = np.isnan(grid)
    if not missing.any() or missing.all():
        return grid
    padded = np.pad(grid, 1, constant_values=np.nan)
    rows, cols = np.nonzero(missing)
    rows, cols = rows + 1, cols + 1
    seen = np.isfinite
    between = ((seen(padded[rows, cols - 1]) & seen(padded[rows, cols + 1]))
               | (seen(padded[rows - 1, cols]) & seen(padded[rows + 1, cols])))
    if between.any():
        rows, cols = rows[between], cols[between]
        around = np.stack([padded[rows + di, cols + dj] for di in (-1, 0, 1) for dj in (-1, 0, 1) if di or dj])
        grid = grid.copy()
        grid[rows - 1, cols - 1] = np.nanmax(around, axis=0)
    return grid


def _inside(contour_xy, lo_xy, cell, shape):
    """(ny, nx) bool: the cells whose centre lies within the planning-frame polygon ``contour_xy``."""
    fixed = 16  # OpenCV's sub-pixel vertices: 4 fractional bits
    vertices = np.round(((np.asarray(contour_xy) - lo_xy) / cell - 0.5) * fixed).astype(np.int32)
    inside = np.zeros(shape, dtype=np.uint8)
    cv2.fillPoly(inside, [vertices], 1, lineType=cv2.LINE_8, shift=4)
    return inside.astype(bool)


def _in_view(intrinsics, R, origin, table_normal, table_offset, lo_xy, cell, shape):
    """(ny, nx) bool: cells whose centre's column meets the table at a point inside the image."""
    ny, nx = shape
    x = lo_xy[0] + (np.arange(nx) + 0.5) * cell
    y = lo_xy[1] + (np.arange(ny) + 0.5) * cell
    # On the table: table_normal . (x, y, z) + table_offset = 0.
    zt = -(table_offset + table_normal[0] * x[None, :] + table_normal[1] * y[:, None]) / table_normal[2]
    p = [origin[k] + R[k, 0] * x[None, :] + R[k, 1] * y[:, None] + R[k, 2] * zt for k in range(3)]
    with np.errstate(divide="ignore", invalid="ignore"):
        pu = intrinsics.fx * p[0] / p[2] + intrinsics.cx
        pv = intrinsics.fy * p[1] / p[2] + intrinsics.cy
        return ((p[2] > 0) & (pu >= -0.5) & (pu <= intrinsics.width - 0.5)
                & (pv >= -0.5) & (pv <= intrinsics.height - 0.5))
