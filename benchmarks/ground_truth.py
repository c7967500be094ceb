"""How far the hand-made masks of the real frames can be trusted: the figures behind the README's segmentation notes.

For every frame that ``benchmarks/segmentation.py`` scores, prints one row:

* the shift (dx, dy) at which the mask's edges best match the colour image's and the depth image's
  edges (normalised cross-correlation of gradient magnitudes around the object, up to 8 px): a
  positive dy means the mask's outline lies that many pixels *above* the image's;
* the IoU of the mask dilated by one pixel against the mask itself (what a 1 px error costs);
* how many separate pieces the mask has, and the smallest closing (disc diameter, px) that joins them;
* the fraction of depth readings in whole millimetres (raw sensor values; a fill is not) inside and
  outside the mask.

Usage::

    python benchmarks/ground_truth.py [--data PATH]
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import cv2
import numpy as np
from scipy import ndimage
from segmentation import default_data, frames

SEARCH_PX = 8
MARGIN_PX = 20


def edges(image):
    image = np.asarray(image, dtype=np.float32)
    channels = [image] if image.ndim == 2 else [image[..., k] for k in range(image.shape[2])]
    return sum(cv2.magnitude(cv2.Sobel(c, cv2.CV_32F, 1, 0), cv2.Sobel(c, cv2.CV_32F, 0, 1)) for c in channels)


def best_shift(truth, image):
    """(dx, dy): mask pixel (u, v) has the edge that ``image`` has at (u + dx, v + dy)."""
    rows, cols = np.nonzero(truth)
    r, m = SEARCH_PX, MARGIN_PX
    top, bottom, left, right = rows.min() - m, rows.max() + m + 1, cols.min() - m, cols.max() + m + 1
    template = edges(truth.astype(np.float32))[top:bottom, left:right]
    score = cv2.matchTemplate(edges(image)[top - r:bottom + r, left - r:right + r], template, cv2.TM_CCOEFF_NORMED)
    dy, dx = np.unravel_index(np.argmax(score), score.shape)
    return int(dx) - r, int(dy) - r


def whole_mm(depth, truth):
    """Fractions of the valid depth readings inside and outside ``truth`` that are whole millimetres."""
    mm = np.asarray(depth, dtype=np.float64).reshape(truth.shape) * 1000.0
    valid = mm > 0
    whole = valid & (np.abs(mm - np.rint(mm)) < 1e-3)
    return whole[truth].sum() / valid[truth].sum(), whole[~truth].sum() / valid[~truth].sum()


def joining_closing(truth):
    """(pieces, smallest odd disc diameter in px whose closing makes one piece)."""
    pieces = ndimage.label(truth, structure=np.ones((3, 3)))[1]
    size = 1
    while ndimage.label(cv2.morphologyEx(truth.astype(np.uint8), cv2.MORPH_CLOSE, cv2.getStructuringElement(
            cv2.MORPH_ELLIPSE, (size, size))), structure=np.ones((3, 3)))[1] > 1:
        size += 2
    return pieces, size


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--data", type=Path, default=default_data(), help="shared data folder")
    args = parser.parse_args(argv)
    rows = list(frames(args.data))
    if not rows:
        print(f"no frames with segmask_N.png found under {args.data}/rgbd", file=sys.stderr)
        return 1
    print("| frame | mask vs colour edges (dx, dy) | mask vs depth edges (dx, dy) | IoU of mask dilated 1 px "
          "| pieces (closing that joins them) | whole-mm depth inside / outside |")
    print("|---|---:|---:|---:|---:|---:|")
    for name, rgb, depth, _, truth in rows:
        lab = cv2.cvtColor(rgb, cv2.COLOR_RGB2LAB)
        dilated = cv2.dilate(truth.astype(np.uint8), np.ones((3, 3), np.uint8)) > 0
        pieces, closing = joining_closing(truth)
        inside, outside = whole_mm(depth, truth)
        print(f"| {name} | {best_shift(truth, lab)} | {best_shift(truth, np.asarray(depth).reshape(truth.shape))} "
              f"| {(truth & dilated).sum() / dilated.sum():.3f} | {pieces} ({closing} px) "
              f"| {inside:.1%} / {outside:.1%} |")
    return 0


if __name__ == "__main__":
    sys.exit(main())
