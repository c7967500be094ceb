from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from contourgrasp import tolerances as tol
from contourgrasp.errors import HandError, HandFileError
from contourgrasp.hand import Ray, SampledChain, chain_joints, chain_tip
from contourgrasp.io.hand_file import hand_to_toml, load_hand, parse_hand
from contourgrasp.sim.tendon_hand import build_hand
from contourgrasp.handmodels.derive import MODELS, derive_hand

#: Two fingers sliding straight in the palm plane: known rays (see the file).
TWO_SLIDERS = Path(__file__).parent / "fixtures" / "two-sliders.xml"


@pytest.fixture
def sliders():
    return TWO_SLIDERS


def own_hand_xml(tmp_path, preset="five-finger-linear"):
    """The MJCF of the simulated hand built from a preset, on its floating base (which the palm fixes)."""
    model = build_hand(load_hand(preset))
    path = tmp_path / f"{preset}.xml"
    path.write_text(f"""<mujoco><compiler angle="radian" autolimits="true"/>
<option timestep="0.002" integrator="implicitfast"/>
<worldbody>{model.body_xml()}</worldbody><tendon>{model.tendon_xml()}</tendon>
<actuator>{model.actuator_xml()}</actuator></mujoco>""")
    return path, model


def test_known_straight_slides_give_exactly_those_rays(sliders):
    derived = derive_hand(sliders, fingertips=["left_tip", "right_tip"])
    left, right = derived.hand.fingers
    np.testing.assert_allclose(left.start, [-0.05, 0.01], atol=1e-6)
    np.testing.assert_allclose(left.trajectory.closing_direction, [1.0, 0.0], atol=1e-6)
    assert left.travel == pytest.approx(0.04, abs=1e-6)
    np.testing.assert_allclose(right.start, [0.06, -0.02], atol=1e-6)
    np.testing.assert_allclose(right.trajectory.closing_direction, [-np.sqrt(0.5), np.sqrt(0.5)], atol=1e-6)
    assert right.travel == pytest.approx(0.03, abs=1e-6)
    assert [f.kind for f in derived.fits] == ["ray", "ray"] and max(f.error for f in derived.fits) < 1e-6
    assert left.radius == pytest.approx(0.008) and right.radius == pytest.approx(0.006)
    assert not derived.hand.is_3d and "hinge" in derived.notes[0]  # slides are no two-link chains


def test_own_simulated_hand_reproduces_the_preset_within_a_millimetre(tmp_path):
    path, model = own_hand_xml(tmp_path)
    preset = load_hand("five-finger-linear")
    derived = derive_hand(path, fingertips=[f"{f.name}_tip" for f in model.fingers], actuators=["flexion"],
                          palm="palm")
    assert derived.hand.is_3d
    for want, got, fit in zip(preset.fingers, derived.hand.fingers, derived.fits, strict=True):
        assert isinstance(got.trajectory, Ray) and fit.error < 1e-3
        assert np.linalg.norm(np.subtract(want.start, got.start)) < 1e-3
        assert np.linalg.norm(want.end - got.end) < 1e-3
        assert got.radius == pytest.approx(want.radius)
    for want, got in zip(preset.chains, derived.hand.chains, strict=True):
        np.testing.assert_allclose(got.knuckle, want.knuckle, atol=1e-6)
        np.testing.assert_allclose(got.links, want.links, atol=1e-6)
        np.testing.assert_allclose(got.open_angles, want.open_angles, atol=1e-3)
    # the thesis timing: the thumb closes first and fastest (lambda_virt about +34 mm, see calibrate)
    thumb = derived.hand.fingers[0]
    assert thumb.virtual_start > 0.02 and all(abs(f.virtual_start) < 0.01 for f in derived.hand.fingers[1:])
    assert parse_hand(hand_to_toml(derived.hand)) == derived.hand


