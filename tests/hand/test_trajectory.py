"""Rays and arcs (eq 3.18-3.21), the hand frame, the presets and the hand's checks."""

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from contourgrasp import (
    Arc,
    Finger,
    Hand,
    Ray,
    contour,
    example_contour,
    load_hand,
    preset_names,
    synthesis,
)
from contourgrasp.errors import HandError
from contourgrasp.hand import rotation, to_image

PRESETS = ["five-finger-curved-thumb", "five-finger-linear", "three-finger"]


def test_presets_are_listed():
    assert preset_names() == PRESETS


@pytest.mark.parametrize("name", PRESETS)
def test_fingers_close_toward_the_grasp_centre(name):
    hand = load_hand(name)
    centre = hand.grasp_centre
    for finger in hand.fingers:
        assert np.linalg.norm(finger.end - centre) < np.linalg.norm(np.array(finger.start) - centre), finger.name


@pytest.mark.parametrize("name", PRESETS)
def test_a_can_at_the_grasp_centre_is_touched_by_every_finger(name):
    """The can (0.12 x 0.066 m) centred on the grasp centre, in some orientation, meets all fingers.

    With the tables' directions taken literally (fingers moving apart) no
    orientation would work. Five-finger hands close the thumb across the
    fingers, so the can's orientation matters; we try every 5 degrees.
    """
    hand = load_hand(name)
    can = example_contour("can")
    touched_by_all = []
    for angle in np.radians(np.arange(0, 180, 5)):
        model = contour.fit(can @ rotation(angle).T + hand.grasp_centre)
        result = synthesis.evaluate_poses(model, hand, [[0.0, 0.0, 0.0]])
        touched_by_all.append(bool(result.touching.all() and not result.start_inside.any()))
    assert any(touched_by_all)


def test_ray_closing_direction_is_normalised():
    assert Ray((3.0, 4.0)).closing_direction == pytest.approx((0.6, 0.8))
    with pytest.raises(HandError, match="non-zero"):
        Ray((0.0, 0.0))


def test_ray_points_and_virtual_start():
    finger = Finger("thumb", (-0.115, 0.1), Ray((0.994, 0.106)), travel=0.09, virtual_start=0.03)
    c = np.array(finger.trajectory.closing_direction)
    np.testing.assert_allclose(finger.end, np.array([-0.115, 0.1]) + 0.09 * c)
    np.testing.assert_allclose(finger.virtual_start_point, np.array([-0.115, 0.1]) + 0.03 * c)


def test_arc_travel_is_arc_length():
    finger = load_hand("five-finger-curved-thumb").fingers[0]
    assert isinstance(finger.trajectory, Arc)
    points = finger.points(np.linspace(0, finger.travel, 5001))
    length = np.sum(np.linalg.norm(np.diff(points, axis=0), axis=1))
    assert length == pytest.approx(finger.travel, rel=1e-4)
    np.testing.assert_allclose(points[0], finger.start, atol=1e-12)


def test_arc_follows_eq_3_20():
    arc = Arc(0.055, 0.04, 3.77)
    finger = Finger("thumb", (-0.115, 0.1), arc, travel=0.09)
    lam = 0.05
    angle = arc.angle(lam)
    expected = np.array([-0.115, 0.1]) + [0.055 * (np.cos(3.77 + angle) - np.cos(3.77)),
                                          0.04 * (np.sin(3.77 + angle) - np.sin(3.77))]
    np.testing.assert_allclose(finger.points(lam)[0], expected, atol=1e-12)
    assert angle > 0


def test_a_negative_a_sin_is_the_mirrored_arc_turning_clockwise():
    counter, clockwise = Arc(0.055, 0.04, 3.77), Arc(0.055, -0.04, 3.77)
    lam = np.linspace(0.0, 0.09, 10)
    np.testing.assert_allclose(clockwise.offset(lam), counter.offset(lam) * [1.0, -1.0], atol=1e-12)
    assert clockwise.perimeter == pytest.approx(counter.perimeter)
    steps = np.diff(clockwise.offset(lam), axis=0)
    assert (steps[:-1, 0] * steps[1:, 1] - steps[:-1, 1] * steps[1:, 0] < 0).all()  # turning clockwise
    with pytest.raises(HandError, match=r"arc \|a_sin\|"):
        Arc(0.055, 0.0, 3.77)


def test_curved_thumb_ends_opposite_the_fingers():
    hand = load_hand("five-finger-curved-thumb")
    thumb, index = hand.fingers[0].end, hand.fingers[1].end
    assert abs(thumb[0] - index[0]) < 0.01
    assert thumb[1] < index[1]


def test_finger_and_hand_validation():
    with pytest.raises(HandError, match="travel"):
        Finger("a", (0, 0), Ray((0, 1)), travel=0.0)
    finger = Finger("a", (0, 0), Ray((0, 1)), travel=0.1)
    with pytest.raises(HandError, match="min_touching"):
        Hand("h", (finger,), min_touching=2)
    with pytest.raises(HandError, match="unique"):
        Hand("h", (finger, finger), min_touching=1)
    with pytest.raises(HandError, match="arc"):
        Finger("a", (0, 0), Arc(0.01, 0.01, 0.0), travel=1.0)


def test_to_image_rotates_right_handed_about_the_optical_axis():
    # yaw = +90 deg turns the hand's x axis onto the image's y axis (down).
    np.testing.assert_allclose(to_image([[1.0, 0.0]], (0.5, 0.5, np.pi / 2)), [[0.5, 1.5]], atol=1e-12)


