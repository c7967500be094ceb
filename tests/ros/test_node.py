"""The contourgrasp node over real rclpy and Fast DDS on localhost, fed the bundled bar-clamp frame by a second node."""

import itertools
import json
import signal
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

rclpy = pytest.importorskip("rclpy", reason="rclpy cannot be imported: install contourgrasp[ros] (make test does)")

from frames import EXAMPLE, FRAME_ID, bar_clamp, camera_info, image, spin_until  # noqa: E402  (isolates DDS first)

from geometry_msgs.msg import PoseStamped  # noqa: E402
from rcl_interfaces.msg import Log  # noqa: E402
from rclpy.executors import SingleThreadedExecutor  # noqa: E402
from rclpy.node import Node  # noqa: E402
from rclpy.parameter import Parameter  # noqa: E402
from sensor_msgs.msg import CameraInfo, Image  # noqa: E402
from std_srvs.srv import Trigger  # noqa: E402
from visualization_msgs.msg import MarkerArray  # noqa: E402

import contourgrasp  # noqa: E402
from contourgrasp.cli import main as contourgrasp_cli  # noqa: E402
from contourgrasp.errors import InputError  # noqa: E402
from contourgrasp.ros.messages import pose_matrix, stamp_seconds  # noqa: E402
from contourgrasp.ros.node import ContourGraspNode  # noqa: E402

TIMEOUT = 60.0
STAMPS = itertools.count(1000)


class Camera:
    """A second node: the camera driver's three topics, a client of ``~/plan`` and listeners of the node's outputs."""

    def __init__(self, context, executor, namespace="/"):
        self.executor = executor
        self.node = Node("camera", namespace=namespace, context=context)
        self.colour = self.node.create_publisher(Image, "color/image_raw", 5)
        self.depth = self.node.create_publisher(Image, "depth/image_raw", 5)
        self.info = self.node.create_publisher(CameraInfo, "color/camera_info", 5)
        self.client = self.node.create_client(Trigger, "contourgrasp/plan")
        self.received = {"grasp": [], "pregrasp": [], "markers": [], "log": []}
        for topic, kind in (("grasp", PoseStamped), ("pregrasp", PoseStamped), ("markers", MarkerArray)):
            self.node.create_subscription(kind, f"contourgrasp/{topic}", self.received[topic].append, 10)
        self.node.create_subscription(Log, "/rosout", self.received["log"].append, 100)
        executor.add_node(self.node)

    def send(self, node, colour, depth, info=None) -> float:
        """Publish ``info`` until ``node`` holds it, then the images until it has paired them; their stamp."""
        stamp = stamp_seconds(colour.header)
        if info is not None:
            self._until(lambda: self.info.publish(info), lambda: node.camera_info is not None and
                        list(node.camera_info.k) == list(info.k), "camera_info")
        self._until(lambda: (self.colour.publish(colour), self.depth.publish(depth)),
                    lambda: node.pairer.newest_stamp == stamp, f"frame of stamp {stamp}")
        return stamp

    def _until(self, publish, received, what: str) -> None:
        for _ in range(int(TIMEOUT / 0.25)):
            publish()
            if spin_until(self.executor, received, 0.25):
                return
        raise AssertionError(f"the node did not receive the {what} in {TIMEOUT} s")

    def call(self):
        assert self.client.wait_for_service(timeout_sec=TIMEOUT)
        future = self.client.call_async(Trigger.Request())
        assert spin_until(self.executor, future.done, TIMEOUT), "no answer from ~/plan"
        return future.result()

    def warnings(self, text: str) -> list[str]:
        return [m.msg for m in self.received["log"] if m.level == Log.WARN and text in m.msg]


@pytest.fixture(scope="module")
def ros():
    context = rclpy.Context()
    rclpy.init(context=context)
    executor = SingleThreadedExecutor(context=context)
    yield context, executor
    executor.shutdown(timeout_sec=5)
    context.try_shutdown()


@pytest.fixture(scope="module")
def reference():
    rgb, depth, intrinsics = bar_clamp()
    return contourgrasp.plan_grasp(rgb, depth, intrinsics, "five-finger-linear", planner="default", segment="auto",
                                   approach_offset=0.01, standoff=0.10, top_k=10)