def test_model_closing_measures_the_known_slides_along_their_rays(sliders):
    """Each slider's tip travels its ray from 0 to its full travel, never past it, and in time order."""
    from contourgrasp.handmodels.derive import record_closing, finger_travel, model_spec

    spec = model_spec(sliders, fingertips=["left_tip", "right_tip"])
    closing = finger_travel(derive_hand(sliders, fingertips=["left_tip", "right_tip"]).hand, record_closing(spec))
    np.testing.assert_allclose(closing.travel, [0.04, 0.03], atol=1e-6)
    np.testing.assert_allclose(closing.progress[:, 0], 0.0, atol=1e-6)
    np.testing.assert_allclose(closing.progress[:, -1], [0.04, 0.03], atol=1e-6)
    assert closing.times[0] == 0 and np.all(np.diff(closing.times) > 0)


def test_the_approach_axis_decides_the_palm_plane(sliders):
    # approaching along the palm's x, the left finger slides along the approach: it does not close
    with pytest.raises(HandError, match="finger 'left_tip': its tip moves 0.00 mm on the palm plane"):
        derive_hand(sliders, fingertips=["left_tip", "right_tip"], approach="x")
    flipped = derive_hand(sliders, fingertips=["left_tip", "right_tip"], approach="-z").hand.fingers[0]
    np.testing.assert_allclose(flipped.start, [-0.05, -0.01], atol=1e-6)  # x kept, y = z x x turned over
    with pytest.raises(HandFileError, match="approach must be one of x, -x"):
        derive_hand(sliders, fingertips=["left_tip", "right_tip"], approach="up")


def test_the_level_reading_brings_the_inspire_thumb_as_deep_as_its_fingers():
    from contourgrasp.handmodels.derive import LEVEL, record_closing, model_spec

    along = record_closing(replace(model_spec("inspire"), approach=None)).tips[:, 0, 2]  # open tips' depths, m
    assert along[1:].mean() - along[0] > 0.08  # along the fingers, the thumb's tip hangs a hand's width higher
    levelled = record_closing(model_spec("inspire"))
    assert model_spec("inspire").approach == LEVEL  # the bundled reading; "fingers" gives the one along the fingers
    assert model_spec("inspire", approach="fingers").approach is None
    depths = levelled.tips[:, 0, 2]
    assert depths[0] == pytest.approx(depths[1:].max(), abs=1e-6)  # as low as the lowest finger
    rotation = np.asarray(levelled.mount.rotation)
    np.testing.assert_allclose(rotation @ rotation.T, np.eye(3), atol=1e-12)
    assert np.linalg.det(rotation) == pytest.approx(1.0)
    # its fingers close on arcs, whose virtual starts come from the recorded closing as for rays
    hand = derive_hand("inspire").hand
    assert all(f.virtual_start > 0.005 for f in hand.fingers[1:]) and hand.fingers[0].virtual_start == 0.0


def test_level_keeps_a_hand_whose_tips_are_level_and_needs_two_fingers(sliders):
    fingers = ["left_tip", "right_tip"]
    level = derive_hand(sliders, fingertips=fingers, approach="level").hand
    along = derive_hand(sliders, fingertips=fingers, approach="fingers").hand
    np.testing.assert_allclose(level.starts, along.starts, atol=1e-9)  # the sliders' tips are equally deep
    from contourgrasp.handmodels.derive import _levelled

    with pytest.raises(HandFileError, match="needs two fingertips at least, got 1"):
        _levelled(np.eye(3), np.zeros((1, 3)), "one.xml")
    with pytest.raises(HandFileError, match="straight along the fingers"):  # thumb 5 cm above the others, along z
        _levelled(np.eye(3), np.array([[0.0, 0.0, 0.05], [0.0, 0.0, 0.1], [0.0, 0.0, 0.1]]), "tower.xml")


@pytest.mark.parametrize("name, fingers", [("inspire", 5), ("jaco-three-finger", 3), ("mpl", 5)])
def test_bundled_models_derive_hands_within_the_tolerance(name, fingers):
    derived = derive_hand(name)
    assert len(derived.hand.fingers) == fingers and derived.hand.name == name
    assert all(f.error <= tol.MODEL_FIT_TOLERANCE for f in derived.fits)
    ends = derived.hand.ends
    assert np.linalg.norm(ends - ends.mean(axis=0), axis=1).mean() < np.linalg.norm(
        derived.hand.starts - derived.hand.starts.mean(axis=0), axis=1).mean()  # closing brings the tips together


