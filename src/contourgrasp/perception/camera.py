"""The camera's images: intrinsics, depth images and their points, colour images (thesis 3.1).

Conventions
-----------
Camera frame = optical frame: x right, y down, z forward, meters. A pixel is
(u, v) = (column, row), with the centre of the top-left pixel at (0, 0).
Depth is the z coordinate in meters. A depth reading is *valid* when it is
finite and inside ``depth_range``, by default the thesis sensor's range
0.2-1.5 m (section 4.1.2); 0 and NaN mark missing readings.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import cv2
import numpy as np
from scipy import ndimage

from .. import validation
from ..errors import PerceptionError
from ..tolerances import APPROACH_MEDIAN_PX, FOCAL_RANGE_PX, MAX_HOLE_PX, MAX_IMAGE_PIXELS, SENSOR_RANGE
from ._frame import memoised
from ._pixels import even_box, pixel_box, stats_in_image


@dataclass(frozen=True)
class Intrinsics:
    """Pinhole intrinsics of the depth camera (colour registered to it).

    Attributes
    ----------
    fx, fy : float
        Focal lengths in pixels.
    cx, cy : float
        Principal point in pixels, from the centre of the top-left pixel.
    width, height : int
        Image size in pixels.
    """

    fx: float
    fy: float
    cx: float
    cy: float
    width: int
    height: int

    def __post_init__(self):
        for name in ("fx", "fy", "cx", "cy"):
            value = validation.finite(f"intrinsics: {name}", getattr(self, name), error=PerceptionError)
            object.__setattr__(self, name, value)
        for name in ("width", "height"):
            value = getattr(self, name)
            real = not isinstance(value, bool) and isinstance(value, (int, float, np.integer, np.floating))
            try:
                whole = real and math.isfinite(value) and value == int(value) and value >= 1
            except OverflowError:
                whole = False
            if not whole:
                raise PerceptionError(f"intrinsics: {name} must be a positive whole number of pixels, "
                                      f"got {validation.shown(value)}")
            object.__setattr__(self, name, int(value))
        if self.width * self.height > MAX_IMAGE_PIXELS:
            raise PerceptionError(f"intrinsics: a {self.width}x{self.height} image has more than "
                                  f"{MAX_IMAGE_PIXELS:,} pixels, the most contourgrasp plans on")
        low, high = FOCAL_RANGE_PX
        for name in ("fx", "fy"):
            if not low <= getattr(self, name) <= high:
                raise PerceptionError(f"intrinsics: {name} must be a focal length in pixels in [{low:g}, {high:g}], "
                                      f"got {getattr(self, name):g}")
        for name, size in (("cx", self.width), ("cy", self.height)):
            if not -size <= getattr(self, name) <= 2 * size:
                raise PerceptionError(f"intrinsics: {name} must lie within the image or one image size beside it, "
                                      f"[{-size}, {2 * size}] px, got {getattr(self, name):g}")

    @property
    def shape(self) -> tuple[int, int]:
        """(height, width), the shape of an image taken with these intrinsics."""
        return (self.height, self.width)

    @property
    def K(self) -> np.ndarray:
        """(3, 3) float: the camera matrix."""
        return np.array([[self.fx, 0.0, self.cx], [0.0, self.fy, self.cy], [0.0, 0.0, 1.0]])

    def check_shape(self, shape, what: str) -> None:
        """Raise :class:`~contourgrasp.errors.PerceptionError` unless an image of ``shape`` fits these intrinsics."""
        if len(shape) < 2:
            raise PerceptionError(f"{what} must be an (H, W) image, got shape {tuple(shape)}")
        if tuple(shape[:2]) != self.shape:
            raise PerceptionError(
                f"{what} is {shape[1]}x{shape[0]} (width x height) but the intrinsics are for "
                f"{self.width}x{self.height}"
            )

    def rays(self, pixels) -> np.ndarray:
        """(n, 3) float: directions (x/z, y/z, 1) of the rays through (n, 2) pixels (u, v)."""
        uv = np.asarray(pixels, dtype=float).reshape(-1, 2)
        return np.c_[(uv[:, 0] - self.cx) / self.fx, (uv[:, 1] - self.cy) / self.fy, np.ones(len(uv))]

    def project(self, points_camera) -> np.ndarray:
        """(n, 2) float: pixels (u, v) of camera-frame points (n, 3); the inverse of :meth:`rays`."""
        p = np.asarray(points_camera, dtype=float).reshape(-1, 3)
        return np.c_[self.fx * p[:, 0] / p[:, 2] + self.cx, self.fy * p[:, 1] / p[:, 2] + self.cy]


def check_intrinsics(intrinsics) -> Intrinsics:
    """``intrinsics`` itself, refused unless an :class:`Intrinsics`."""
    if not isinstance(intrinsics, Intrinsics):
        raise PerceptionError(f"intrinsics must be a contourgrasp.perception.Intrinsics, got {type(intrinsics).__name__}")
    return intrinsics


def as_depth(depth) -> np.ndarray:
    """(H, W) float: a depth image, squeezing a trailing channel of 1 ((H, W, 1) as stored by gqcnn).

    A float64 image is returned as it is, not copied: nothing in perception
    writes to its depth images.
    """
    d = _array("depth image", depth)
    if d.ndim == 3 and d.shape[2] == 1:
        d = d[..., 0]
    if d.ndim != 2 or d.size == 0:
        raise PerceptionError(f"depth image must be an (H, W) array, got shape {d.shape}")
    if not (np.issubdtype(d.dtype, np.number) and not np.issubdtype(d.dtype, np.complexfloating)):
        raise PerceptionError(f"depth image must hold real numbers, got {d.dtype}")
    return d.astype(float, copy=False)


def valid_depth(depth, depth_range=SENSOR_RANGE) -> np.ndarray:
    """(H, W) bool: finite readings inside ``depth_range`` (m)."""
    d = as_depth(depth)
    lo, hi = validation.depth_range("depth_range", depth_range, error=PerceptionError)

    def valid():
        with np.errstate(invalid="ignore"):
            return np.isfinite(d) & (d >= lo) & (d <= hi)

    return memoised(d, ("valid", lo, hi), valid)


def backproject(depth, intrinsics: Intrinsics) -> np.ndarray:
    """(H, W, 3) float: camera-frame point of every pixel, NaN where the depth is not finite.

    x = (u - cx) z / fx, y = (v - cy) z / fy (the pixel-wise form of eq 3.1-3.2).
    """
    d = as_depth(depth)
    check_intrinsics(intrinsics).check_shape(d.shape, "depth image")
    return pixel_points(np.where(np.isfinite(d), d, np.nan), intrinsics, *np.indices(d.shape))


def fill_depth_holes(depth, *, max_hole_px: int = MAX_HOLE_PX) -> tuple[np.ndarray, int]:
    """Fill small holes of a depth image with the nearest reading.

    A hole is a connected (8-neighbour) region of missing readings (0, NaN,
    negative or infinite). Holes of at most ``max_hole_px`` pixels take the
    value of the nearest present reading; larger ones, such as the sensor's
    dead band or a far shadow, are left missing. Nearest-reading fill (rather
    than inpainting) invents no depth that the sensor did not measure, so a
    filled pixel is either table or object, never in between.

    Parameters
    ----------
    depth : (H, W) or (H, W, 1) float
        Depth in meters.
    max_hole_px : int
        Largest hole filled, pixels; 0 fills nothing.

    Returns
    -------
    filled : (H, W) float
        A copy with the small holes filled.
    count : int
        Number of pixels filled.
    """
    d = as_depth(depth)
    max_hole_px = validation.integer("max_hole_px", max_hole_px, 0, error=PerceptionError)
    with np.errstate(invalid="ignore"):
        missing = ~np.isfinite(d) | (d <= 0)
    if not missing.any() or missing.all() or max_hole_px == 0:
        return d.copy(), 0
    labels, stats = _holes(missing)
    small = stats[:, cv2.CC_STAT_AREA] <= max_hole_px
    small[0] = False
    if not small.any():
        return d.copy(), 0
    out = d.copy()
    for box, fill in _fill_boxes(labels, stats, small, d.shape):
        _, (rows, cols) = ndimage.distance_transform_edt(missing[box], return_indices=True)
        out[box][fill] = d[box][rows[fill], cols[fill]]
    return out, int(stats[small, cv2.CC_STAT_AREA].sum())


def _holes(missing):
    """(labels, stats) of the 8-connected regions of ``missing``, as OpenCV's on the whole image (the
    background's row aside), labelled on their :func:`~contourgrasp.perception._pixels.even_box`."""
    box = even_box(missing)
    labels = np.zeros(missing.shape, dtype=np.int32)
    _, labels[box], stats, centroids = cv2.connectedComponentsWithStats(missing[box].astype(np.uint8), connectivity=8)
    return labels, stats_in_image(stats, centroids, (box[1].start, box[0].start))[0]