def _started(ros, namespace="/", **overrides):
    context, executor = ros
    node = ContourGraspNode(context=context, namespace=namespace,
                            parameter_overrides=[Parameter(k, value=v) for k, v in overrides.items()])
    executor.add_node(node)
    return node, Camera(context, executor, namespace)


def _stopped(ros, node, camera):
    _, executor = ros
    for n in (node, camera.node):
        executor.remove_node(n)
        n.destroy_node()


@pytest.fixture(scope="module")
def rig(ros, reference):
    node, camera = _started(ros)
    yield node, camera
    _stopped(ros, node, camera)


def good_frame(stamp=None):
    rgb, depth, intrinsics = bar_clamp()
    stamp = next(STAMPS) + 0.25 if stamp is None else stamp
    return image(rgb, "rgb8", stamp), image(depth.astype(np.float32), "32FC1", stamp), camera_info(intrinsics)


def test_plan_answers_the_pose_and_json_of_plan_grasp_and_publishes_it(rig, reference, tmp_path):
    node, camera = rig
    stamp = camera.send(node, *good_frame())
    response = camera.call()
    assert response.success, response.message
    plan = json.loads(response.message)
    np.testing.assert_array_equal(plan["T_camera_hand"], reference.T_camera_hand)
    np.testing.assert_array_equal(plan["T_camera_pregrasp"], reference.T_camera_pregrasp)

    assert contourgrasp_cli(["plan", "--rgb", str(EXAMPLE / "color_0.png"), "--depth", str(EXAMPLE / "depth_0.npy"),
                             "--intrinsics", str(EXAMPLE / "primesense_overhead_color.intr"),
                             "--out", str(tmp_path / "plan.json")]) == 0
    written = json.loads((tmp_path / "plan.json").read_text())
    assert {k: v for k, v in plan.items() if k != "timing_ms"} == {k: v for k, v in written.items() if k != "timing_ms"}

    def published(topic):
        return [m for m in camera.received[topic]
                if stamp_seconds(m.header if topic != "markers" else m.markers[0].header) == stamp]

    assert spin_until(camera.executor, lambda: all(published(t) for t in ("grasp", "pregrasp", "markers")), TIMEOUT)
    for topic, T in (("grasp", reference.T_camera_hand), ("pregrasp", reference.T_camera_pregrasp)):
        pose = published(topic)[-1]
        assert pose.header.frame_id == FRAME_ID
        np.testing.assert_allclose(pose_matrix(pose.pose), T, atol=1e-12)
    markers = published("markers")[-1].markers
    assert {m.header.frame_id for m in markers} == {FRAME_ID}
    assert {m.ns for m in markers[1:]} == {"outline", "path", "start", "grasp"}
    assert camera.warnings("") == []


def _unknown_encoding(colour, depth, info):
    colour.encoding = "yuv422"
    return colour, depth, info


def _sizes_differ(colour, depth, info):
    _, d, _ = bar_clamp()
    return colour, image(d[::2, ::2].astype(np.float32), "32FC1", stamp_seconds(colour.header)), info


def _k_all_zero(colour, depth, info):
    info.k = np.zeros(9)
    return colour, depth, info


def _millimetres_in_32fc1(colour, depth, info):
    _, d, _ = bar_clamp()
    return colour, image((1000 * d).astype(np.float32), "32FC1", stamp_seconds(colour.header)), info


@pytest.mark.parametrize("spoil, reason", [
    (_unknown_encoding, "encoding 'yuv422'"),
    (_sizes_differ, "register depth to colour"),
    (_k_all_zero, "K is all zero"),
    (_millimetres_in_32fc1, "REP 118 wants meters in 32FC1"),
], ids=["unknown-encoding", "sizes-differ", "K-all-zero", "millimetres-in-32FC1"])
def test_a_bad_message_gives_one_warning_and_success_false_then_the_next_good_frame_plans(rig, reference, spoil,
                                                                                          reason):
    node, camera = rig
    camera.send(node, *spoil(*good_frame()))
    response = camera.call()
    assert not response.success
    assert reason in response.message and "\n" not in response.message
    assert spin_until(camera.executor, lambda: camera.warnings(reason), 10)
    assert len(camera.warnings(reason)) == 1

    camera.send(node, *good_frame())
    response = camera.call()
    assert response.success, response.message
    np.testing.assert_array_equal(json.loads(response.message)["T_camera_hand"], reference.T_camera_hand)


