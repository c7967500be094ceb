import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from contourgrasp import Arc, Finger, Hand, Ray, efd, example_contour, load_hand, preset_names, synthesis
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
        model = efd.fit(can @ rotation(angle).T + hand.grasp_centre)
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

from dataclasses import replace  # noqa: E402

from contourgrasp.hand import (FingerChain, Palm, chain_capsules, chain_deviation, chain_joints,  # noqa: E402
                               chain_tip, check_chain)


def straight_chain(tilt=0.0, q=(0.0, 0.0), **kw):
    """A chain in the y-z plane (direction +y) of links 0.06 + 0.04 m, knuckle at (0.01, 0.02), 0.005 deep."""
    args = dict(knuckle=(0.01, 0.02), knuckle_depth=0.005, direction=(0.0, 1.0), links=(0.06, 0.04), radius=0.008,
                open_angles=(-tilt, 0.0), closed_angles=q)
    return FingerChain(**(args | kw))


def test_forward_kinematics_is_trigonometry():
    chain = straight_chain(tilt=0.3, q=(0.2, 0.5))
    joints = chain_joints(chain, [0.0, 0.5, 1.0])
    for s, (k, j, t) in zip([0.0, 0.5, 1.0], joints, strict=True):
        q1 = -0.3 + s * (0.2 + 0.3)
        q2 = s * 0.5
        np.testing.assert_allclose(k, [0.01, 0.02, 0.005], atol=1e-15)
        np.testing.assert_allclose(j, [0.01, 0.02 + 0.06 * math.sin(q1), 0.005 + 0.06 * math.cos(q1)], atol=1e-15)
        np.testing.assert_allclose(t, j + [0.0, 0.04 * math.sin(q1 + q2), 0.04 * math.cos(q1 + q2)], atol=1e-15)
    np.testing.assert_allclose(chain_tip(chain, [0.0, 0.5, 1.0]), joints[:, 2])


def test_a_hanging_finger_points_straight_down_and_a_right_angle_points_along_its_direction():
    np.testing.assert_allclose(chain_tip(straight_chain(q=(0.0, 0.0)), 0.0), [[0.01, 0.02, 0.105]], atol=1e-15)
    bent = straight_chain(q=(math.pi / 2, 0.0))  # closed: the whole finger horizontal, along +y
    np.testing.assert_allclose(chain_tip(bent, 1.0), [[0.01, 0.12, 0.005]], atol=1e-15)
    diagonal = straight_chain(direction=(3.0, 4.0), q=(math.pi / 2, 0.0))  # direction normalised to (0.6, 0.8)
    np.testing.assert_allclose(chain_tip(diagonal, 1.0), [[0.07, 0.10, 0.005]], atol=1e-15)


def test_lean_geometry_knuckle_inward_of_the_open_tip_by_l_sin_tilt():
    # The diagnosis: an open finger leaning outward by tilt has its knuckle (l1 + l2) sin(tilt)
    # inward of its tip, i.e. along the closing direction; the tip is (l1 + l2) cos(tilt) below the knuckle.
    for tilt in (math.radians(18.0), math.radians(24.6)):
        chain = straight_chain(tilt=tilt, q=(0.0, 0.0))
        tip = chain_tip(chain, 0.0)[0]
        assert chain.knuckle[1] - tip[1] == pytest.approx(0.1 * math.sin(tilt), abs=1e-15)
        assert tip[2] - chain.knuckle_depth == pytest.approx(0.1 * math.cos(tilt), abs=1e-15)


def test_capsules_are_post_proximal_distal():
    chain = straight_chain(tilt=0.2, q=(0.3, 0.3))
    caps = chain_capsules(chain, np.linspace(0, 1, 7))
    joints = chain_joints(chain, np.linspace(0, 1, 7))
    assert caps.shape == (7, 3, 2, 3)
    np.testing.assert_allclose(caps[:, 0, 0], np.tile([0.01, 0.02, 0.0], (7, 1)))  # post from the palm
    np.testing.assert_allclose(caps[:, 0, 1], joints[:, 0])
    np.testing.assert_allclose(caps[:, 1], joints[:, :2])
    np.testing.assert_allclose(caps[:, 2], joints[:, 1:])
    lengths = np.linalg.norm(caps[..., 1, :] - caps[..., 0, :], axis=-1)
    np.testing.assert_allclose(lengths, np.tile([0.005, 0.06, 0.04], (7, 1)), atol=1e-15)


@pytest.mark.parametrize("name", ["five-finger-linear", "three-finger"])
def test_presets_carry_chains_that_follow_their_rays(name):
    hand = load_hand(name)
    assert hand.is_3d and len(hand.chains) == len(hand.fingers)
    for finger, chain in zip(hand.fingers, hand.chains, strict=True):
        assert max(chain_deviation(finger, chain)) < 1e-9, finger.name  # the sim's chains: exact
        assert chain.radius == finger.radius


def test_the_curved_thumb_preset_is_a_2d_hand():
    assert not load_hand("five-finger-curved-thumb").is_3d


def shifted(chain, dx):
    return replace(chain, knuckle=(chain.knuckle[0] + dx[0], chain.knuckle[1] + dx[1]))


