"""Fitting the thesis's trajectories to a fingertip path: an exact arc is recovered, a zigzag refused."""

import numpy as np
import pytest

from contourgrasp import tolerances as tol
from contourgrasp.errors import HandError
from contourgrasp.hand import Arc
from contourgrasp.sim.model_fit import fit_finger


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
