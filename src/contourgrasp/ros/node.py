"""The ``contourgrasp`` ROS 2 node: plans a grasp on the camera's paired colour and depth images.

Subscribes (remappable) ``color/image_raw`` (rgb8, bgr8, rgba8, bgra8, mono8),
``depth/image_raw`` (16UC1 millimetres or 32FC1 meters, registered to the
colour image) and ``color/camera_info``. Colour and depth are paired by stamp
within ``pair_tolerance`` seconds; a frame without a pair is not planned on.

Serves ``~/plan`` (std_srvs/Trigger): plans on the newest pair and answers the
plan JSON of ``contourgrasp plan``, or success false with the one-line reason.
The node keeps a memory of failed grasps per object of its scene
(:class:`~contourgrasp.synthesis.SceneMemory`: each object's found again by where the camera sees it), which
every plan of that object avoids: ``~/report_outcome`` (std_srvs/SetBool) tells it how the last grasp
published went -- ``data`` false: it failed, and is remembered on its object, in the object's frame;
true: it succeeded, the object is gone and its memory forgotten -- and ``~/clear_memory``
(std_srvs/Trigger) clears every object's (a new scene).
With ``continuous`` it plans every pair as it arrives. Parameter ``target``
([u, v], a pixel of the depth image; ``[-1, -1]`` for the default rule of
:func:`contourgrasp.perception.choose_target`) names the object to plan on;
unlike the others it may be set while the node runs (``ros2 param set
/contourgrasp target "[320, 240]"``, e.g. from a click), and is checked when set. Each plan publishes
``~/grasp`` and ``~/pregrasp`` (geometry_msgs/PoseStamped: T_camera_hand and
T_camera_pregrasp in the image's frame, at its stamp) and ``~/markers``
(visualization_msgs/MarkerArray), and logs one line with its time.
"""

from __future__ import annotations

import json
import math
import signal
import time
import warnings
from collections import deque
from dataclasses import dataclass, replace

import rclpy
from geometry_msgs.msg import PoseStamped
from rcl_interfaces.msg import ParameterDescriptor, SetParametersResult
from rclpy.exceptions import InvalidParameterTypeException
from rclpy.executors import ExternalShutdownException
from rclpy.node import Node
from rclpy.qos import HistoryPolicy, QoSProfile, ReliabilityPolicy
from sensor_msgs.msg import CameraInfo, Image
from std_srvs.srv import SetBool, Trigger
from visualization_msgs.msg import MarkerArray

from ..errors import InputError, NoFeasibleGrasp
from ..hand import Hand
from ..io.hand_file import load_hand
from ..io.plan_file import image_plan_to_dict
from ..io.planner_file import Planner, load_planner
from ..picking import plan_any
from ..pipeline import PlanOptions, approaches_supported, plan_frame
from ..synthesis import SceneMemory
from ..threads import one_blas_thread
from ..validation import with_options
from . import messages
from .pairing import PAIR_TOLERANCE, Pairer

#: The options' defaults, which the parameters' defaults are.
DEFAULTS = PlanOptions()
#: QoS of the subscriptions: best effort (it receives from reliable publishers too), a queue of one, so that a
#: node busy planning goes on with the newest images rather than falling behind the camera.
NEWEST = QoSProfile(depth=1, history=HistoryPolicy.KEEP_LAST, reliability=ReliabilityPolicy.BEST_EFFORT)

DEPTH_MODE_CHOICES = ("", "max", "plane")

#: The node's parameters: name -> (default, description). Read once at start (read-only).
PARAMETERS = {
    "hand": ("five-finger-linear", "hand preset name or hand TOML file"),
    "planner": ("default", "planner preset name or planner TOML file"),
    "segment": (DEFAULTS.perception.segment, "segmentation: auto, rgb or depth"),
    "approach_offset": (DEFAULTS.perception.approach_offset, "added to the nearest depth inside the contour, m"),
    "standoff": (DEFAULTS.standoff, "pre-grasp distance back along the approach axis, m"),
    "pair_tolerance": (PAIR_TOLERANCE, "largest stamp difference of a colour and a depth image paired, s"),
    "continuous": (False, "plan every paired frame, not only on ~/plan"),
    "harmonics": (0, "EFD harmonics; 0: the planner's"),
    "xy_step": (0.0, "grid step in x and y, m; 0: the planner's"),
    "yaw_step_deg": (0.0, "grid step in yaw, degrees; 0: the planner's"),
    "depth_mode": ("", "contour plane: max or plane; empty: the planner's"),
    "approaches": ("", "approach kinds chosen among, joined by '+': top, side, tilted; empty: the planner's"),
    "top_k": (DEFAULTS.search.top_k, "ranked distinct poses in the plan JSON"),
    "target": ([-1, -1], "pixel [u, v] of the depth image: plan on the object under it; [-1, -1]: the default rule"),
    "any_object": (False, "with no target: where the object chosen has no feasible grasp, plan on the next one the "
                          "hand spans (a bin, a table to clear; those a grasp failed on last)"),
}

