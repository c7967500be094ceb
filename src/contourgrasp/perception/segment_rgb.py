"""The thesis's RGB segmentation (section 3.1): grayscale, median blur, adaptive threshold, closing, contours."""

from __future__ import annotations

import cv2
import numpy as np

from .. import validation
from ..errors import PerceptionError
from ..tolerances import MIN_AREA_PX
from .camera import as_gray
from .region import Segmentation, make_segmentation, pick_object


def segment_rgb(
    rgb,
    *,
    blur: int = 5,
    block_size: int = 11,
    c: float = 2.0,
    close_kernel: int = 5,
    close_iterations: int = 2,
    min_area_px: int = MIN_AREA_PX,
) -> Segmentation:
    """The thesis's RGB segmentation (section 3.1).

    Grayscale; median blur (``blur``, odd, 1 = none); adaptive threshold
    (Gaussian-weighted mean over ``block_size`` pixels minus ``c``, inverted
    so that pixels darker than their surroundings, i.e. edges and dark
    objects, are foreground); closing, i.e. ``close_iterations`` dilations
    then as many erosions with an elliptic ``close_kernel``-pixel element;
    the filled external contours; the largest one not touching the image
    border (:mod:`contourgrasp.perception.region`).

    The defaults (11 px blocks, c = 2) find the object on all five shared
    PrimeSense frames, but its outline includes shadows and straps (the
    figures are in docs/perception.md).

    Parameters
    ----------
    rgb : (H, W, 3) uint8
        Colour image in RGB order, or (H, W) uint8 grayscale.
    blur, block_size, c, close_kernel, close_iterations
        As above.
    min_area_px : int
        Smallest object, pixels.

    Raises
    ------
    SegmentationError
        No closed contour, only contours touching the border, or a tiny one.
    """
    gray = as_gray(rgb)
    blur = validation.integer("blur", blur, 1, odd=True, error=PerceptionError)
    block_size = validation.integer("block_size", block_size, 3, odd=True, error=PerceptionError)
    c = validation.finite("c", c, error=PerceptionError)
    close_kernel = validation.integer("close_kernel", close_kernel, 1, error=PerceptionError)
    close_iterations = validation.integer("close_iterations", close_iterations, 0, error=PerceptionError)
    min_area_px = validation.integer("min_area_px", min_area_px, 1, error=PerceptionError)
    if blur > 1:
        gray = cv2.medianBlur(gray, blur)
    binary = cv2.adaptiveThreshold(gray, 255, cv2.ADAPTIVE_THRESH_GAUSSIAN_C, cv2.THRESH_BINARY_INV, block_size, c)
    kernel = cv2.getStructuringElement(cv2.MORPH_ELLIPSE, (close_kernel, close_kernel))
    closed = cv2.erode(cv2.dilate(binary, kernel, iterations=close_iterations), kernel, iterations=close_iterations)
    contours, _ = cv2.findContours(closed, cv2.RETR_EXTERNAL, cv2.CHAIN_APPROX_NONE)
    filled = np.zeros(gray.shape, dtype=np.uint8)
    cv2.drawContours(filled, contours, -1, 1, thickness=cv2.FILLED)
    mask, notes = pick_object(filled > 0, np.zeros(gray.shape, dtype=bool), min_area_px, "with a closed contour")
    return make_segmentation("rgb", mask, notes)
