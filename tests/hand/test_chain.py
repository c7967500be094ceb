"""The 3-D hand: chain kinematics against trigonometry, the presets' chains against their rays, refusals."""

import math
from dataclasses import replace

import numpy as np
import pytest

from contourgrasp import Arc, Finger, Ray, load_hand
from contourgrasp.errors import HandError
from contourgrasp.hand import (
    FingerChain,
    Palm,
    SampledChain,
    chain_capsules,
    chain_deviation,
    chain_joints,
    chain_tip,
    check_chain,
    link_names,
)


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


def sampled_from(chain, m=41):
    """The planar chain's joints measured at m evenly spaced closing progresses, as a SampledChain."""
    return SampledChain(joints=chain_joints(chain, np.linspace(0.0, 1.0, m)), radius=chain.radius)


def test_a_sampled_chain_is_its_samples_and_linear_between_them():
    planar = straight_chain(tilt=0.3, q=(0.2, 0.5))
    sampled = sampled_from(planar, m=5)
    at = np.array([0.0, 0.25, 0.5, 1.0])
    np.testing.assert_allclose(chain_joints(sampled, at), chain_joints(planar, at), atol=1e-15)
    halfway = chain_joints(sampled, 0.125)[0]
    np.testing.assert_allclose(halfway, chain_joints(planar, [0.0, 0.25]).mean(axis=0), atol=1e-15)
    np.testing.assert_allclose(chain_joints(sampled, [-1.0, 2.0]), chain_joints(planar, [0.0, 1.0]), atol=1e-15)
    np.testing.assert_allclose(chain_capsules(sampled, at), chain_capsules(planar, at), atol=1e-15)
    assert link_names(planar) == link_names(sampled) == ("post", "proximal", "distal")


def test_a_sampled_chain_of_four_hinges_is_a_post_and_four_links():
    joints = [[[0.0, 0.0, 0.01 * k] for k in range(5)], [[0.0, 0.002 * k, 0.01 * k] for k in range(5)]]
    chain = SampledChain(joints=joints, radius=0.005)
    capsules = chain_capsules(chain, 1.0)[0]
    assert capsules.shape == (5, 2, 3) and link_names(chain) == ("post", "link 1", "link 2", "link 3", "link 4")
    np.testing.assert_allclose(capsules[0], [[0.0, 0.0, 0.0], [0.0, 0.0, 0.0]])  # the knuckle is on the palm
    np.testing.assert_allclose(chain_tip(chain, 1.0)[0], [0.0, 0.008, 0.04])


def test_a_sampled_chain_is_checked_against_its_trajectory_within_the_fit_tolerance():
    planar = straight_chain()
    tip = chain_tip(planar, [0.0, 1.0])[:, :2]
    finger = Finger(name="index", start=tuple(tip[0]), trajectory=Ray((0.0, -1.0)), travel=0.03, radius=0.008)
    line = np.c_[np.full(41, tip[0, 0]), tip[0, 1] - np.linspace(0, 0.03, 41), np.full(41, 0.1)]
    knuckle = np.tile([tip[0, 0], tip[0, 1] + 0.05, 0.0], (41, 1))
    bowed = line + np.c_[0.0025 * np.sin(np.linspace(0, np.pi, 41)), np.zeros((41, 2))]  # 2.5 mm off the ray
    check_chain(finger, SampledChain(joints=np.stack([knuckle, bowed], axis=1), radius=0.008))  # within 3 mm
    too_far = line + np.c_[0.0035 * np.sin(np.linspace(0, np.pi, 41)), np.zeros((41, 2))]
    with pytest.raises(HandError, match=r"finger 'index': 3-D chain: tip path leaves the finger's ray by 3.50 mm"):
        check_chain(finger, SampledChain(joints=np.stack([knuckle, too_far], axis=1), radius=0.008))


def test_sampled_chain_values_are_checked():
    with pytest.raises(HandError, match="2..201 samples of 2..8"):
        SampledChain(joints=[[[0, 0, 0.01], [0, 0, 0.05]]], radius=0.005)
    with pytest.raises(HandError, match="2..201 samples of 2..8"):
        SampledChain(joints=np.zeros((2, 9, 3)), radius=0.005)
    with pytest.raises(HandError, match="finite"):
        SampledChain(joints=[[[0, 0, np.nan], [0, 0, 0.05]]] * 2, radius=0.005)
    with pytest.raises(HandError, match="joints"):
        SampledChain(joints=[[[0, 0, 3.0], [0, 0, 0.05]]] * 2, radius=0.005)
    with pytest.raises(HandError, match="radius"):
        SampledChain(joints=[[[0, 0, 0.01], [0, 0, 0.05]]] * 2, radius=-0.005)


def test_a_tilted_palm_is_the_plane_through_its_vertices():
    palm = Palm(outline=((0, 0, 0.01), (0.1, 0, 0.03), (0.1, 0.1, 0.05), (0, 0.1, 0.03)), thickness=0.02)
    np.testing.assert_allclose(palm.plane, [0.01, 0.2, 0.2], atol=1e-15)
    assert palm.outline == ((0, 0), (0.1, 0), (0.1, 0.1), (0, 0.1)) and palm.depths == (0.01, 0.03, 0.05, 0.03)
    assert Palm(outline=((0, 0, 0), (0.1, 0, 0), (0.1, 0.1, 0)), thickness=0.02).depths is None  # flat at z = 0
    with pytest.raises(HandError, match="0.50 mm off one plane"):
        Palm(outline=((0, 0), (0.1, 0), (0.1, 0.1), (0, 0.1)), thickness=0.02, depths=(0, 0, 0, 0.002))
    with pytest.raises(HandError, match="one finite number per outline vertex"):
        Palm(outline=((0, 0), (0.1, 0), (0.1, 0.1)), thickness=0.02, depths=(0, 0))
    with pytest.raises(HandError, match="depths given twice"):
        Palm(outline=((0, 0, 0), (0.1, 0, 0), (0.1, 0.1, 0)), thickness=0.02, depths=(0, 0, 0))
