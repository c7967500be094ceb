from pathlib import Path

import numpy as np
import pytest

from contourgrasp.errors import HandError
from contourgrasp.handmodels.force import fingertip_forces

#: A hinged lever 0.05 m long driven at 0.2 N m and a slider driven at 3 N, both saturated (see the file).
LEVER_AND_SLIDER = Path(__file__).parent / "fixtures" / "lever-and-slider.xml"


def test_fingertip_forces_are_the_saturated_drives_over_their_levers():
    forces = fingertip_forces(LEVER_AND_SLIDER, fingertips=["lever_tip", "slider_tip"], progress=(0.2, 0.5, 0.9))
    assert list(forces) == [0.2, 0.5, 0.9]
    for row in forces.values():
        assert row["lever_tip"] == pytest.approx(0.2 / 0.05, rel=1e-9)  # torque over lever, along the arc
        assert row["slider_tip"] == pytest.approx(3.0, rel=1e-9)


def test_a_fingertip_stopped_at_its_joint_limit_has_no_force_along_a_motion(tmp_path):
    stopped = tmp_path / "stopped.xml"  # the lever's hinge ends at 0.1 rad, long before its servo's target
    stopped.write_text(LEVER_AND_SLIDER.read_text().replace('range="0 1.2"', 'range="0 0.1"'))
    row = fingertip_forces(stopped, fingertips=["lever_tip", "slider_tip"], progress=(0.8,))[0.8]
    assert np.isnan(row["lever_tip"]) and row["slider_tip"] == pytest.approx(3.0)


def test_the_jaco_models_three_identical_fingers_push_alike():
    for row in fingertip_forces("jaco-three-finger").values():
        assert set(row) == {"thumb", "index", "pinky"}
        assert max(row.values()) - min(row.values()) < 0.01 * max(row.values())
        assert 1.0 < min(row.values()) < 10.0  # a 0.3 N m servo over a finger about 0.1 m long: a few newtons


@pytest.mark.parametrize("progress", [(), (0.0,), (1.5,), ("half",)])
def test_fingertip_forces_refuse_a_progress_outside_the_closing(progress):
    with pytest.raises(HandError, match="progress"):
        fingertip_forces(LEVER_AND_SLIDER, fingertips=["lever_tip", "slider_tip"], progress=progress)


@pytest.mark.parametrize("close_time", [0.0, -1.0, float("inf"), 1e6])
def test_fingertip_forces_refuse_a_closing_time_out_of_range(close_time):
    with pytest.raises(HandError, match="close_time"):
        fingertip_forces(LEVER_AND_SLIDER, fingertips=["lever_tip", "slider_tip"], close_time=close_time)