def test_the_node_plans_with_one_blas_thread_and_leaves_the_process_its_own(rig, monkeypatch):
    from threadpoolctl import threadpool_limits
    from conftest import blas_threads

    import contourgrasp.ros.node as node_module

    node, camera = rig
    during, plan_frame = [], node_module.plan_frame
    monkeypatch.setattr(node_module, "plan_frame", lambda *a, **k: during.append(blas_threads()) or plan_frame(*a, **k))
    with threadpool_limits(limits=2, user_api="blas"):
        assert blas_threads() == {2}
        camera.send(node, *good_frame())
        assert camera.call().success
        assert during == [{1}] and blas_threads() == {2}


def test_no_frame_until_a_colour_and_a_depth_image_pair_within_the_tolerance(ros):
    node, camera = _started(ros, "/fresh")
    try:
        response = camera.call()
        assert not response.success and response.message.startswith("no frame yet")
        colour, depth, info = good_frame()
        camera.info.publish(info)
        late = image(bar_clamp()[1].astype(np.float32), "32FC1", stamp_seconds(colour.header) + 0.5)
        for _ in range(5):
            camera.colour.publish(colour)
            camera.depth.publish(late)
            spin_until(camera.executor, lambda: False, 0.2)
        assert node.pairer.colour and node.pairer.depth and node.pairer.newest is None
        assert camera.call().message.startswith("no frame yet")
    finally:
        _stopped(ros, node, camera)


def test_continuous_plans_every_frame_without_a_call_and_keeps_the_last_latencies(ros, reference, monkeypatch):
    import contourgrasp.ros.node as node_module

    monkeypatch.setattr(node_module, "LATENCIES_KEPT", 1)
    node, camera = _started(ros, "/live", continuous=True)
    try:
        for _ in range(2):
            stamp = camera.send(node, *good_frame())
            assert spin_until(camera.executor, lambda: any(stamp_seconds(g.header) == stamp
                                                           for g in camera.received["grasp"]), TIMEOUT)
            grasp = [g for g in camera.received["grasp"] if stamp_seconds(g.header) == stamp][-1]
            np.testing.assert_allclose(pose_matrix(grasp.pose), reference.T_camera_hand, atol=1e-12)
        assert len(node.latencies_ms) == 1 and node.latencies_ms[0] > 0  # two planned, the last kept
    finally:
        _stopped(ros, node, camera)


def test_a_frame_stamped_far_ahead_does_not_freeze_the_plan_on_it(ros):
    """After a frame stamped 1e9 s (a clock jump), ~/plan plans the frame received since, not the old one: a bad
    current frame answers success false, and the jump is logged."""
    node, camera = _started(ros, "/jump")
    try:
        colour, depth, info = good_frame(stamp=1e9)
        camera.send(node, colour, depth, info)
        assert camera.call().success
        rgb, _, _ = bar_clamp()
        flat = np.zeros(rgb.shape[:2], np.float32)  # no reading: nothing to plan on
        camera.send(node, image(rgb, "rgb8", 500.0), image(flat, "32FC1", 500.0))
        answer = camera.call()
        assert not answer.success and "no valid reading" in answer.message
        assert spin_until(camera.executor, lambda: camera.warnings("stamps went back"), TIMEOUT)
    finally:
        _stopped(ros, node, camera)


@pytest.mark.parametrize("name, value", [("segment", "bogus"), ("hand", "no-such-hand"), ("standoff", -0.1),
                                         ("pair_tolerance", 0.0), ("top_k", 0), ("standoff", 1),
                                         ("harmonics", 100000), ("xy_step", 1e-9), ("yaw_step_deg", 1e-6),
                                         ("target", [1, 2, 3]), ("target", "centre"), ("approaches", "sideways"),
                                         ("approaches", "top+top")])
