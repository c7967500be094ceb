"""The parts of a hand model found by name (contourgrasp.handmodels.lookup), on a small model whose answers are known."""

import mujoco
import numpy as np
import pytest

from contourgrasp.errors import HandFileError
from contourgrasp.handmodels import lookup as parts

#: A palm on a free base (an arm's stand-in) with two two-hinge fingers; the right tip is a box, the left a ball.
HAND = """<mujoco>
  <compiler angle="radian"/>
  <worldbody>
    <body name="base">
      <freejoint/>
      <geom name="base_box" type="box" size="0.02 0.02 0.02" mass="1"/>
      <body name="palm" pos="0 0 0.1">
        <geom name="plate" type="box" size="0.04 0.03 0.005" euler="0 0 0.5"/>
        <body name="left_proximal" pos="-0.03 0 0">
          <joint name="left_1" type="hinge" axis="0 1 0"/>
          <geom type="capsule" fromto="0 0 0 0 0 -0.04" size="0.007"/>
          <body name="left_distal" pos="0 0 -0.04">
            <joint name="left_2" type="hinge" axis="0 1 0"/>
            <geom name="left_ball" type="sphere" size="0.008" pos="0 0 -0.03"/>
            <site name="left_tip" pos="0 0 -0.03"/>
          </body>
        </body>
        <body name="right_proximal" pos="0.03 0 0">
          <joint name="right_1" type="hinge" axis="0 1 0"/>
          <geom type="capsule" fromto="0 0 0 0 0 -0.04" size="0.007"/>
          <body name="right_distal" pos="0 0 -0.04">
            <joint name="right_2" type="hinge" axis="0 1 0"/>
            <geom name="right_pad" type="box" size="0.005 0.01 0.02" pos="0 0 -0.02"/>
          </body>
        </body>
      </body>
    </body>
  </worldbody>
  <actuator>
    <motor name="left_drive" joint="left_1" ctrlrange="-1 1"/>
    <motor name="right_drive" joint="right_1" ctrlrange="-1 1"/>
    <motor name="free_drive" joint="right_2"/>
  </actuator>
</mujoco>"""


@pytest.fixture(scope="module")
def model():
    return mujoco.MjModel.from_xml_string(HAND)


def _body(m, name):
    return m.body(name).id


def test_the_palm_is_the_deepest_body_holding_every_fingertip(model):
    palm = parts.palm_body(model, None, ("left_tip", "right_distal"), "hand.xml")
    assert palm == _body(model, "palm")  # not the base, which holds them too
    assert parts.palm_body(model, "base", ("left_tip",), "hand.xml") == _body(model, "base")
    with pytest.raises(HandFileError, match="hand.xml: palm 'left_ball' is not a body \\(a geom\\)"):
        parts.palm_body(model, "left_ball", ("left_tip",), "hand.xml")


def test_the_subtree_holds_the_fingers_not_the_base(model):
    names = {model.body(b).name for b in parts.subtree(model, _body(model, "palm"))}
    assert names == {"palm", "left_proximal", "left_distal", "right_proximal", "right_distal"}


def test_a_fingertip_is_a_site_or_a_body_on_the_palm(model):
    subtree = parts.subtree(model, _body(model, "palm"))
    assert parts.fingertip(model, "left_tip", subtree, "hand.xml") == ("site", model.site("left_tip").id)
    assert parts.fingertip(model, "right_distal", subtree, "hand.xml") == ("body", _body(model, "right_distal"))
    with pytest.raises(HandFileError, match="'base' is not on a finger of the palm body"):
        parts.fingertip(model, "base", subtree, "hand.xml")


def test_a_fingers_hinges_run_from_the_palm_to_its_tip(model):
    tip = ("site", model.site("left_tip").id)
    assert [model.joint(j).name for j in parts.moving_path(model, tip, _body(model, "palm"))] == ["left_1", "left_2"]


def test_the_tip_radius_is_half_the_tip_geoms_smallest_extent(model):
    collides = np.ones(model.ngeom, bool)
    assert parts.tip_radius(model, ("site", model.site("left_tip").id), collides) == pytest.approx(0.008)
    assert parts.tip_radius(model, ("body", _body(model, "right_distal")), collides) == pytest.approx(0.005)
    assert parts.tip_radius(model, ("body", _body(model, "right_distal")), np.zeros(model.ngeom, bool)) == 0.0


def test_actuators_are_the_hands_with_a_control_range(model):
    subtree = parts.subtree(model, _body(model, "palm"))
    named = parts.actuators(model, ("left_drive", "right_drive"), subtree, "hand.xml")
    assert [model.actuator(a).name for a in named] == ["left_drive", "right_drive"]
    with pytest.raises(HandFileError, match="'free_drive' has no control range"):
        parts.actuators(model, None, subtree, "hand.xml")  # all on the hand, one of them without a range
    with pytest.raises(HandFileError, match="no actuator named 'grip' \\(the model's: left_drive, right_drive"):
        parts.actuators(model, ("grip",), subtree, "hand.xml")
    assert parts.held_controls(model, (("right_drive", 0.75),), subtree, "hand.xml") == [(1, pytest.approx(0.5))]


def test_geom_corners_are_the_box_turned_and_placed(model):
    data = mujoco.MjData(model)
    mujoco.mj_forward(model, data)
    plate = model.geom("plate").id
    corners = parts.geom_corners(model, data, [plate], data.xpos[_body(model, "palm")], np.eye(3))
    c, s = np.cos(0.5), np.sin(0.5)
    signs = np.array([[sx, sy, sz] for sx in (-1, 1) for sy in (-1, 1) for sz in (-1, 1)])
    half = np.array([[0.04, 0.03, 0.005]]) * signs
    expected = half @ np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]]).T
    assert sorted(map(tuple, np.round(corners, 9))) == sorted(map(tuple, np.round(expected, 9)))
