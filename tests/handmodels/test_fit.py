"""Fitting the thesis's trajectories to a fingertip path (an exact arc is recovered, a zigzag refused) and the
palm's plate to its geoms' boxes."""

import numpy as np
import pytest

from contourgrasp import tolerances as tol
from contourgrasp.errors import HandError
from contourgrasp.hand import Arc
from contourgrasp.handmodels.fit import BOX_CORNERS, fit_finger, palm_plate


def test_fit_finger_recovers_an_arc_and_refuses_a_zigzag():
    truth = Arc(0.05, 0.03, 3.5)
    lam = np.linspace(0.0, 0.06, 300)
    path = np.array([0.1, 0.2]) + truth.offset(lam)
    finger, fit = fit_finger("curl", path)
    assert fit.kind == "arc" and fit.error < 1e-6 and fit.ray_error > tol.MODEL_FIT_TOLERANCE
    assert finger.travel == pytest.approx(0.06, abs=1e-5)
    zigzag = np.stack([np.linspace(0, 0.05, 50), 0.01 * np.sign(np.sin(np.linspace(0, 20, 50)))], axis=1)
    with pytest.raises(HandError, match="finger 'zig': no ray or arc fits"):
        fit_finger("zig", zigzag)


def test_fit_finger_recovers_a_clockwise_arc_as_the_mirrored_ellipse():
    # a right hand's curling finger, projected, turns clockwise: the mirror image of a counter-clockwise arc
    counter = Arc(0.05, 0.03, 3.5)
    lam = np.linspace(0.0, 0.06, 300)
    path = np.array([0.1, 0.2]) + counter.offset(lam) * [1.0, -1.0]
    finger, fit = fit_finger("curl", path)
    assert fit.kind == "arc" and fit.error < 1e-6
    assert finger.trajectory.a_sin == pytest.approx(-0.03, abs=1e-6)
    np.testing.assert_allclose(finger.points(lam[::30]), path[::30], atol=1e-6)


def box_corners(centre, half, turn=0.0):
    """(8, 3) float: a box's corners in fit.BOX_CORNERS's order, turned by ``turn`` about the y axis."""
    c, s = np.cos(turn), np.sin(turn)
    rotation = np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])
    return np.asarray(centre) + (BOX_CORNERS * half) @ rotation.T


def test_a_palm_box_gives_its_underside_and_several_their_deepest_rectangle():
    flat = palm_plate(box_corners([0.0, 0.0, -0.01], [0.05, 0.04, 0.01]))  # underside at z = 0
    assert flat.depths is None and flat.thickness == pytest.approx(0.02)
    assert sorted(flat.outline) == sorted([(-0.05, -0.04), (-0.05, 0.04), (0.05, -0.04), (0.05, 0.04)])
    tilted = palm_plate(box_corners([0.0, 0.0, 0.0], [0.06, 0.04, 0.01], turn=0.3))
    # the broad face toward +z, tilted by 0.3 rad: its z rises along x by tan(0.3)
    a, b, c = tilted.plane
    assert b == pytest.approx(-np.tan(0.3), abs=1e-9) and c == pytest.approx(0.0, abs=1e-9)
    assert a == pytest.approx(0.01 / np.cos(0.3), abs=1e-9)
    two = palm_plate(np.vstack([box_corners([0.0, 0.0, -0.01], [0.05, 0.04, 0.01]),
                                 box_corners([0.08, 0.0, 0.0], [0.02, 0.02, 0.015])]))
    assert two.depths == (0.015,) * 4 and two.points[:, 0].max() == pytest.approx(0.1)