def test_an_invalid_parameter_is_refused_at_start_naming_it(ros, name, value):
    context, _ = ros
    with pytest.raises(InputError, match=f"^parameter {name}: "):
        ContourGraspNode(context=context, parameter_overrides=[Parameter(name, value=value)])


def _ros_command(*ros_args):
    return [sys.executable, "-m", "contourgrasp.cli", "ros", "--ros-args", *ros_args]


@pytest.mark.parametrize("ros_args, message", [
    (["-p", "segment:=bogus"], "parameter segment: must be one of 'auto', 'rgb', 'depth', got 'bogus'"),
    (["-p", "harmonics:=100000"], "parameter harmonics: must be at most 100, got 100000"),
    (["-p", "xy_step:=1e-9"], "parameter xy_step: the search grid would have"),
    (["-p", "bogus"], "contourgrasp: error: ROS arguments: failed to initialize rcl: Couldn't parse parameter"),
], ids=["refused-parameter", "too-many-harmonics", "too-fine-a-grid", "unparsable-argument"])
def test_the_ros_command_exits_2_with_one_line_for_bad_arguments(ros_args, message):
    done = subprocess.run(_ros_command(*ros_args), capture_output=True, text=True, timeout=TIMEOUT)
    assert done.returncode == 2
    assert message in done.stderr and "Traceback" not in done.stderr
    assert "deprecated" not in done.stderr  # third-party import warnings are not the user's business


def test_the_ros_command_serves_plan_and_stops_on_ctrl_c(ros):
    context, executor = ros
    process = subprocess.Popen(_ros_command("-r", "__ns:=/command"), stdout=subprocess.PIPE,
                               stderr=subprocess.PIPE, text=True)
    camera = Camera(context, executor, "/command")
    try:
        assert camera.call().message.startswith("no frame yet")
        process.send_signal(signal.SIGINT)
        code = process.wait(timeout=TIMEOUT)
        stderr = process.stderr.read()
        assert code == 0, stderr
        assert "Traceback" not in stderr
    finally:
        if process.poll() is None:
            process.kill()
            process.wait(timeout=TIMEOUT)
        process.stdout.close()
        process.stderr.close()
        executor.remove_node(camera.node)
        camera.node.destroy_node()


#: The node's ``main`` with a spin that, as rclpy's signal handler can on a Ctrl-C, finds the context shut down
#: between two waits (ros2/rclpy#398): the next wait set then raises RCLError.
RACING_CTRL_C = """
import sys, rclpy
from rclpy.executors import SingleThreadedExecutor
def spin(node):
    executor = SingleThreadedExecutor(context=node.context)
    executor.add_node(node)
    rclpy.shutdown(context=node.context)
    executor.spin_once()
rclpy.spin = spin
from contourgrasp.ros import node
sys.exit(node.main())
"""


def test_a_ctrl_c_that_shuts_the_context_down_mid_spin_still_exits_0():
    done = subprocess.run([sys.executable, "-c", RACING_CTRL_C], capture_output=True, text=True, timeout=TIMEOUT)
    assert done.returncode == 0, done.stderr
    assert "ready" in done.stderr and "Traceback" not in done.stderr


