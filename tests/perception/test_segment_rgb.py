"""The thesis's RGB steps (contourgrasp.perception.segment_rgb)."""

from __future__ import annotations



from contourgrasp.perception import segment_rgb
from perception_scenes import render, iou


def test_rgb_segmentation_follows_the_thesis_steps():
    _, rgb, truth, _ = render(kind="box")
    seg = segment_rgb(rgb)
    assert seg.method == "rgb"
    assert iou(seg.mask, truth) > 0.95
