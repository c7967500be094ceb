"""The mask helpers shared by the perception stages (perception._pixels)."""

import cv2
import numpy as np
import pytest

from contourgrasp.perception._pixels import components


@pytest.mark.parametrize("threads", [1, 2])
def test_components_label_and_count_as_opencv_on_the_whole_image(threads):
    """Labelled on the mask's box, the labels are numbered as OpenCV numbers them on the whole image
    (ties between regions of one area are broken by label), and every area is counted."""
    rng = np.random.default_rng(3)
    before = cv2.getNumThreads()
    cv2.setNumThreads(threads)
    try:
        for _ in range(200):
            shape = tuple(rng.integers(3, 300, 2))
            mask = np.zeros(shape, dtype=bool)
            for _ in range(rng.integers(1, 10)):
                r, c = rng.integers(0, shape[0]), rng.integers(0, shape[1])
                block = mask[r:r + rng.integers(1, 60), c:c + rng.integers(1, 60)]
                block[...] = rng.random(block.shape) < rng.uniform(0.3, 0.95)
            count, labels = cv2.connectedComponents(mask.astype(np.uint8), connectivity=8)
            got_count, got_labels, areas = components(mask)
            assert got_count == count
            np.testing.assert_array_equal(got_labels, labels)
            np.testing.assert_array_equal(areas, np.bincount(labels.ravel(), minlength=count))
    finally:
        cv2.setNumThreads(before)


def test_an_empty_mask_is_all_background():
    count, labels, areas = components(np.zeros((4, 5), dtype=bool))
    assert count == 1 and not labels.any() and areas.tolist() == [20]


def test_fill_holes_is_scipys_binary_fill_holes():
    from scipy import ndimage

    from contourgrasp.perception._pixels import fill_holes

    rng = np.random.default_rng(0)
    for _ in range(200):
        mask = rng.random((int(rng.integers(1, 40)), int(rng.integers(1, 40)))) < rng.uniform(0.2, 0.8)
        np.testing.assert_array_equal(fill_holes(mask), ndimage.binary_fill_holes(mask))