def test_arc_chords_stay_within_half_a_millimetre_of_the_arc():
    finger = load_hand("five-finger-curved-thumb").fingers[0]
    chords, lam = finger.polyline()
    fine = finger.points(np.linspace(0, finger.travel, 2000))
    a, b = chords[:-1], chords[1:]
    d = b - a
    u = np.clip(np.einsum("kmi,mi->km", fine[:, None] - a[None], d) / np.sum(d * d, axis=1), 0, 1)
    nearest = a[None] + u[..., None] * d[None]
    assert np.linalg.norm(fine[:, None] - nearest, axis=2).min(axis=1).max() < 5e-4


def test_a_hand_without_fingers_is_a_hand_error():
    with pytest.raises(HandError, match="no fingers"):
        Hand("h", (), 1)


@pytest.mark.parametrize("make, field", [
    (lambda: Finger("f", (1e300, 0.0), Ray((1.0, 0.0)), 0.1), "start"),
    (lambda: Finger("f", (-1e300, 0.0), Ray((1.0, 0.0)), 0.1), "start"),
    (lambda: Finger("f", (0.0, 0.0), Ray((1.0, 0.0)), 0.1, virtual_start=1e300), "virtual_start"),
    (lambda: Finger("f", (0.0, 0.0), Ray((1.0, 0.0)), 1e300), "travel"),
    (lambda: Finger("f", (0.0, 0.0), Ray((1.0, 0.0)), 0.1, radius=3.0), "radius"),
    (lambda: Finger("f", (0.0, 0.0), Ray((1.0, 0.0)), 0.1, alpha=float("nan")), "alpha"),
    (lambda: Finger("f", (0.0, 0.0), Ray((1.0, 0.0)), 0.1, beta=-1.0), "beta"),
    (lambda: Finger("f", "ab", Ray((1.0, 0.0)), 0.1), "start"),
    (lambda: Finger("f", (0.0, 0.0), "ray", 0.1), "trajectory"),
    (lambda: Arc(0.05, 0.04, 1e300), "phi_off"),
    (lambda: Arc(1e300, 0.04, 0.0), "a_cos"),
    (lambda: Arc(0.05, "x", 0.0), "a_sin"),
    (lambda: Ray("ab"), "closing_direction"),
    (lambda: Ray((0.0, 0.0)), "closing_direction"),
    (lambda: Hand("h", [Finger("f", (0.0, 0.0), Ray((1.0, 0.0)), 0.1)], 1, miss_penalty=-1.0), "miss_penalty"),
    (lambda: Hand("h", [Finger("f", (0.0, 0.0), Ray((1.0, 0.0)), 0.1)], 1.5), "min_touching"),
    (lambda: Hand("h", [Finger("f", (0.0, 0.0), Ray((1.0, 0.0)), 0.1)], 1, max_imbalance=1.5), "max_imbalance"),
    (lambda: Hand("h", [Finger("f", (0.0, 0.0), Ray((1.0, 0.0)), 0.1)], 1, tips_brush_table="yes"), "tips_brush_table"),
    (lambda: Hand("h", [Finger("f", (0.0, 0.0), Ray((1.0, 0.0)), 0.1)], 1, grasp_height_fraction=0.8),
     "grasp_height_fraction"),
    (lambda: Hand("h", [Finger("f", (0.0, 0.0), Ray((1.0, 0.0)), 0.1)], 1, slice_contour="hand"), "slice_contour"),
    (lambda: Hand("h", [Finger("f", (0.0, 0.0), Ray((1.0, 0.0)), 0.1)], 1, slice_contour=1), "slice_contour"),
    (lambda: Hand("h", [Finger(f"f{i}", (0.0, 0.0), Ray((1.0, 0.0)), 0.1) for i in range(11)], 1), "fingers"),
])
def test_absurd_hand_values_are_hand_errors_naming_the_field(make, field):
    """A start of 1e300 or a phi_off of 1e300 once divided by zero in the search's kernels."""
    with pytest.raises(HandError, match=field):
        make()


def test_a_huge_closing_direction_is_normalised():
    assert Ray((1e300, 1e300)).closing_direction == pytest.approx((math.sqrt(0.5), math.sqrt(0.5)))


absurd_numbers = st.one_of(st.floats(allow_nan=True, allow_infinity=True), st.sampled_from([1e-300, 1e300, -1e300]),
                           st.integers(-10**30, 10**30), st.text(max_size=2), st.none(), st.booleans())


@settings(max_examples=100, deadline=None)
@given(start=st.tuples(absurd_numbers, absurd_numbers), direction=st.tuples(absurd_numbers, absurd_numbers),
       arc=st.one_of(st.none(), st.tuples(absurd_numbers, absurd_numbers, absurd_numbers)),
       travel=absurd_numbers, virtual_start=absurd_numbers, alpha=absurd_numbers, beta=absurd_numbers,
       radius=absurd_numbers, min_touching=absurd_numbers, miss_penalty=absurd_numbers)
def test_fuzz_hand_construction_gives_a_hand_or_a_hand_error(start, direction, arc, travel, virtual_start, alpha,
                                                             beta, radius, min_touching, miss_penalty):
    try:
        trajectory = Ray(direction) if arc is None else Arc(*arc)
        finger = Finger("f", start, trajectory, travel, virtual_start=virtual_start, alpha=alpha, beta=beta,
                        radius=radius)
        hand = Hand("h", (finger,), min_touching, miss_penalty=miss_penalty)
    except HandError:
        return
    assert np.all(np.isfinite(hand.starts)) and np.all(np.isfinite(hand.virtual_starts))
    assert np.all(np.isfinite(hand.segments().start))


# --- the 3-D hand: finger chains, forward kinematics, consistency with the 2-D trajectory ---