#: Parameters that may be set while the node runs (checked by ``target_pixel`` when set).
WRITABLE = ("target",)
NO_TARGET = (-1, -1)


@dataclass(frozen=True)
class Settings:
    """The node's validated parameters: the hand, the planner, the options planned with (the planner's, with the
    node's parameters put in), the target pixel (None: the default rule) and whether, without one, the next object
    is planned where the one chosen has no feasible grasp (:func:`~contourgrasp.picking.plan_any`)."""

    hand: Hand
    planner: Planner
    pair_tolerance: float
    continuous: bool
    options: PlanOptions = DEFAULTS
    target_px: tuple[int, int] | None = None
    any_object: bool = False


def settings_from_parameters(values: dict) -> Settings:
    """Validate the parameters' values (``PARAMETERS``' names); :class:`InputError` names the one refused."""
    v = {name: default for name, (default, _) in PARAMETERS.items()} | values
    hand = _loaded("hand", load_hand, v["hand"])
    planner = _loaded("planner", load_planner, v["planner"])
    _require(v["depth_mode"] in DEPTH_MODE_CHOICES, "depth_mode", "must be max, plane or empty", v)
    for name in ("xy_step", "yaw_step_deg"):
        _require(math.isfinite(v[name]) and v[name] >= 0, name, "must be a finite number >= 0 (0: the planner's)", v)
    _require(math.isfinite(v["pair_tolerance"]) and v["pair_tolerance"] > 0, "pair_tolerance",
             "must be a positive time in s", v)
    _require(v["harmonics"] >= 0, "harmonics", "must be an integer >= 0 (0: the planner's)", v)
    overrides = {"harmonics": v["harmonics"], "xy_step": v["xy_step"], "yaw_step": math.radians(v["yaw_step_deg"]),
                 "depth_mode": v["depth_mode"], "approaches": v["approaches"]}
    given = {"segment": v["segment"], "approach_offset": v["approach_offset"], "standoff": v["standoff"],
             "top_k": v["top_k"]} | {name: value for name, value in overrides.items() if value}
    for name, value in given.items():  # one at a time, so that the message names the parameter refused
        try:
            with_options(planner.options, {name: value}, what="parameters", error=InputError)
        except InputError as err:
            parameter = PARAMETER_OF.get(name, name)
            raise InputError(f"parameter {parameter}: {str(err).removeprefix(name + ' ')}") from None
    try:
        options = with_options(planner.options, given, what="parameters", error=InputError)
    except InputError as err:  # each one fits, not all of them together (a grid too large)
        raise InputError(f"parameters {', '.join(PARAMETER_OF.get(n, n) for n in given)} together: {err}") from None
    _require(approaches_supported(hand, options.scene), "approaches",
             "side and tilted approaches need a planner with descent and a 3-D hand", v)
    return Settings(hand, planner, v["pair_tolerance"], v["continuous"], options, target_pixel(v["target"]),
                    v["any_object"])


#: The parameter that sets an option, where their names differ.
PARAMETER_OF = {"yaw_step": "yaw_step_deg"}


def target_pixel(value) -> tuple[int, int] | None:
    """The ``target`` parameter's value as a pixel (u, v), or None for ``[-1, -1]``; :class:`InputError` names it."""
    pixel = tuple(int(x) for x in value)
    if pixel == NO_TARGET:
        return None
    if len(pixel) != 2 or min(pixel) < 0:
        raise InputError(f"parameter target: must be a pixel [u, v] >= 0, or [-1, -1] for the default rule, "
                         f"got {list(pixel)}")
    return pixel


def _loaded(name: str, load, value):
    try:
        return load(value)
    except InputError as err:
        raise InputError(f"parameter {name}: {err}") from None


def _require(ok: bool, name: str, what: str, values: dict) -> None:
    if not ok:
        raise InputError(f"parameter {name}: {what}, got {values[name]!r}")


#: Plans whose latency the node keeps (``latencies_ms``): a node running for days must not grow.
LATENCIES_KEPT = 10_000