@pytest.mark.parametrize("name, hinges", [("inspire", [4, 2, 2, 2, 2]), ("jaco-three-finger", [2, 2, 2])])
def test_bundled_models_carry_their_chains_as_measured(name, hinges):
    derived = derive_hand(name)
    hand = derived.hand
    assert hand.is_3d and not derived.notes and all(isinstance(c, SampledChain) for c in hand.chains)
    assert [chain_joints(c, 0.0).shape[1] - 1 for c in hand.chains] == hinges  # a point per hinge, and the tip
    for finger, chain in zip(hand.fingers, hand.chains, strict=True):
        assert chain.radius == finger.radius
        np.testing.assert_allclose(chain_tip(chain, 0.0)[0, :2], finger.start, atol=1e-6)  # sampled from the open tip
    mount = derived.mount
    assert max(chain_tip(c, np.linspace(0, 1, 101))[:, 2].max() for c in hand.chains) == pytest.approx(
        mount.tip_depth, abs=5e-4)  # the measured tips go as deep as the model's
    assert max(hand.palm.depths or (0.0,)) == pytest.approx(mount.palm_depth, abs=1e-9)  # the palm box's deepest corner
    assert parse_hand(hand_to_toml(hand)) == hand


def test_the_inspire_palm_is_its_box_tilted_underside():
    palm = derive_hand("inspire").hand.palm
    a, b, c = palm.plane
    assert b > 0.9 and abs(c) < 0.1  # read level, the palm slopes down toward the fingers (about 48 degrees)
    assert min(palm.depths) < -0.02 and max(palm.depths) > 0.05


def test_a_derived_hand_carries_the_models_squeeze_balance_and_table_brushing(sliders):
    # closing in free air cannot measure them: the bundled models' are chosen on the bench, a file's are the defaults
    jaco, inspire = derive_hand("jaco-three-finger").hand, derive_hand("inspire").hand
    assert (jaco.max_imbalance, jaco.tips_brush_table) == (1.0, False)
    assert (inspire.max_imbalance, inspire.tips_brush_table) == (tol.HAND_MAX_IMBALANCE, True)
    assert (inspire.grasp_height_fraction, jaco.grasp_height_fraction) == (0.0, tol.GRASP_HEIGHT_FRACTION)
    assert (inspire.slice_contour, jaco.slice_contour) == (False, "unbalanced")
    assert not derive_hand(sliders, fingertips=["left_tip", "right_tip"]).hand.tips_brush_table
    mine = derive_hand(sliders, fingertips=["left_tip", "right_tip"], max_imbalance=0.5, tips_brush_table=True,
                       slice_contour=True).hand
    assert (mine.max_imbalance, mine.tips_brush_table, mine.slice_contour) == (0.5, True, True)
    with pytest.raises(HandError, match="max_imbalance must be at most 1"):
        derive_hand(sliders, fingertips=["left_tip", "right_tip"], max_imbalance=2.0)
    with pytest.raises(HandError, match="slice_contour must be one of"):
        derive_hand(sliders, fingertips=["left_tip", "right_tip"], slice_contour="sometimes")


def test_bad_models_are_refused_naming_what(sliders, tmp_path):
    with pytest.raises(HandFileError, match="no site or body named 'nose'"):
        derive_hand(sliders, fingertips=["left_tip", "nose"])
    with pytest.raises(HandError, match="fingertip 'right_tip' does not move"):
        derive_hand(sliders, fingertips=["left_tip", "right_tip"], actuators=["left_drive"])
    with pytest.raises(HandFileError, match="palm 'left_tip' is not a body \\(a site\\)"):
        derive_hand(sliders, fingertips=["left_tip", "right_tip"], palm="left_tip")
    with pytest.raises(HandFileError, match="no actuator named 'grip'"):
        derive_hand(sliders, fingertips=["left_tip"], actuators=["grip"])
    broken = tmp_path / "broken.xml"
    broken.write_bytes(b"\x00\xffnot xml")
    with pytest.raises(HandFileError, match="broken.xml: cannot load the MuJoCo model"):
        derive_hand(broken, fingertips=["tip"])
    with pytest.raises(HandFileError, match="name the fingertips"):
        derive_hand(sliders)
    with pytest.raises(HandError, match="hold_time"):
        derive_hand(sliders, fingertips=["left_tip", "right_tip"], hold_time=1e6)  # a bound on the simulation asked for
    assert set(MODELS) == {"inspire", "jaco-three-finger", "mpl"}


