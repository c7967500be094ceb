"""lambda_virt from closing speeds: the derivation on synthetic closings, the simulated hand, the CLI."""

from dataclasses import replace

import numpy as np
import pytest

from contourgrasp import InputError, load_hand
from contourgrasp.cli import main
from contourgrasp.io.hand_file import hand_to_toml
from contourgrasp.sim.calibrate import CLOSED_WITHIN, FingerTravel, calibrate_virtual_starts, derive_virtual_starts

TRAVEL = 0.05
TIMES = np.linspace(0.0, 2.0, 2001)


def linear_closing(speeds, delays=None) -> FingerTravel:
    """Fingers of equal travel closing at constant speeds (m/s) after delays (s), stopping at full travel."""
    speeds = np.asarray(speeds, dtype=float)
    delays = np.zeros_like(speeds) if delays is None else np.asarray(delays, dtype=float)
    travelled = np.minimum(speeds[:, None] * np.maximum(TIMES - delays[:, None], 0.0), TRAVEL)
    names = tuple(f"f{i}" for i in range(len(speeds)))
    return FingerTravel(names=names, travel=np.full(len(speeds), TRAVEL), times=TIMES, travelled=travelled)


def test_constant_speeds_give_the_analytic_offsets():
    # s_r(T_i(d)) = d v_r / v_i, so lambda_i = mean over [0, F'] of d (1 - v_r / v_i) = F' / 2 (1 - v_r / v_i).
    speeds = np.array([0.2, 0.1, 0.05])
    closing = linear_closing(speeds)
    reach = TRAVEL - CLOSED_WITHIN
    starts = derive_virtual_starts(closing)
    expected = reach / 2 * (1 - speeds[2] / speeds)
    np.testing.assert_allclose([starts[n] for n in closing.names], expected, atol=1e-9)
    np.testing.assert_allclose(closing.closing_times, reach / speeds, atol=1e-9)
    np.testing.assert_allclose(closing.mean_speeds, speeds, rtol=1e-9)


def test_default_reference_is_the_finger_that_closes_last_and_gets_zero():
    starts = derive_virtual_starts(linear_closing([0.2, 0.05, 0.1]))
    assert starts["f1"] == 0.0
    assert starts["f0"] > starts["f2"] > 0  # faster fingers: virtual start ahead along the closing motion


def test_slower_finger_than_the_reference_starts_behind():
    # Thesis 3.4: a slower finger's virtual start lies farther from its closed position (negative lambda here).
    starts = derive_virtual_starts(linear_closing([0.2, 0.1]), reference="f0")
    assert starts["f0"] == 0.0 and starts["f1"] < 0


def test_a_late_start_at_equal_speed_is_an_offset_of_speed_times_delay():
    # f0 leads by v tau once f1 moves; before that, f0 at d meets f1 at 0: mean over [0, F'] of min(d, v tau).
    v, tau = 0.1, 0.1
    starts = derive_virtual_starts(linear_closing([v, v], delays=[0.0, tau]))
    reach, lead = TRAVEL - CLOSED_WITHIN, v * tau
    assert starts["f1"] == 0.0
    assert starts["f0"] == pytest.approx(lead - lead**2 / (2 * reach), abs=1e-9)


def test_equal_closing_gives_zero_everywhere():
    starts = derive_virtual_starts(linear_closing([0.1, 0.1, 0.1]))
    np.testing.assert_allclose(list(starts.values()), 0.0, atol=1e-12)


def test_a_finger_that_never_closes_and_an_unknown_reference_are_refused():
    with pytest.raises(InputError, match="does not close"):
        derive_virtual_starts(linear_closing([0.1, 0.01]))
    with pytest.raises(InputError, match="reference finger 'thumb'"):
        derive_virtual_starts(linear_closing([0.1, 0.2]), reference="thumb")


@pytest.fixture(scope="module")
def calibration():
    return calibrate_virtual_starts("five-finger-linear")


def test_simulated_hand_thumb_leads_and_the_reference_is_zero(calibration):
    # hand_model's "thesis" timing: thumb first and fastest, ring and little start before
    # index and middle but close last (chapter 5's observation).
    v = calibration.virtual_start
    assert calibration.reference == "ring" and v["ring"] == 0.0
    assert v["thumb"] > 0.02
    assert abs(v["little"]) < 1e-6 and v["index"] == pytest.approx(v["middle"], abs=1e-6)
    assert -0.01 < v["index"] < 0
    t = calibration.closing_time
    assert t["thumb"] < t["index"] < t["ring"] <= 1.0 + 0.3  # within the trial's ramp and squeeze


def test_calibration_is_deterministic(calibration):
    assert calibrate_virtual_starts("five-finger-linear") == calibration


def test_cli_writes_a_loadable_calibrated_hand(tmp_path, capsys, calibration):
    out = tmp_path / "calibrated.toml"
    assert main(["calibrate", "--out", str(out)]) == 0
    table = capsys.readouterr().out
    assert "thumb" in table and "ring *" in table and str(out) in table
    hand = load_hand(str(out))
    for f in hand.fingers:
        assert f.virtual_start == pytest.approx(calibration.virtual_start[f.name], abs=1e-4)
    assert [f.start for f in hand.fingers] == [f.start for f in load_hand("five-finger-linear").fingers]


@pytest.mark.parametrize("hand", ["five-finger-curved-thumb", "no-such-hand"])
def test_cli_refuses_a_hand_it_cannot_simulate(tmp_path, capsys, hand):
    out = tmp_path / "calibrated.toml"
    assert main(["calibrate", "--hand", hand, "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert len(err.strip().splitlines()) == 1 and err.startswith("contourgrasp: error:")
    assert not out.exists()


def test_calibrate_leaves_no_mujoco_log_in_the_working_directory(tmp_path, monkeypatch, capsys):
    # MuJoCo's default warning handler appends to MUJOCO_LOG.TXT in the working directory; a hand too small to
    # simulate stably makes it warn. The run refuses that hand in one line and writes no file.
    monkeypatch.chdir(tmp_path)
    hand = tmp_path / "tiny.toml"
    # the preset's 2-D part only: its chains would not follow a 1 um travel (the sim derives new ones)
    preset = hand_to_toml(replace(load_hand("three-finger"), chains=None, palm=None))
    hand.write_text(preset.replace("travel = 0.08", "travel = 1e-6"))
    assert main(["calibrate", "--hand", str(hand)]) == 2
    err = capsys.readouterr().err
    assert "unstable" in err and len(err.strip().splitlines()) == 1
    assert main(["calibrate", "--hand", "three-finger"]) == 0
    assert [p.name for p in tmp_path.iterdir()] == ["tiny.toml"]