def test_the_ros_command_without_the_extra_says_install_it(monkeypatch, capsys):
    monkeypatch.setitem(sys.modules, "rclpy", None)
    monkeypatch.delitem(sys.modules, "contourgrasp.ros.node")
    assert contourgrasp_cli(["ros"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "pip install 'contourgrasp[ros]'" in err


def test_no_object_and_no_feasible_grasp_are_one_line_reasons(ros, tmp_path):
    default = (Path(contourgrasp.__file__).parent / "data" / "planners" / "default.toml").read_text()
    planner = tmp_path / "reach-2cm.toml"
    planner.write_text(default.replace('name = "default"', 'name = "reach-2cm"')
                       .replace("d_max = 0.15", "d_max = 0.02"))
    node, camera = _started(ros, "/odd", segment="depth", planner=str(planner))
    try:
        colour, depth, info = good_frame()
        camera.send(node, colour, depth, info)
        response = camera.call()
        assert not response.success and response.message.startswith("no feasible grasp: the object is too small or too far")
        d = bar_clamp()[1]
        flat = np.where(d > 0, np.median(d[d > 0]), 0).astype(np.float32)
        colour, _, _ = good_frame()
        camera.send(node, colour, image(flat, "32FC1", stamp_seconds(colour.header)))
        response = camera.call()
        assert not response.success and "no object found" in response.message and "\n" not in response.message
    finally:
        _stopped(ros, node, camera)


def _set_target(camera, namespace, value):
    """Set the node's ``target`` over DDS (its set_parameters service); the result."""
    from rcl_interfaces.srv import SetParameters

    client = camera.node.create_client(SetParameters, f"{namespace.rstrip('/')}/contourgrasp/set_parameters")
    try:
        assert client.wait_for_service(timeout_sec=TIMEOUT)
        request = SetParameters.Request(parameters=[Parameter("target", value=value).to_parameter_msg()])
        future = client.call_async(request)
        assert spin_until(camera.executor, future.done, TIMEOUT), "no answer from set_parameters"
        return future.result().results[0]
    finally:
        camera.node.destroy_client(client)


def test_the_target_parameter_picks_the_object_and_may_be_set_while_running(ros, reference):
    u, v = (int(x) for x in np.argwhere(reference.target.mask)[0][::-1])
    node, camera = _started(ros, "/aim", target=[u, v])
    try:
        colour, depth, info = good_frame()
        camera.send(node, colour, depth, info)
        response = camera.call()
        assert response.success
        data = json.loads(response.message)
        assert data["target"] == {"label": reference.target.label, "reason": f"the candidate under pixel ({u}, {v})"}
        np.testing.assert_allclose(data["T_camera_hand"], reference.T_camera_hand, atol=1e-9)
        assert _set_target(camera, "/aim", [320, 40]).successful
        response = camera.call()
        assert not response.success and response.message.startswith("no object at pixel (320, 40); the nearest")
        refused = _set_target(camera, "/aim", [5])
        assert not refused.successful and refused.reason.startswith("parameter target: must be a pixel [u, v]")
        assert _set_target(camera, "/aim", [-1, -1]).successful
        assert camera.call().success
    finally:
        _stopped(ros, node, camera)


def test_fuzz_the_parameters_give_settings_or_one_input_error():
    """Every parameter at absurd values of its own type (what ROS lets through): a Settings, or an InputError naming
    the parameter; never another exception."""
    from hypothesis import given, settings
    from hypothesis import strategies as st

    from contourgrasp.ros.node import PARAMETERS, settings_from_parameters

    absurd = {bool: st.booleans(), str: st.sampled_from(["", "bogus", "default", "paper", "three-finger", "max", "x" * 500]),
              int: st.sampled_from([-1, 0, 1, 3, 100, 100000, 10**18]),
              float: st.sampled_from([0.0, -0.1, 1e-9, 1e-300, 0.02, 1.0, 1e300, float("nan"), float("inf")]),
              list: st.sampled_from([[-1, -1], [1, 2], [1, 2, 3], [10**9, 1], []])}
    values = st.fixed_dictionaries({}, optional={name: absurd[type(default)]
                                                 for name, (default, _) in PARAMETERS.items()})

    @settings(max_examples=150, deadline=None)
    @given(values)
    def check(chosen):
        try:
            settings_from_parameters(chosen)
        except InputError as err:
            assert str(err).startswith("parameter ") and "\n" not in str(err)

    check()


def test_parameters_that_fit_alone_but_not_together_are_refused_naming_them():
    from contourgrasp.ros.node import settings_from_parameters

    with pytest.raises(InputError, match=r"^parameters .*xy_step, yaw_step_deg together: the search grid would have"):
        settings_from_parameters({"planner": "paper", "xy_step": 0.005, "yaw_step_deg": 1.0})
    assert settings_from_parameters({"planner": "paper", "xy_step": 0.005}).options.search.grid.xy_step == 0.005


def test_side_approaches_need_a_planner_that_checks_the_descent():
    from contourgrasp.ros.node import settings_from_parameters

    with pytest.raises(InputError, match=r"^parameter approaches: side and tilted approaches need a planner with descent"):
        settings_from_parameters({"planner": "paper", "approaches": "top+tilted"})
    assert settings_from_parameters({"approaches": "top+tilted"}).options.scene.approaches == "top+tilted"


def _call(camera, kind, service, request):
    client = camera.node.create_client(kind, service)
    try:
        assert client.wait_for_service(timeout_sec=TIMEOUT)
        future = client.call_async(request)
        assert spin_until(camera.executor, future.done, TIMEOUT), f"no answer from {service}"
        return future.result()
    finally:
        camera.node.destroy_client(client)


def test_a_failure_reported_is_avoided_by_the_next_plan_and_a_success_or_a_clear_forgets(ros, reference):
    from std_srvs.srv import SetBool

    from contourgrasp import tolerances as tol

    node, camera = _started(ros, "/memory")
    try:
        refused = _call(camera, SetBool, "/memory/contourgrasp/report_outcome", SetBool.Request(data=False))
        assert not refused.success and refused.message.startswith("no grasp published")
        colour, depth, info = good_frame()
        camera.send(node, colour, depth, info)
        first = json.loads(camera.call().message)
        failed = _call(camera, SetBool, "/memory/contourgrasp/report_outcome", SetBool.Request(data=False))
        assert failed.success and "avoid its 1 failed grasp(s)" in failed.message and len(node.memory) == 1
        second = json.loads(camera.call().message)
        step = np.subtract([second["pose"][k] for k in ("x", "y", "yaw")], [first["pose"][k] for k in ("x", "y", "yaw")])
        turn = abs((step[2] + np.pi) % (2 * np.pi) - np.pi)
        assert np.hypot(*step[:2]) > tol.MEMORY_REACH or turn > tol.MEMORY_TURN  # not the failed grasp again
        succeeded = _call(camera, SetBool, "/memory/contourgrasp/report_outcome", SetBool.Request(data=True))
        assert succeeded.success and len(node.memory) == 0
        camera.call()
        _call(camera, SetBool, "/memory/contourgrasp/report_outcome", SetBool.Request(data=False))
        cleared = _call(camera, Trigger, "/memory/contourgrasp/clear_memory", Trigger.Request())
        assert cleared.success and len(node.memory) == 0
        assert json.loads(camera.call().message)["pose"] == first["pose"]  # forgotten: the first plan again
    finally:
        _stopped(ros, node, camera)


def walled_frame():
    """A top-down frame (0.7 m to the table): a 40 px box between two 25 cm walls 2 px away, no grasp on it,
    and a free box in a corner; grey colour. (colour, depth, info) messages."""
    from contourgrasp.perception import Intrinsics

    depth = np.full((480, 640), 0.7, dtype=np.float32)
    for x, y, w, h, height in ((300, 220, 40, 40, 0.06), (150, 150, 148, 180, 0.25), (342, 150, 148, 180, 0.25),
                               (560, 40, 40, 40, 0.06)):
        depth[y:y + h, x:x + w] = 0.7 - height
    stamp = next(STAMPS) + 0.25
    intrinsics = Intrinsics(fx=525.0, fy=525.0, cx=319.5, cy=239.5, width=640, height=480)
    grey = np.full((480, 640, 3), 128, dtype=np.uint8)
    return image(grey, "rgb8", stamp), image(depth, "32FC1", stamp), camera_info(intrinsics)


def test_any_object_plans_the_next_object_where_the_one_chosen_has_no_grasp(ros):
    fast = dict(hand="three-finger", segment="depth", xy_step=0.03, yaw_step_deg=6.0)
    for namespace, any_object in (("/first", False), ("/any", True)):
        node, camera = _started(ros, namespace, any_object=any_object, **fast)
        try:
            colour, depth, info = walled_frame()
            camera.send(node, colour, depth, info)
            response = camera.call()
            if not any_object:
                assert not response.success and response.message.startswith("no feasible grasp")
                continue
            assert response.success, response.message
            assert json.loads(response.message)["target"]["reason"] == "the candidate under pixel (579, 59)"
        finally:
            _stopped(ros, node, camera)
