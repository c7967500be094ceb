"""Telling a failed grasp from a picture (contourgrasp.sim.detect): an object gone, pushed, thin, grey or pale."""

import numpy as np

from contourgrasp.perception import Intrinsics
from contourgrasp.sim.detect import seen_lifted


def test_a_picture_says_lifted_when_the_object_has_left_its_place_and_not_when_it_was_pushed():
    camera = Intrinsics(fx=525.0, fy=525.0, cx=79.5, cy=59.5, width=160, height=120)

    def frame(box=None, height=0.05, colour=(40, 60, 160)):
        depth, rgb = np.full((120, 160), 0.7), np.full((120, 160, 3), 200, np.uint8)
        if box is not None:
            depth[box] -= height
            rgb[box] = colour
        return rgb, depth

    before = frame(np.s_[50:70, 70:90])

    class Planned:
        segmentation = type("Seg", (), {"mask": before[1] < 0.69})()

    Planned.camera = camera
    assert not seen_lifted(Planned, before, before)  # unmoved
    assert not seen_lifted(Planned, before, frame(np.s_[50:70, 78:98]))  # pushed 8 px (1 cm)
    assert seen_lifted(Planned, before, frame())  # gone
    rolled = frame(np.s_[50:70, 130:150])  # 60 px (8 cm) away: gone from its place, still on the table
    assert seen_lifted(Planned, before, rolled) and not seen_lifted(Planned, before, rolled, anywhere=True)
    flat = frame(np.s_[50:70, 70:90], height=0.004)  # a thin object depth does not see: its colour still there
    assert not seen_lifted(Planned, flat, flat) and seen_lifted(Planned, flat, frame())
    neighbour = np.s_[50:70, 94:114]  # a box 4 px (5 mm) beside it
    both = frame(np.s_[50:70, 70:90])
    both[1][neighbour] -= 0.05
    alone = frame(neighbour)
    grey_both, grey_alone = ((np.full_like(image, 200), depth) for image, depth in (both, alone))  # no colour
    assert seen_lifted(Planned, grey_both, grey_alone)  # the neighbour that stood beside it is not it
    assert not seen_lifted(Planned, grey_both, grey_both)
    pale = frame(np.s_[50:70, 70:90], colour=(205, 200, 195))  # as light as the table: its colour tells nothing
    assert seen_lifted(Planned, pale, frame(), anywhere=True) and not seen_lifted(Planned, pale, pale, anywhere=True)