#: What one more distance transform costs beyond its pixels, in pixels (about 30 us against 60 ns a
#: pixel, measured with scipy's): :func:`_fill_boxes` searches hole by hole only where that is cheaper.
HOLE_CALL_PX = 512


def _fill_boxes(labels, stats, small, shape):
    """(box, fill) pairs: image slices to search and the pixels of ``small`` holes each fills.

    Either one box around all the small holes or one box per hole, whichever has fewer pixels to
    transform, counting :data:`HOLE_CALL_PX` per box: a few holes scattered over a real frame
    would otherwise span most of it (the bar clamp's 21: 340 x 535 pixels). Both hold every hole
    pixel's nearest reading (:func:`_hole_boxes`).
    """
    holes = np.flatnonzero(small)
    own = _hole_boxes(stats[holes], shape)
    whole = _hole_boxes(stats[holes], shape, together=True)[0]
    if ((own[:, 1] - own[:, 0]) * (own[:, 3] - own[:, 2]) + HOLE_CALL_PX).sum() < _pixels(whole):
        return [(_slices(box), labels[_slices(box)] == hole) for box, hole in zip(own, holes)]
    return [(_slices(whole), small[labels[_slices(whole)]])]


def _hole_boxes(stats, shape, *, together: bool = False) -> np.ndarray:
    """(n, 4) int: (top, bottom, left, right) of a box holding the nearest readings of each hole in
    ``stats`` (OpenCV's rows), or (1, 4) of one box for all of them ``together``.

    A pixel of a hole at most ``e`` pixels wide and high has a reading within
    ``e`` pixels along its row or its column: the first pixel past the hole
    there is not missing (it would belong to the hole), unless the hole runs
    from edge to edge both ways, and then ``e`` spans the image. So every
    nearest reading lies within the hole's bounding box grown by its ``e`` (all
    the holes' grown by the largest ``e``), and the distance transform need not
    look farther.
    """
    top, left = stats[:, cv2.CC_STAT_TOP], stats[:, cv2.CC_STAT_LEFT]
    height, width = stats[:, cv2.CC_STAT_HEIGHT], stats[:, cv2.CC_STAT_WIDTH]
    reach = np.maximum(width, height)
    if together:
        reach = reach.max()
    boxes = np.c_[top - reach, top + height + reach, left - reach, left + width + reach]
    if together:
        boxes = np.array([[boxes[:, 0].min(), boxes[:, 1].max(), boxes[:, 2].min(), boxes[:, 3].max()]])
    return np.clip(boxes, 0, [shape[0], shape[0], shape[1], shape[1]])