class ContourGraspNode(Node):
    """The ``contourgrasp`` node (module docstring); ``kwargs`` go to :class:`rclpy.node.Node`.

    Attributes
    ----------
    settings : Settings
    latencies_ms : deque of float
        Per plan published, the last ``LATENCIES_KEPT``: time from the message that completed the frame
        (continuous) or the service call to the poses published, ms.
    memory : SceneMemory
        The scene's failed grasps, per object (module docstring).
    last : ImageGraspPlan or None
        The last plan published, which ``~/report_outcome`` is about.

    Raises
    ------
    InputError
        A parameter refused (logged as an error first; the node is destroyed).
    """

    def __init__(self, **kwargs):
        super().__init__("contourgrasp", **kwargs)
        try:
            self.settings = settings_from_parameters(self._declared_values())
        except InputError as err:
            self.get_logger().error(str(err))
            self.destroy_node()
            raise
        self.pairer = Pairer(self.settings.pair_tolerance)
        self.camera_info = None
        self.latencies_ms: deque[float] = deque(maxlen=LATENCIES_KEPT)
        self._subscribe()
        self.grasp_publisher = self.create_publisher(PoseStamped, "~/grasp", 10)
        self.pregrasp_publisher = self.create_publisher(PoseStamped, "~/pregrasp", 10)
        self.markers_publisher = self.create_publisher(MarkerArray, "~/markers", 10)
        self.memory, self.last = SceneMemory(), None
        self.create_service(Trigger, "~/plan", self._on_plan)
        self.create_service(SetBool, "~/report_outcome", self._on_report_outcome)
        self.create_service(Trigger, "~/clear_memory", self._on_clear_memory)
        self.add_on_set_parameters_callback(self._on_set_parameters)
        self.get_logger().info(
            f"ready: hand {self.settings.hand.name}, planner {self.settings.planner.name}, "
            f"{'continuous' if self.settings.continuous else 'on ~/plan'}; colour, depth, camera_info from "
            f"{', '.join(s.topic_name for s in self.subscriptions)}")

    def _declared_values(self) -> dict:
        values = {}
        for name, (default, description) in PARAMETERS.items():
            try:
                parameter = self.declare_parameter(name, default, ParameterDescriptor(
                    description=description, read_only=name not in WRITABLE))
            except InvalidParameterTypeException:
                kind = {bool: "a bool", int: "an integer", float: "a double (write 1.0, not 1)", str: "a string",
                        list: "an integer array [u, v]"}
                raise InputError(f"parameter {name}: must be {kind[type(default)]}") from None
            values[name] = parameter.value
        return values

    def _on_set_parameters(self, parameters):
        """Check a new ``target`` (the only parameter not read-only) and take it for the next plans."""
        target_px = self.settings.target_px
        for parameter in (p for p in parameters if p.name in WRITABLE):
            try:
                target_px = target_pixel(parameter.value)
            except InputError as err:  # ROS itself refuses a value that is not an integer array
                return SetParametersResult(successful=False, reason=str(err))
        self.settings = replace(self.settings, target_px=target_px)
        return SetParametersResult(successful=True)

    def _subscribe(self) -> None:
        self.create_subscription(Image, "color/image_raw", self._on_colour, NEWEST)
        self.create_subscription(Image, "depth/image_raw", self._on_depth, NEWEST)
        self.create_subscription(CameraInfo, "color/camera_info", self._on_camera_info, NEWEST)

    def _on_colour(self, msg) -> None:
        received = time.perf_counter()
        self._on_pair(self.pairer.add_colour(messages.stamp_seconds(msg.header), msg), received)

    def _on_depth(self, msg) -> None:
        received = time.perf_counter()
        self._on_pair(self.pairer.add_depth(messages.stamp_seconds(msg.header), msg), received)

    def _on_camera_info(self, msg) -> None:
        self.camera_info = msg

    def _on_pair(self, pair, received: float) -> None:
        if self.pairer.jumped is not None:
            self.get_logger().warning(f"the images' stamps went back {self.pairer.jumped:.3f} s (a clock jump?): "
                                      f"planning on the frame stamped {self.pairer.newest_stamp:.3f} from now on")
        if pair is not None and self.settings.continuous:
            self.plan(pair, received)

    def _on_plan(self, _request, response):
        started = time.perf_counter()
        if self.pairer.newest is None:
            response.success, response.message = False, (
                f"no frame yet: no colour and depth image paired within {self.settings.pair_tolerance} s")
        else:
            response.success, response.message = self.plan(self.pairer.newest, started)
        return response

    def _on_report_outcome(self, request, response):
        """The last grasp published failed (``data`` false: remembered on its object) or succeeded (true: its object's
        memory forgotten)."""
        if self.last is None:
            response.success, response.message = False, "no grasp published since the memory was last cleared"
        elif request.data:
            self.memory, self.last = self.memory.without(self.last.seen), None
            response.success, response.message = True, "the grasp succeeded: its object's failed grasps are forgotten"
        else:
            seen = self.last.seen
            self.memory = self.memory.with_failure(seen, self.last.metric.contour_xy, self.last.plan.pose,
                                                   approach=self.last.approach)
            self.last = None  # reported once
            response.success, response.message = True, (
                f"the grasp failed: remembered on its object; its next plans avoid its {len(self.memory.of(seen))} "
                f"failed grasp(s)")
        self.get_logger().info(response.message)
        return response

    def _on_clear_memory(self, _request, response):
        self.memory, self.last = SceneMemory(), None
        response.success, response.message = True, "the memory of failed grasps is cleared"
        self.get_logger().info(response.message)
        return response

    def plan(self, pair, started: float) -> tuple[bool, str]:
        """Plan on a (colour, depth) pair and publish; (True, plan JSON) or (False, the reason, logged)."""
        colour, depth = pair
        stamp = messages.stamp_seconds(colour.header)
        try:
            result = self._planned(colour, depth)
        except (InputError, NoFeasibleGrasp) as err:
            reason = f"no feasible grasp: {err.reason}" if isinstance(err, NoFeasibleGrasp) else str(err)
            self.get_logger().warning(f"frame {stamp:.3f}: {reason}")
            return False, reason
        except Exception as err:  # a bug: reported, and the node goes on with the next frame
            reason = f"internal error (please report): {type(err).__name__}: {err}"
            self.get_logger().error(f"frame {stamp:.3f}: {reason}")
            return False, reason
        self.last = result
        self.grasp_publisher.publish(messages.pose_stamped(result.T_camera_hand, colour.header))
        self.pregrasp_publisher.publish(messages.pose_stamped(result.T_camera_pregrasp, colour.header))
        self.markers_publisher.publish(messages.plan_markers(result, colour.header))
        elapsed = 1e3 * (time.perf_counter() - started)
        self.latencies_ms.append(elapsed)
        self.get_logger().info(f"frame {stamp:.3f}: {messages.plan_summary(result)}; pose published "
                               f"{elapsed:.0f} ms after the frame")
        return True, json.dumps(image_plan_to_dict(result), indent=2)

    def _planned(self, colour, depth):
        if self.camera_info is None:
            raise InputError("no camera_info received yet")
        # limited while planning only: the node may share its process
        with warnings.catch_warnings(record=True) as caught, one_blas_thread():
            warnings.simplefilter("always")
            rgb, d, intrinsics = messages.rgbd_arrays(colour, depth, self.camera_info)
            if self.settings.any_object and self.settings.target_px is None:
                result = plan_any(rgb, d, intrinsics, self.settings.hand, self.settings.options, memory=self.memory)
            else:
                result = plan_frame(rgb, d, intrinsics, self.settings.hand, self.settings.options,
                                    target_px=self.settings.target_px, memory=self.memory)
        for w in caught:
            self.get_logger().warning(str(w.message))
        return result


