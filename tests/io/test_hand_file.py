import dataclasses
import math
import re

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import contourgrasp as cg
from contourgrasp import HandFileError
from contourgrasp.hand import Finger, FingerChain, Hand, Ray, SampledChain, chain_joints, chain_tip
from contourgrasp.io.hand_file import hand_to_toml, load_hand, parse_hand, preset_names

GOOD = """
name = "pinch"
min_touching = 2
[[fingers]]
name = "left"
start = [-0.06, 0.0]
closing_direction = [1.0, 0.0]
travel = 0.05
alpha = 10.0
beta = 1000.0
[[fingers]]
name = "right"
start = [0.06, 0.0]
closing_direction = [-1.0, 0.0]
travel = 0.05
alpha = 10.0
beta = 1000.0
"""


def test_a_hand_file_plans_grasps(tmp_path):
    path = tmp_path / "pinch.toml"
    path.write_text(GOOD)
    hand = load_hand(path)
    assert hand.name == "pinch" and [f.name for f in hand.fingers] == ["left", "right"]
    assert hand.miss_penalty == pytest.approx(100.0)  # 10 x the largest alpha
    plan = cg.synthesize(cg.example_contour("ellipse") * 0.8, path, yaw_step=math.radians(10))
    assert not any(f.missed for f in plan.fingers)


@pytest.mark.parametrize(
    "edit, message",
    [
        (("travel = 0.05", "travel = 0.0", 1), r"fingers\[0\] \(left\)\.travel: Input should be greater than 0"),
        (("closing_direction = [1.0, 0.0]", "closing_direction = [0.0, 0.0]", 1), r"fingers\[0\] \(left\): closing_direction has zero length"),
        (("alpha = 10.0", "alpha = 10.0\ncolour = 3", 1), r"fingers\[0\] \(left\)\.colour: unknown key"),
        (("travel = 0.05", 'travel = "far"', 1), r"travel: Input should be a valid number"),
        (("min_touching = 2", "min_touching = 3", 1), r"min_touching = 3 exceeds the 2 fingers"),
        (('name = "pinch"\n', "", 1), r"name: required field is missing"),
        (("start = [-0.06, 0.0]", "start = [-0.06]", 1), r"start: List should have at least 2 items"),
        (("closing_direction = [1.0, 0.0]", "closing_direction = [1.0, 0.0]\narc = {a_cos = 0.05, a_sin = 0.04, phi_off = 0.0}", 1), "exactly one of"),
        (("beta = 1000.0", "beta = -1.0", 1), r"beta: Input should be greater than or equal to 0"),
        (("[[fingers]]", "[[fingers", 1), "not valid TOML"),
        (("min_touching = 2", "min_touching = 2\ntips_brush_table = 1", 1),
         r"tips_brush_table: Input should be a valid boolean"),
        (("min_touching = 2", "min_touching = 2\ngrasp_height_fraction = 0.9", 1),
         r"grasp_height_fraction: Input should be less than or equal to 0.7"),
        (("min_touching = 2", 'min_touching = 2\nslice_contour = "hand"', 1),
         r"slice_contour: must be true, false or \"unbalanced\", got 'hand'"),
    ],
)
def test_hand_file_errors_name_the_file_and_the_field(tmp_path, edit, message):
    old, new, count = edit
    path = tmp_path / "bad.toml"
    path.write_text(GOOD.replace(old, new, count))
    with pytest.raises(HandFileError, match=rf"^{path}: .*{message}"):
        load_hand(path)


def test_unknown_hand_and_missing_file():
    with pytest.raises(HandFileError, match="unknown hand 'six-finger'"):
        load_hand("six-finger")
    with pytest.raises(HandFileError, match="cannot read hand file"):
        load_hand("/nonexistent/hand.toml")


def test_parse_hand_source_name():
    with pytest.raises(HandFileError, match="^mine: "):
        parse_hand("name = 3", source="mine")