def _slices(box):
    return np.s_[box[0]:box[1], box[2]:box[3]]


def _pixels(box) -> int:
    return int((box[1] - box[0]) * (box[3] - box[2]))


def pixel_points(depth, intrinsics, rows, cols) -> np.ndarray:
    """(..., 3) float: camera-frame points of the pixels (rows, cols), index arrays of any one shape (eq 3.1-3.2)."""
    return pixel_points_at(depth[rows, cols], intrinsics, rows, cols)


def pixel_points_at(z, intrinsics, rows, cols) -> np.ndarray:
    """:func:`pixel_points` with the pixels' depths ``z`` given."""
    return np.stack([(cols - intrinsics.cx) * z / intrinsics.fx, (rows - intrinsics.cy) * z / intrinsics.fy, z], axis=-1)


def denoised_depth(depth, valid) -> np.ndarray:
    """(H, W) float: the valid readings median-filtered over ``APPROACH_MEDIAN_PX`` pixels, for nearest points.

    Invalid readings count as infinitely far, so they never make a pixel
    nearer; a pixel whose window is mostly invalid keeps its own reading.

    Parameters
    ----------
    depth : (H, W) float
        Depth in meters.
    valid : (H, W) bool
        The valid readings (:func:`valid_depth`).

    Examples
    --------
    >>> depth = np.full((5, 5), 0.7); depth[2, 2] = 0.5   # a flying pixel
    >>> round(float(denoised_depth(depth, depth > 0).min()), 6)
    0.7
    """
    smooth = cv2.medianBlur(np.where(valid, depth, np.inf).astype(np.float32), APPROACH_MEDIAN_PX)
    return np.where(np.isfinite(smooth), smooth, depth)


