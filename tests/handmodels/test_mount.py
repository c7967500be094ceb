import warnings

import numpy as np
import pytest

from contourgrasp.handmodels.derive import MODELS
from contourgrasp.handmodels.lookup import geom_corners
from contourgrasp.handmodels.mount import PREFIX, mount_model
from contourgrasp.sim.objects import soda_can
from contourgrasp.sim.planners import make_planner
from contourgrasp.sim.scene import build_scene
from contourgrasp.sim.trial import HIT, STRUCK, Execution, execute_grasp, pose_matrix, run_trial


@pytest.fixture(scope="module")
def jaco():
    return mount_model("jaco-three-finger")


def tips_in_hand_frame(scene, name):
    position, rotation = scene.palm_pose()
    sites = [scene.model.site(PREFIX + tip).id for tip in MODELS[name].fingertips]
    return (scene.data.site_xpos[sites] - position) @ rotation


@pytest.mark.parametrize("name", ["jaco-three-finger", "inspire", "mpl"])
def test_mounted_model_opens_and_closes_on_its_derived_hand(name):
    mounted = mount_model(name)
    scene = build_scene("can", seed=0, hand=mounted)
    scene.set_hand(0.0, 0.0, 0.6, 0.0)
    scene.step(2.0)  # as the derivation, which settles the open hand for 2 s
    hand = mounted.hand
    np.testing.assert_allclose(tips_in_hand_frame(scene, name)[:, :2], hand.starts, atol=1e-3)
    nearest = np.full(len(hand.fingers), np.inf)
    for k in range(1, 751):  # the trials' closing: the synergy ramped over 1 s, then held
        scene.command([0.0, 0.0, 0.6, 0.0], min(1.0, k / 500))
        scene.step()
        nearest = np.minimum(nearest, np.linalg.norm(tips_in_hand_frame(scene, name)[:, :2] - hand.ends, axis=1))
    # every fingertip passes through its derived closed position: within 1 mm, or for an arc (fitted through the
    # path's first point) within twice its fit error, the start's offset from the ellipse and the ellipse's from the path
    fit_error = np.array([fit.error for fit in mounted.derivation.fits])
    assert np.all(nearest < np.maximum(1e-3, 2 * fit_error)), (nearest, fit_error)
    assert set(mounted.geom_names()) <= {scene.model.geom(g).name for g in range(scene.model.ngeom)}


def test_only_the_palm_s_subtree_is_mounted():
    """The MPL's palm hangs below its forearm and wrist bodies, which carry collision geoms: those stay out; the scene's
    settings rule (the model brings no conflicting option)."""
    mpl = mount_model("mpl")
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        scene = build_scene("can", seed=0, hand=mpl)
    m = scene.model
    bodies = {m.body(int(m.geom_bodyid[m.geom(name).id])).name.removeprefix(PREFIX) for name in mpl.geom_names()}
    assert "palm" in bodies and not bodies & {"forearm", "wristx", "wristy", "wristz"}
    assert len(mpl.geom_names()) == sum(1 for name in mpl.geom_names() if name.split("_")[0] in
                                        {"palm", "thumb", "index", "middle", "ring", "little"})


def test_a_trial_with_the_mounted_jaco_grasps_the_can(jaco):
    assert jaco.hand.max_imbalance == 1.0  # default plans the Jaco without the squeeze's balance (its own)
    planner = make_planner("default", jaco.hand, seed=0)
    record = run_trial("can", seed=0, planner=planner, hand=jaco)
    assert record.cause is None and set(record.fingers_in_contact) == {"thumb", "index", "pinky"}


def test_a_mounted_model_grasps_among_neighbours(jaco):
    """A clutter scene simulates the mounted model as a single object's scene does (it was refused, read as a file)."""
    planner = make_planner("default", jaco.hand, seed=0)
    records = [run_trial("can", seed=seed, planner=planner, hand=jaco, scene_kind="clutter", pool=("bottle", "case"))
               for seed in (0, 1)]
    assert [r.cause for r in records] == [HIT, None]  # seed 0's hand touches a neighbour: a failure, not a refusal
    assert set(records[1].fingers_in_contact) == {"thumb", "index", "pinky"}


def test_the_inspire_palm_below_its_frame_is_kept_clear_of_a_tall_object():
    # read level, the Inspire's palm reaches along its fingers below z = 0 (the thumb's knuckle): the trial's own
    # descent keeps that part, not z = 0, palm_clearance above the object's top (it struck a 12 cm can before)
    inspire = mount_model("inspire")
    scene = build_scene(soda_can(standing=True), seed=0, hand=inspire)
    scene.set_hand(0.0, 0.0, 0.6, 0.0)
    scene.step(0.01)
    origin = scene.palm_pose()[0]
    palm = [scene.model.geom(name).id for name in inspire.geom_names() if name.startswith("palm_")]
    corners = geom_corners(scene.model, scene.data, palm, np.zeros(3), np.eye(3))  # world frame
    deepest = corners[np.argmin(corners[:, 2])]
    assert origin[2] - deepest[2] == pytest.approx(inspire.palm_depth, abs=2e-3) and inspire.palm_depth > 0.04
    under = scene.camera.from_world(deepest)[:2] - scene.camera.from_world(origin)[:2]
    centre = scene.camera.from_world(scene.object_com())[:2]
    top = scene.camera.height - 0.12  # the can stands 12 cm tall, under the palm's deepest point
    outcome = execute_grasp(scene, pose_matrix(*(centre - under), 0.0, top), top)
    palm_height = scene.camera.height - outcome.palm_depth
    assert palm_height - inspire.palm_depth >= 0.12 + Execution().palm_clearance - 1e-6
    assert outcome.cause != STRUCK