def main(ros_args=()) -> int:
    """Run the node until shut down (Ctrl-C, SIGTERM); ``ros_args`` follow ``--ros-args``.

    Returns 0, or 2 for a parameter refused (logged). Raises :class:`InputError` for ROS arguments rcl cannot parse.
    """
    try:
        rclpy.init(args=["contourgrasp", "--ros-args", *ros_args])
    except RuntimeError as err:  # rclpy's RCLError: arguments rcl cannot parse
        raise InputError(f"ROS arguments: {str(err).split(', at /')[0]}") from None
    try:
        node = ContourGraspNode()
    except InputError:
        rclpy.try_shutdown()
        return 2
    try:
        rclpy.spin(node)
    except (KeyboardInterrupt, ExternalShutdownException):
        pass
    except RuntimeError:  # rclpy's RCLError: rclpy's signal handler shuts the context down while the spin makes
        if rclpy.ok():    # its next wait set, a race of Ctrl-C (ros2/rclpy#398); any other error is the node's
            raise
    finally:
        _ignore_interrupts()
        node.destroy_node()
        rclpy.try_shutdown()
    return 0


def _ignore_interrupts() -> None:
    """Ignore SIGINT from here on: rclpy's handler passes a Ctrl-C on to Python's, whose KeyboardInterrupt may
    land after the spin has already stopped on it and cut the teardown short (the process then hangs at exit
    on a context never shut down). A Python handler not yet run when SIG_IGN is set is not run at all."""
    while True:
        try:
            signal.signal(signal.SIGINT, signal.SIG_IGN)
            return
        except KeyboardInterrupt:
            continue