def denoised_at(depth, valid, rows, cols) -> np.ndarray:
    """(n,) float: :func:`denoised_depth` at the pixels (rows, cols), not empty.

    The filter runs on their bounding box grown by its reach only: inside the box every window is
    the whole image's, and where the box meets the image's edge it is that edge.
    """
    box = pixel_box(rows, cols, APPROACH_MEDIAN_PX // 2, depth.shape)
    return denoised_depth(depth[box], valid[box])[rows - box[0].start, cols - box[1].start]


def colour_on_depth(rgb, depth_shape, *, intrinsics: Intrinsics | None = None,
                    colour_intrinsics: Intrinsics | None = None) -> np.ndarray:
    """A colour image registered to the depth camera, resampled onto the depth image's pixel grid.

    Cameras give colour at another resolution than depth (a PhoXi's colour at twice its depth's, a
    RealSense colour stream at 1280 x 720 beside depth at 640 x 480). With both intrinsics, each depth
    pixel (u, v) takes the colour at ``cx_c + (u - cx) fx_c / fx``, ``cy_c + (v - cy) fy_c / fy`` (the two
    images registered: one optical centre, no rotation). Without them, the colour image must show the
    same view at another scale (the same aspect ratio, within a pixel), and is resized.

    Parameters
    ----------
    rgb : (H', W', 3) or (H', W') uint8
    depth_shape : (H, W)
    intrinsics, colour_intrinsics : Intrinsics, optional
        Of the depth image and of the colour image; give both or neither.

    Returns
    -------
    (H, W, 3) or (H, W) uint8
        ``rgb`` itself when it has the depth image's size.

    Raises
    ------
    PerceptionError
        Another aspect ratio without the colour intrinsics, or intrinsics of another size than the images.
    """
    img = as_image(rgb)
    height, width = depth_shape[:2]
    if img.shape[:2] == (height, width):
        return img
    check_colour_size(img.shape, depth_shape, intrinsics=intrinsics, colour_intrinsics=colour_intrinsics)
    if colour_intrinsics is None:
        shrink = img.shape[1] > width
        return cv2.resize(img, (width, height), interpolation=cv2.INTER_AREA if shrink else cv2.INTER_LINEAR)
    sx, sy = colour_intrinsics.fx / intrinsics.fx, colour_intrinsics.fy / intrinsics.fy
    to_colour = np.array([[sx, 0.0, colour_intrinsics.cx - sx * intrinsics.cx],
                          [0.0, sy, colour_intrinsics.cy - sy * intrinsics.cy]])
    resized = np.allclose(to_colour[:, 2], [0.5 * sx - 0.5, 0.5 * sy - 0.5], atol=0.05) and \
        np.allclose([sx * width, sy * height], img.shape[1::-1], atol=0.5)
    if resized:  # the colour image is the depth's view at another scale: resized, averaging when it shrinks
        return cv2.resize(img, (width, height), interpolation=cv2.INTER_AREA if sx > 1.0 else cv2.INTER_LINEAR)
    return cv2.warpAffine(img, to_colour, (width, height), flags=cv2.INTER_LINEAR | cv2.WARP_INVERSE_MAP,
                          borderMode=cv2.BORDER_REPLICATE)


def check_colour_size(colour_shape, depth_shape, *, intrinsics: Intrinsics | None = None,
                      colour_intrinsics: Intrinsics | None = None) -> None:
    """Refuse a colour image :func:`colour_on_depth` cannot put on the depth image's grid (its docstring)."""
    (height, width), (colour_height, colour_width) = depth_shape[:2], colour_shape[:2]
    if (colour_height, colour_width) == (height, width):
        return
    if (intrinsics is None) != (colour_intrinsics is None):
        raise PerceptionError("give the depth and the colour intrinsics together, or neither")
    if colour_intrinsics is None:
        if abs(colour_height - height * colour_width / width) > 1.0:
            raise PerceptionError(f"rgb image is {colour_width}x{colour_height} but the depth image is {width}x{height}: "
                                  f"not the same view at another resolution (the aspect ratios differ); give the "
                                  f"colour camera's intrinsics, or register the colour to the depth")
        return
    check_intrinsics(intrinsics).check_shape((height, width), "depth image")
    check_intrinsics(colour_intrinsics).check_shape(colour_shape, "rgb image")


def as_rgb(rgb) -> np.ndarray:
    """(H, W, 3) uint8: a checked colour image, grayscale expanded to RGB."""
    img = as_image(rgb)
    return cv2.cvtColor(img, cv2.COLOR_GRAY2RGB) if img.ndim == 2 else img


def as_gray(rgb) -> np.ndarray:
    """(H, W) uint8: a checked colour image as grayscale."""
    img = as_image(rgb)
    return img if img.ndim == 2 else cv2.cvtColor(img, cv2.COLOR_RGB2GRAY)


def as_image(rgb) -> np.ndarray:
    """(H, W, 3) or (H, W) uint8, C-contiguous: a checked colour image, as given."""
    img = _array("rgb image", rgb)
    if img.dtype != np.uint8:
        raise PerceptionError(f"rgb image must be 8-bit (uint8), got {img.dtype}")
    if (img.ndim == 2 or (img.ndim == 3 and img.shape[2] == 3)) and img.size:
        return np.ascontiguousarray(img)
    raise PerceptionError(f"rgb image must be (H, W, 3) or (H, W), got shape {img.shape}")


def _array(name, value) -> np.ndarray:
    try:
        return np.asarray(value)
    except (TypeError, ValueError):
        raise PerceptionError(f"{name} must be an array of numbers, got {type(value).__name__}") from None
