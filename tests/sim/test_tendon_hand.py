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


# --- one truth: the simulated hand is the hand file's chains and palm ---

from dataclasses import replace  # noqa: E402
from pathlib import Path  # noqa: E402

import mujoco  # noqa: E402

from contourgrasp.hand import chain_tip  # noqa: E402
from contourgrasp.sim.tendon_hand import HandDesign, derive_body  # noqa: E402

FIXTURES = Path(__file__).parent / "fixtures"

#: The simulated hand as build_hand made it before the hand files carried chains (commit 0ad15b2):
#: its MJCF (body, tendon, actuators: fixtures/hand-<preset>.xml) and its tip depth.
OLD_TIP_DEPTH = {"five-finger-linear": 0.12031993868144564, "three-finger": 0.10695105660572947}


def hand_mjcf(model) -> str:
    return model.body_xml() + "\n" + model.tendon_xml() + "\n" + model.actuator_xml()


@pytest.mark.parametrize("name", sorted(OLD_TIP_DEPTH))
def test_the_sim_hand_from_the_file_is_the_one_built_before(name):
    hand = contourgrasp.load_hand(name)
    assert hand.is_3d
    model = build_hand(hand)
    assert hand_mjcf(model) == (FIXTURES / f"hand-{name}.xml").read_text()
    assert model.tip_depth == OLD_TIP_DEPTH[name]
    # and the 2-D part alone, given its body by the rule, is the same hand
    assert hand_mjcf(build_hand(replace(hand, chains=None, palm=None))) == hand_mjcf(model)


@pytest.mark.parametrize("name", sorted(OLD_TIP_DEPTH))
def test_compiled_model_numbers_match_the_old_hand(name):
    # The MJCF text is compared above; here the compiled numbers of both, to 1e-9.
    def compiled(xml_body):
        xml = f"""<mujoco><compiler angle="radian" autolimits="true"/><worldbody>{xml_body}</worldbody>
        <tendon>{model.tendon_xml()}</tendon><actuator>{model.actuator_xml()}</actuator></mujoco>"""
        return mujoco.MjModel.from_xml_string(xml)
    model = build_hand(contourgrasp.load_hand(name))
    old_body = (FIXTURES / f"hand-{name}.xml").read_text().split("\n<fixed")[0]
    new, old = compiled(model.body_xml()), compiled(old_body)
    for field in ("body_pos", "body_quat", "body_mass", "geom_size", "geom_pos", "geom_quat", "jnt_range",
                  "jnt_stiffness", "qpos_spring", "jnt_axis", "site_pos"):
        np.testing.assert_allclose(getattr(new, field), getattr(old, field), atol=1e-9, err_msg=field)


def test_radii_lengths_and_knuckles_come_from_the_file():
    hand = contourgrasp.load_hand("five-finger-linear")
    chains = list(hand.chains)
    fingers = list(hand.fingers)
    # a thicker index finger: the file's radius is both the planner's disc and the sim's capsule
    fingers[1] = replace(fingers[1], radius=0.012)
    chains[1] = replace(chains[1], radius=0.012)
    model = build_hand(replace(hand, fingers=tuple(fingers), chains=tuple(chains)))
    index = model.fingers[1]
    assert index.radius == 0.012 and index.lengths == hand.chains[1].links
    np.testing.assert_array_equal(index.knuckle, hand.chains[1].knuckle)
    assert 'name="index_proximal" type="capsule" fromto="0 0 0 0 0 0.055" size="0.012"' in model.body_xml()
    assert "finger_radius" not in HandDesign.__dataclass_fields__
    assert "thumb_radius" not in HandDesign.__dataclass_fields__


def test_the_issue_diagnosis_of_the_open_fingers():
    # fingers lean 18.0 deg, the thumb 24.6 deg; knuckles 31 mm (thumb 51 mm) inward of the
    # tips; links 55 + 45 mm (thumb 67 + 55 mm); radius 9 mm (11 mm).
    model = build_hand(HAND)
    for f in model.fingers:
        thumb = f.name == "thumb"
        assert np.degrees(f.tilt) == pytest.approx(24.6 if thumb else 18.0, abs=0.05)
        inward = (f.knuckle - np.asarray(f.start)) @ np.asarray(f.direction)
        assert 1000 * inward == pytest.approx(51 if thumb else 31, abs=0.5)
        assert inward == pytest.approx(sum(f.lengths) * np.sin(f.tilt), abs=1e-12)
        assert np.round(1000 * np.array(f.lengths)).tolist() == ([67, 55] if thumb else [55, 45])
        assert f.radius == (0.011 if thumb else 0.009)
        # the chain's open tip is the MJCF tip site of the open pose: check through the file's chain
        np.testing.assert_allclose(chain_tip(f.chain, 0.0)[0, :2], f.start, atol=1e-12)


def test_a_2d_hand_needs_radii_for_the_simulation():
    hand = replace(HAND, chains=None, palm=None)
    thin = replace(hand, fingers=tuple(replace(f, radius=0.0) for f in hand.fingers))
    with pytest.raises(contourgrasp.InputError, match="radius 0"):
        build_hand(thin)
    assert derive_body(hand) == HAND


def test_a_palm_that_is_not_a_rectangle_is_refused_by_the_sim():
    from contourgrasp.hand import Palm
    pts = HAND.palm.points
    skew = Palm(outline=tuple(map(tuple, pts[:3])), thickness=HAND.palm.thickness)  # a triangle
    with pytest.raises(contourgrasp.InputError, match="axis-aligned rectangle"):
        build_hand(replace(HAND, palm=skew))


def test_the_presets_chains_are_what_the_tool_derives():
    import importlib.util
    path = Path(__file__).parents[2] / "tools" / "derive_hand_chains.py"
    spec = importlib.util.spec_from_file_location("derive_hand_chains", path)
    tool = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(tool)
    assert tool.main(["--check"]) == 0