def test_a_pre_flexed_hand_opens_part_of_the_way():
    """open_from 0.5 starts the synergy halfway: the open controls halfway between the fully open and the closed ones,
    and the open fingertips where the fully open hand's pass halfway through its closing (within the closing's step)."""
    full, half = derive_hand("jaco-three-finger"), derive_hand(replace(MODELS["jaco-three-finger"], open_from=0.5))
    opened, closed = np.array(full.mount.open_controls), np.array(full.mount.closed_controls)
    np.testing.assert_allclose(half.mount.open_controls, opened + 0.5 * (closed - opened))
    np.testing.assert_allclose(half.mount.closed_controls, closed)
    assert all(h.travel < f.travel - 0.01 for h, f in zip(half.hand.fingers, full.hand.fingers))
    for bad in (-0.1, 1.0, float("nan")):
        with pytest.raises(HandError, match="open_from"):
            replace(MODELS["mpl"], open_from=bad)


def test_the_mpl_is_read_opposed_pre_flexed_and_unbalanced():
    derived = derive_hand("mpl")
    assert derived.hand.is_3d and not derived.notes and derived.hand.max_imbalance == 1.0
    assert dict(derived.mount.held) == {"A_thumb_ABD": pytest.approx(2.1)}  # its ctrlrange's top: opposed


def test_our_simulated_hand_is_not_built_from_measured_chains():
    from contourgrasp.errors import SimulationError

    with pytest.raises(SimulationError, match=r"finger .thumb. has a measured chain .*\(bench --hand-model\)"):
        build_hand(derive_hand("jaco-three-finger").hand)


def test_the_fit_table_says_which_chains_are_measured():
    from contourgrasp.handmodels.derive import fit_table

    assert fit_table(derive_hand("jaco-three-finger"))[-1] == (
        "3-D chains and palm: yes (as measured: thumb, index, pinky, the palm tilted)")



@pytest.mark.parametrize("options, message", [
    ({"fingertips": 3}, "fingertips must be a list of names, got 3"),
    ({"fingertips": "thumb_tip"}, "fingertips must be a list of names, got 'thumb_tip'"),
    ({"actuators": [1, 2]}, "actuators must be a list of names"),
    ({"palm": 3}, "palm must be a body's name, got 3"),
    ({"close_time": 10**400}, "close_time must be a finite number"),
])
def test_bad_arguments_are_hand_errors_naming_them(options, message):
    from contourgrasp.errors import HandError

    with pytest.raises(HandError, match=message):
        derive_hand("inspire", **options)


def test_a_model_of_thousands_of_bodies_is_refused_before_it_is_closed(tmp_path):
    from contourgrasp.errors import HandFileError

    bodies = "".join(f'<body name="b{i}" pos="{0.01 * i} 0 0"><joint name="j{i}"/><geom size="0.005"/></body>'
                     for i in range(2000))
    path = tmp_path / "many.xml"
    path.write_text(f'<mujoco><worldbody><body name="palm"><geom size="0.01"/>{bodies}</body></worldbody></mujoco>')
    with pytest.raises(HandFileError, match="many.xml: 2002 bodies, more than a hand model has"):
        derive_hand(path, fingertips=["b1", "b2"])


def test_every_bundled_model_file_and_its_licence_is_installed_with_the_package():
    import fnmatch
    import tomllib

    root = Path(__file__).resolve().parents[2]
    patterns = tomllib.loads((root / "pyproject.toml").read_text())["tool"]["setuptools"]["package-data"]["contourgrasp"]
    package = root / "src" / "contourgrasp"
    files = [p.relative_to(package).as_posix() for p in (package / "data" / "models").rglob("*") if p.is_file()
             and "__pycache__" not in p.parts]
    assert "data/models/mpl/LICENSE" in files
    assert [f for f in files if not any(fnmatch.fnmatchcase(f, pattern) for pattern in patterns)] == []