def test_presets_have_the_table_values():
    hand = load_hand("five-finger-linear")
    thumb = hand.fingers[0]
    assert thumb.trajectory.closing_direction == pytest.approx((0.994, 0.106), abs=1e-3)
    assert (thumb.travel, thumb.virtual_start, thumb.alpha, thumb.beta, thumb.required) == (0.09, 0.03, 25.0, 1e4, True)
    assert [f.virtual_start for f in hand.fingers] == [0.03, 0.0, 0.0, 0.01, 0.01]
    three = load_hand("three-finger")
    assert [f.beta for f in three.fingers] == [5e4] * 3 and three.min_touching == 3


@pytest.mark.parametrize("name", preset_names())
def test_hand_to_toml_round_trips(name):
    hand = load_hand(name)
    again = parse_hand(hand_to_toml(hand, comment="a\nb"))
    assert (again.name, again.min_touching, again.miss_penalty, again.max_imbalance, again.tips_brush_table,
            again.grasp_height_fraction, again.slice_contour) == (
        hand.name, hand.min_touching, hand.miss_penalty, hand.max_imbalance, hand.tips_brush_table,
        hand.grasp_height_fraction, hand.slice_contour)
    text = hand_to_toml(hand)
    assert "grasp_height_fraction" not in text and "slice_contour" not in text  # the defaults: the files as they were
    lower = parse_hand(hand_to_toml(dataclasses.replace(hand, grasp_height_fraction=0.0)))
    assert lower.grasp_height_fraction == 0.0
    for slicing in (False, True):
        assert parse_hand(hand_to_toml(dataclasses.replace(hand, slice_contour=slicing))).slice_contour is slicing
    for f, g in zip(hand.fingers, again.fingers, strict=True):
        assert (g.name, g.start, g.travel, g.virtual_start, g.alpha, g.beta, g.required) == (
            f.name, f.start, f.travel, f.virtual_start, f.alpha, f.beta, f.required)
        np.testing.assert_allclose(g.points([0.0, 0.01]), f.points([0.0, 0.01]), atol=1e-15)
    assert (again.chains, again.palm) == (hand.chains, hand.palm)  # the 3-D body exactly (None for a 2-D hand)


def test_hand_to_toml_escapes_names():
    finger = Finger(name='the "odd" one\\ ä\x7f', start=(0.0, 0.0), trajectory=Ray((0.0, 1.0)), travel=0.05)
    hand = Hand(name="x\ny", fingers=(finger,), min_touching=1, description="tab\there")
    again = parse_hand(hand_to_toml(hand))
    assert (again.name, again.fingers[0].name, again.description) == (hand.name, finger.name, hand.description)


ONE_FINGER = """name = "h"
min_touching = 1

[[fingers]]
name = "left"
start = [-0.08, 0.0]
closing_direction = [1.0, 0.0]
travel = 0.1
"""


@pytest.mark.parametrize("line, field", [("virtual_start = 1e300", "fingers[0] (left).virtual_start"),
                                         ("radius = 1e300", "fingers[0] (left).radius"),
                                         ("alpha = -1e300", "fingers[0] (left).alpha"),
                                         ("beta = 1e300", "fingers[0] (left).beta")])
def test_absurd_magnitudes_are_refused_naming_the_field(tmp_path, line, field):
    """virtual_start = 1e300 was once accepted and wrote Infinity into the plan JSON."""
    path = tmp_path / "hand.toml"
    path.write_text(ONE_FINGER + line + "\n")
    with pytest.raises(HandFileError, match=f"hand.toml: {re.escape(field)}: .*(less|greater) than or equal"):
        load_hand(path)


