"""Measurements of the simulation as an instrument: how much a hold inside its friction cones creeps."""

import pytest

from contourgrasp.sim.measure import squeeze_creep


@pytest.mark.parametrize("margin", [1.2, 2.0, 20.0])
def test_a_hold_inside_the_friction_cone_does_not_creep(margin):
    assert abs(squeeze_creep(margin)) < 2e-4


@pytest.mark.parametrize("margin", [0.5, 0.9])
def test_a_load_outside_the_friction_cone_slides(margin):
    assert squeeze_creep(margin) > 1.0


def test_the_soft_friction_of_impratio_10_crept():
    assert squeeze_creep(2.0, impratio=10) > 4e-4 > squeeze_creep(2.0, impratio=30) > squeeze_creep(2.0)