def test_a_chain_whose_open_tip_is_2_mm_off_is_refused_naming_the_finger():
    hand = load_hand("five-finger-linear")
    index = 1
    normal = np.array([-hand.chains[index].direction[1], hand.chains[index].direction[0]])
    chains = list(hand.chains)
    chains[index] = shifted(chains[index], 0.002 * normal)  # the whole path 2 mm beside the ray
    with pytest.raises(HandError, match=r"finger 'index': 3-D chain open tip is 2\.00 mm from the finger's start"):
        replace(hand, chains=tuple(chains))
    chains[index] = shifted(hand.chains[index], 0.0009 * normal)  # 0.9 mm: within the tolerance
    assert replace(hand, chains=tuple(chains)).is_3d


def overshooting(overshoot):
    """A ray finger along +y and a chain in its plane whose tip passes its end by ``overshoot`` and comes back.

    The proximal link hangs straight down (0.05 m), the distal one (0.05 m) swings from straight
    down through horizontal, where the tip is 0.05 m ahead, to theta > pi / 2, where it is
    0.05 sin(theta) = travel ahead: the path leaves the segment by 0.05 - travel beyond its end.
    """
    travel = 0.05 - overshoot
    theta = math.pi - math.asin(travel / 0.05)
    finger = Finger("f", start=(0.0, 0.0), trajectory=Ray((0.0, 1.0)), travel=travel, radius=0.008)
    chain = FingerChain(knuckle=(0.0, 0.0), knuckle_depth=0.0, direction=(0.0, 1.0), links=(0.05, 0.05),
                        radius=0.008, open_angles=(0.0, 0.0), closed_angles=(0.0, theta))
    return finger, chain


def test_a_chain_whose_path_leaves_the_ray_by_2_mm_is_refused():
    finger, chain = overshooting(0.002)
    open_, closed, path = chain_deviation(finger, chain)
    assert open_ < 1e-12 and closed < 1e-12  # both ends on the ray
    assert path == pytest.approx(0.002, abs=1e-5)
    with pytest.raises(HandError, match=r"finger 'f': 3-D chain: tip path leaves the finger's ray by 2\.00 mm"):
        check_chain(finger, chain)
    check_chain(*overshooting(0.0009))  # 0.9 mm: within the tolerance


def test_an_arc_finger_and_a_straight_chain_between_its_ends_differ_by_the_sagitta():
    # A planar chain's tip projects onto a line, so against an arc it strays by the arc's sagitta
    # even with both ends exactly on the arc: the path check (not the end checks) refuses it.
    arc = Arc(0.05, 0.05, 0.0)  # a circle of 5 cm: the tip moves from (0.05, 0) toward (0, 0.05)
    finger = Finger("thumb", start=(0.0, 0.0), trajectory=arc, travel=0.05 * 0.64, radius=0.0)
    end = finger.end
    d = end / np.linalg.norm(end)
    length = float(np.linalg.norm(end))
    # A chain whose tip slides along the chord: knuckle above the chord's middle, links equal, the
    # proximal link swinging symmetrically about the vertical.
    l = 0.05
    half = length / 2
    q = math.asin(half / (2 * l))
    chain = FingerChain(knuckle=tuple(d * half), knuckle_depth=0.0, direction=tuple(d), links=(l, l), radius=0.0,
                        open_angles=(-q, 0.0), closed_angles=(q, 0.0))
    open_, closed, path = chain_deviation(finger, chain)
    assert open_ < 1e-9 and closed < 1e-9
    sagitta = 0.05 * (1 - math.cos(0.32))  # the circle's bulge over the chord of 0.32 rad
    assert path == pytest.approx(sagitta, rel=0.02) and path > 2e-3
    with pytest.raises(HandError, match=r"finger 'thumb': 3-D chain: tip path leaves the finger's arc by"):
        check_chain(finger, chain)


def test_chain_and_palm_values_are_checked():
    with pytest.raises(HandError, match="chain links"):
        straight_chain(links=(0.06, 0.0))
    with pytest.raises(HandError, match="chain direction"):
        straight_chain(direction=(0.0, 0.0))
    with pytest.raises(HandError, match="open_angles"):
        straight_chain(open_angles=(4.0, 0.0))
    with pytest.raises(HandError, match="knuckle_depth"):
        straight_chain(knuckle_depth=-0.01)
    with pytest.raises(HandError, match="no area"):
        Palm(outline=((0, 0), (1e-3, 0), (2e-3, 0)), thickness=0.02)
    with pytest.raises(HandError, match="thickness"):
        Palm(outline=((0, 0), (0.1, 0), (0.1, 0.1)), thickness=0.0)
    hand = load_hand("five-finger-linear")
    with pytest.raises(HandError, match="both a chain for every finger and a palm"):
        replace(hand, palm=None)
    with pytest.raises(HandError, match="4 chains for 5 fingers"):
        replace(hand, chains=hand.chains[:4])
    with pytest.raises(HandError, match="radius"):
        replace(hand, chains=(replace(hand.chains[0], radius=0.02), *hand.chains[1:]))