@pytest.mark.parametrize("old, new, field", [("start = [-0.08, 0.0]", "start = [1e300, 0.0]", "start"),
                                             ("travel = 0.1", "travel = 1e300", "travel"),
                                             ('closing_direction = [1.0, 0.0]',
                                              "arc = { a_cos = 0.05, a_sin = 0.04, phi_off = 1e300 }", "phi_off"),
                                             ('closing_direction = [1.0, 0.0]',
                                              "arc = { a_cos = 1e300, a_sin = 0.04, phi_off = 0.0 }", "a_cos"),
                                             ('closing_direction = [1.0, 0.0]',
                                              "arc = { a_cos = 0.05, a_sin = 0.0, phi_off = 0.0 }", "a_sin"),
                                             ('closing_direction = [1.0, 0.0]',
                                              "arc = { a_cos = 0.05, a_sin = -1e300, phi_off = 0.0 }", "a_sin")])
def test_absurd_lengths_and_angles_are_refused_naming_the_field(old, new, field):
    """A start of 1e300 or an arc phi_off of 1e300 once divided by zero in the search's kernels."""
    with pytest.raises(HandFileError, match=f"fingers\\[0\\] \\(left\\).*{field}"):
        parse_hand(ONE_FINGER.replace(old, new), source="hand.toml")


def test_a_clockwise_arc_finger_round_trips():
    hand = parse_hand(ONE_FINGER.replace("closing_direction = [1.0, 0.0]",
                                         "arc = { a_cos = 0.05, a_sin = -0.04, phi_off = 1.0 }"))
    assert hand.fingers[0].trajectory.a_sin == -0.04
    again = parse_hand(hand_to_toml(hand))
    np.testing.assert_array_equal(again.fingers[0].points(np.linspace(0, 0.1, 5)), hand.fingers[0].points(np.linspace(0, 0.1, 5)))


@pytest.mark.parametrize("content", [bytes(range(256)), "name = 'h'".encode("utf-16"), b"\xff\xfe\x00"])
def test_a_binary_or_utf16_file_is_one_hand_file_error_naming_it(tmp_path, content):
    path = tmp_path / "hand.toml"
    path.write_bytes(content)
    with pytest.raises(HandFileError, match=f"{re.escape(str(path))}: cannot read hand file \\(not UTF-8"):
        load_hand(path)


def test_deeply_nested_toml_is_one_hand_file_error():
    with pytest.raises(HandFileError, match="hand.toml: not valid TOML"):
        parse_hand("x = " + "[" * 100_000 + "]" * 100_000, source="hand.toml")


@settings(max_examples=100, deadline=None)
@given(content=st.one_of(st.binary(max_size=300), st.text(max_size=300).map(str.encode),
                         st.sampled_from([ONE_FINGER.encode(), ONE_FINGER.encode("utf-16")]),
                         st.builds(lambda cut, junk: ONE_FINGER.encode()[:cut] + junk, st.integers(0, 150),
                                   st.binary(max_size=20))))
def test_fuzz_load_hand_on_random_bytes_gives_a_hand_or_a_hand_file_error(tmp_path_factory, content):
    path = tmp_path_factory.mktemp("fuzz") / "hand.toml"
    path.write_bytes(content)
    try:
        hand = load_hand(path)
    except HandFileError as err:
        assert str(err).startswith(str(path)) and "\n" not in str(err)
        return
    assert np.all(np.isfinite(hand.starts))


# --- the 3-D body: [fingers.chain] and [palm] ---

PINCH_3D = GOOD.replace("""beta = 1000.0
[[fingers]]""", """beta = 1000.0
radius = 0.008
[fingers.chain]
knuckle = [-0.06, 0.0]
knuckle_depth = 0.01
links = [0.05, 0.05]
open_angles = [0.0, 0.0]
closed_angles = [0.0, 1.5707963267948966]
[[fingers]]""") + """radius = 0.008
[fingers.chain]
knuckle = [0.06, 0.0]
knuckle_depth = 0.01
links = [0.05, 0.05]
open_angles = [0.0, 0.0]
closed_angles = [0.0, 1.5707963267948966]
[palm]
outline = [[-0.08, -0.02], [0.08, -0.02], [0.08, 0.02], [-0.08, 0.02]]
thickness = 0.02
"""
# Each finger of GOOD with a body: the proximal link straight down below its open tip, the distal
# swinging from straight down to horizontal (pi / 2), which brings the tip the travel, 0.05 m, ahead.


