"""The object's cross-section at a height: the outline the closing fingertips meet.

The planner's contour is the object's outline as the camera saw it, projected on one plane: for a
tall object seen from above and off the optical axis, its visible side wall is in the mask too, so
the outline is centimetres longer than the object is at any height. The fingertips close at the
grasp height. :func:`cross_section` takes the object's cells of the height map
(:class:`~contourgrasp.perception.HeightMap`) standing at least that high -- in the planning frame,
every reading at its own (x, y), whatever the perspective -- and returns their outline.

Reading of the height map: a cell's height is the highest surface seen in its column, so "the
object reaches this height here" is read as "its cross-section at this height covers the cell".
That holds for objects whose sides do not overhang (boxes, cans, fruit, a lying bottle above its
axis); under an overhang the camera cannot see the difference. Unseen cells do not count: inside
the outline as seen, they are mostly the object's own occlusion shadow on the table (the visible side
wall of a tall object, projected at its top, reaches over it), and where the section misses a hidden
edge of the object, the descent check still sees the height map's bound there.
"""

from __future__ import annotations

import cv2
import numpy as np

from .. import validation
from ..errors import PerceptionError
from ..tolerances import MAX_HAND_SIZE, MIN_SECTION_CELLS
from .height_map import HeightMap


def cross_section(heights: HeightMap, height: float) -> np.ndarray | None:
    """The outline of the object's cells standing at least ``height`` above the table, planning frame.

    Parameters
    ----------
    heights : HeightMap
    height : float
        Above the table, m, in [0, ``MAX_HAND_SIZE``].

    Returns
    -------
    (n, 2) float or None
        The largest connected region's outer boundary through its border cells' centres, m, in
        the planning frame's (x, y), in boundary order; None when fewer than
        ``tolerances.MIN_SECTION_CELLS`` object cells stand that high.

    Raises
    ------
    PerceptionError
        ``heights`` is not a HeightMap, or ``height`` is not a finite number in range.

    Examples
    --------
    A 4 cm x 2 cm box 3 cm tall: its section at 1 cm is the box.

    >>> import numpy as np
    >>> from contourgrasp.perception import HeightMap
    >>> grid = np.zeros((40, 60)); box = np.zeros((40, 60), bool); box[10:20, 10:30] = True
    >>> grid[box] = 0.03
    >>> hm = HeightMap(grid, 0.002, np.zeros(2), box, np.zeros_like(box), 0.03, np.ones_like(box),
    ...                np.array([0.0, 0.0, -1.0]), 0.5, np.zeros(2), 0.5)
    >>> outline = cross_section(hm, 0.01)
    >>> np.ptp(outline, axis=0).round(3).tolist()
    [0.038, 0.018]
    """
    if not isinstance(heights, HeightMap):
        raise PerceptionError(f"heights must be a HeightMap, got {type(heights).__name__}")
    height = validation.bounded("height", height, MAX_HAND_SIZE, " m", error=PerceptionError)
    with np.errstate(invalid="ignore"):
        covered = heights.object & (heights.heights >= height)
    count, labels, stats, _ = cv2.connectedComponentsWithStats(covered.astype(np.uint8), connectivity=8)
    if count < 2:
        return None
    largest = 1 + int(np.argmax(stats[1:, cv2.CC_STAT_AREA]))
    if stats[largest, cv2.CC_STAT_AREA] < MIN_SECTION_CELLS:
        return None
    region = (labels == largest).astype(np.uint8)
    contours, _ = cv2.findContours(region, cv2.RETR_EXTERNAL, cv2.CHAIN_APPROX_NONE)
    cells = max(contours, key=len)[:, 0, :].astype(float)  # (col, row)
    return heights.origin + (cells + 0.5) * heights.cell
