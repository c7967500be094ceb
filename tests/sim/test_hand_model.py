"""The simulated hand against its 2-D preset: straight fingertip paths, full closure, timing."""

import numpy as np
import pytest

import contourgrasp
from contourgrasp.sim import build_hand, fingertip_path_error, fingertip_paths
from contourgrasp.sim.scene import Camera

HAND = contourgrasp.load_hand("five-finger-linear")


def pixel_at_working_distance() -> float:
    """One pixel's footprint on the table (m): below it the camera cannot tell a path error."""
    return Camera().height / Camera().intrinsics.fx


@pytest.mark.parametrize("timing", ["thesis", "uniform"])
def test_fingertip_paths_follow_the_preset(timing):
    # Each finger is a planar chain in the vertical plane of its ray, so its tip's projection
    # is on the ray by construction; only soft joint limits and the base's compliance can
    # pull it off. Bound: one pixel at the working distance (~1.4 mm).
    errors = fingertip_path_error(HAND, timing=timing)
    print(f"\nfingertip path error ({timing}), mm:", {k: round(v, 3) for k, v in errors.items()})
    assert set(errors) == {f.name for f in HAND.fingers}
    assert max(errors.values()) < 1000 * pixel_at_working_distance()


def test_closing_on_nothing_ends_fully_closed():
    paths = fingertip_paths(HAND)
    for finger in HAND.fingers:
        np.testing.assert_allclose(paths[finger.name][0], finger.start, atol=5e-4)
        np.testing.assert_allclose(paths[finger.name][-1], finger.end, atol=5e-4)


def test_thesis_timing_thumb_first_index_and_middle_last():
    paths = fingertip_paths(HAND, timing="thesis")
    moved = {f.name: int(np.argmax(np.linalg.norm(paths[f.name] - f.start, axis=1) > 1e-3)) for f in HAND.fingers}
    assert moved["thumb"] < moved["ring"] == moved["little"] < moved["index"] == moved["middle"]


def test_uniform_timing_fingers_start_together():
    paths = fingertip_paths(HAND, timing="uniform")
    moved = {int(np.argmax(np.linalg.norm(paths[f.name] - f.start, axis=1) > 1e-3)) for f in HAND.fingers}
    assert max(moved) - min(moved) <= 10  # steps of 2 ms


def test_arc_fingers_are_refused():
    with pytest.raises(contourgrasp.InputError, match="arc"):
        build_hand(contourgrasp.load_hand("five-finger-curved-thumb"))


def test_unknown_timing_is_refused():
    with pytest.raises(contourgrasp.InputError, match="timing"):
        build_hand(HAND, timing="sometimes")


def test_fingertips_stay_low_while_closing():
    # The tip must not rise over flat objects (stones are ~4 cm thick).
    for finger in build_hand(HAND).fingers:
        _, depth = finger.tip(np.linspace(0, 1, 101))
        assert np.ptp(depth) < 0.012