def test_a_3d_hand_file_loads_its_chains_and_palm(tmp_path):
    path = tmp_path / "pinch3d.toml"
    path.write_text(PINCH_3D)
    hand = load_hand(path)
    assert hand.is_3d and [c.knuckle for c in hand.chains] == [(-0.06, 0.0), (0.06, 0.0)]
    assert hand.chains[0].direction == (1.0, 0.0) and hand.chains[1].direction == (-1.0, 0.0)  # the rays'
    assert [c.radius for c in hand.chains] == [0.008, 0.008]  # the finger's radius
    assert hand.palm.thickness == 0.02 and len(hand.palm.outline) == 4
    assert parse_hand(hand_to_toml(hand)) == hand


@pytest.mark.parametrize(
    "old, new, message",
    [
        ("links = [0.05, 0.05]", "links = [0.05, -0.05]", r"fingers\[0\] \(left\)\.chain\.links\[1\]: Input should be greater than 0"),
        ("knuckle_depth = 0.01", "knuckle_depth = -0.01", r"fingers\[0\] \(left\)\.chain\.knuckle_depth"),
        ("knuckle_depth = 0.01", "knuckle_depth = 0.01\nlength = 3", r"fingers\[0\] \(left\)\.chain\.length: unknown key"),
        ("open_angles = [0.0, 0.0]", "open_angles = [0.0]", r"fingers\[0\] \(left\)\.chain\.open_angles: List should have at least 2 items"),
        ("thickness = 0.02", "thickness = 0.0", r"palm\.thickness: Input should be greater than 0"),
        ("outline = [[-0.08, -0.02], [0.08, -0.02], [0.08, 0.02], [-0.08, 0.02]]", "outline = [[0.0, 0.0], [0.1, 0.0]]",
         r"palm\.outline: List should have at least 3 items"),
        ("knuckle = [-0.06, 0.0]", "knuckle = [-0.062, 0.0]",
         r"fingers\[0\] \(left\)\.chain: finger 'left': 3-D chain open tip is 2\.00 mm from the finger's start"),
        ("knuckle = [0.06, 0.0]", "knuckle = [0.06, 0.002]",
         r"fingers\[1\] \(right\)\.chain: finger 'right': 3-D chain open tip is 2\.00 mm"),
    ],
)
def test_3d_hand_file_errors_name_the_file_and_the_field(tmp_path, old, new, message):
    assert old in PINCH_3D
    path = tmp_path / "bad.toml"
    path.write_text(PINCH_3D.replace(old, new, 1))
    with pytest.raises(HandFileError, match=re.escape(str(path)) + ": " + message):
        load_hand(path)


def measured_pinch():
    """PINCH_3D with its left finger's chain as measured (joints) and its palm tilted (vertices with z)."""
    planar = parse_hand(PINCH_3D)
    joints = chain_joints(planar.chains[0], np.linspace(0.0, 1.0, 5)).round(6).tolist()
    left = PINCH_3D[PINCH_3D.index("[fingers.chain]"):PINCH_3D.index("[[fingers]]", PINCH_3D.index("[fingers.chain]"))]
    text = PINCH_3D.replace(left, f"[fingers.chain]\njoints = {joints}\n", 1)
    return text.replace("outline = [[-0.08, -0.02], [0.08, -0.02], [0.08, 0.02], [-0.08, 0.02]]",
                        "outline = [[-0.08, -0.02, 0.0], [0.08, -0.02, 0.016], [0.08, 0.02, 0.016], [-0.08, 0.02, 0.0]]")


def test_a_measured_chain_and_a_tilted_palm_load_and_round_trip():
    hand = parse_hand(measured_pinch())
    assert isinstance(hand.chains[0], SampledChain) and isinstance(hand.chains[1], FingerChain)
    np.testing.assert_allclose(chain_tip(hand.chains[0], [0.0, 0.5, 1.0]),
                               chain_tip(parse_hand(PINCH_3D).chains[0], [0.0, 0.5, 1.0]), atol=1e-6)
    np.testing.assert_allclose(hand.palm.plane, [0.008, 0.1, 0.0], atol=1e-12)
    assert parse_hand(hand_to_toml(hand)) == hand


@pytest.mark.parametrize(
    "old, new, message",
    [
        ("joints = ", "knuckle = [-0.06, 0.0]\njoints = ",
         r"fingers\[0\] \(left\)\.chain: give either joints \(a measured chain\) or the planar chain's keys, not both"),
        ("joints = [[", "joints = [[[0.0, 0.0, 0.0], ", r"fingers\[0\] \(left\)\.chain: every sample of joints must have"),
        ("joints = [[", "joints = [[[0.0, 0.0]], [", r"fingers\[0\] \(left\)\.chain\.joints\[0\]\[0\]: List should have at least 3"),
        ("0.016], [0.08, 0.02, 0.016]", "0.016], [0.08, 0.02, 0.026]", r"palm: palm outline's vertices are 2\.50 mm off one plane"),
    ],
)
def test_measured_chain_and_tilted_palm_errors_name_the_field(old, new, message):
    text = measured_pinch()
    assert old in text
    with pytest.raises(HandFileError, match=r"<string>: " + message):
        parse_hand(text.replace(old, new, 1))


def test_a_planar_chain_missing_a_key_says_which():
    with pytest.raises(HandFileError, match=r"fingers\[0\] \(left\)\.chain: a planar chain needs .*missing: links"):
        parse_hand(PINCH_3D.replace("links = [0.05, 0.05]\n", "", 1))


def test_a_3d_hand_needs_every_chain_and_the_palm():
    with pytest.raises(HandFileError, match=r"hand: a 3-D hand needs .* missing: \[palm\]"):
        parse_hand(PINCH_3D.split("[palm]")[0])
    right_chain = PINCH_3D.index("[fingers.chain]\nknuckle = [0.06")
    text = PINCH_3D[:right_chain] + PINCH_3D[PINCH_3D.index("[palm]"):]
    assert text.count("[fingers.chain]") == 1
    with pytest.raises(HandFileError, match=r"missing: \[fingers\.chain\] of right"):
        parse_hand(text)


def test_an_arc_finger_chain_needs_its_direction():
    hand = load_hand("five-finger-curved-thumb")
    text = hand_to_toml(hand).replace("radius = 0.011\n", "radius = 0.011\n[fingers.chain]\nknuckle = [-0.1, 0.1]\n"
                                      "knuckle_depth = 0.0\nlinks = [0.06, 0.05]\nopen_angles = [0.0, 0.0]\n"
                                      "closed_angles = [0.5, 0.5]\n", 1)
    with pytest.raises(HandFileError, match=r"fingers\[0\] \(thumb\): chain.direction is required for a finger on an arc"):
        parse_hand(text)


def test_a_2d_hand_file_plans_with_a_note(tmp_path):
    path = tmp_path / "pinch.toml"
    path.write_text(GOOD)
    plan = cg.synthesize(cg.example_contour("ellipse") * 0.8, path, yaw_step=math.radians(10))
    assert len(plan.notes) == 1 and "no 3-D geometry" in plan.notes[0] and "'pinch'" in plan.notes[0]
    from contourgrasp.io.plan_file import plan_to_dict
    assert plan_to_dict(plan)["notes"] == list(plan.notes)
    three_d = tmp_path / "pinch3d.toml"
    three_d.write_text(PINCH_3D)
    plan = cg.synthesize(cg.example_contour("ellipse") * 0.8, three_d, yaw_step=math.radians(10))
    assert plan.notes == () and plan_to_dict(plan)["notes"] == []
