"""The ``contourgrasp`` command: a thin layer over the library.

Exit codes: 0 ok, 2 bad input, 3 no feasible grasp. Errors are one line on
stderr; output files are written atomically (all of them or none).
"""

from __future__ import annotations

import argparse
import json
import math
import sys
import warnings

import numpy as np

from . import __version__, efd, synthesize
from .errors import InputError, NoFeasibleGrasp
from .io.contour_file import example_contour, example_names, read_contour
from .io.hand_file import load_hand, preset_names
from .io.plan_file import atomic_outputs, plan_to_dict, write_json

EXIT_OK, EXIT_INPUT, EXIT_INFEASIBLE = 0, 2, 3


def _positive_float(text: str) -> float:
    value = float(text)
    if not (value > 0 and math.isfinite(value)):
        raise argparse.ArgumentTypeError(f"must be a positive number, got {text}")
    return value


def _non_negative_float(text: str) -> float:
    value = float(text)
    if not (value >= 0 and math.isfinite(value)):
        raise argparse.ArgumentTypeError(f"must be a number >= 0, got {text}")
    return value


def _positive_int(text: str) -> int:
    value = int(text)
    if value < 1:
        raise argparse.ArgumentTypeError(f"must be a positive integer, got {text}")
    return value


def _contour(spec: str) -> np.ndarray:
    if spec.startswith("example:"):
        return example_contour(spec.removeprefix("example:"))
    return read_contour(spec)


def _parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(prog="contourgrasp", description=__doc__.splitlines()[0])
    parser.add_argument("--version", action="version", version=f"contourgrasp {__version__}")
    sub = parser.add_subparsers(dest="command", required=True)

    sub.add_parser("hands", help="list the built-in hand presets")

    contour_help = (f"contour file: CSV (x,y in meters) or .npy (n x 2); "
                    f"or example:NAME with NAME in {', '.join(example_names())}")
    synth = sub.add_parser("synth", help="plan a grasp on a metric contour")
    synth.add_argument("--contour", required=True, help=contour_help)
    synth.add_argument("--hand", default="five-finger-linear", help="preset name or hand TOML file")
    synth.add_argument("--harmonics", type=_positive_int, default=4)
    synth.add_argument("--curvature", choices=efd.CURVATURE_MODES, default="paper")
    synth.add_argument("--xy-step", type=_positive_float, default=0.05, help="grid step in x and y, m")
    synth.add_argument("--yaw-step-deg", type=_positive_float, default=2.0, help="grid step in yaw, degrees")
    synth.add_argument("--d-max", type=_non_negative_float, nargs="+", default=[0.15], metavar="D",
                       help="D_max (one value, or x and y), m")
    synth.add_argument("--d-min", type=_non_negative_float, default=0.015, help="D_min, m")
    synth.add_argument("--top-k", type=_positive_int, default=10, help="ranked distinct poses to report")
    synth.add_argument("--out", help="write the plan JSON here (default: print it)")
    synth.add_argument("--plot", help="write the plan picture (PNG) here")

    harm = sub.add_parser("efd", help="approximate a contour with several harmonic counts")
    harm.add_argument("--contour", required=True, help=contour_help)
    harm.add_argument("--harmonics", type=_positive_int, nargs="+", default=[1, 2, 4, 8])
    harm.add_argument("--curvature", choices=efd.CURVATURE_MODES, default="paper")
    harm.add_argument("--plot", help="write the figure (PNG) here")
    return parser


def _hands(_args) -> int:
    for name in preset_names():
        hand = load_hand(name)
        fingers = ", ".join(f.name for f in hand.fingers)
        print(f"{name:26s} {hand.description}\n{'':26s} fingers: {fingers}; min_touching {hand.min_touching}")
    return EXIT_OK


def _synth(args) -> int:
    if len(args.d_max) > 2:
        raise InputError(f"--d-max takes one or two values, got {len(args.d_max)}")
    plan = synthesize(
        _contour(args.contour),
        load_hand(args.hand),
        harmonics=args.harmonics,
        curvature=args.curvature,
        xy_step=args.xy_step,
        yaw_step=math.radians(args.yaw_step_deg),
        d_max=tuple(args.d_max) if len(args.d_max) == 2 else args.d_max[0],
        d_min=args.d_min,
        top_k=args.top_k,
    )
    data = plan_to_dict(plan)
    with atomic_outputs(args.out, args.plot) as (out, plot):
        if out is not None:
            write_json(data, out)
        if plot is not None:
            from .visualize import plan_figure

            plan_figure(plan).savefig(plot, dpi=110, format="png")
    if args.out is None:
        print(json.dumps(data, indent=2))
    else:
        x, y, yaw = plan.pose
        touching = sum(not f.missed for f in plan.fingers)
        print(f"pose x={x:.4f} m y={y:.4f} m yaw={math.degrees(yaw):.1f} deg, cost {plan.cost.total:.2f}, "
              f"{touching}/{len(plan.fingers)} fingers touch, {plan.timing_ms['total']:.0f} ms -> {args.out}")
    return EXIT_OK


def _efd(args) -> int:
    contour = efd.clean_polygon(_contour(args.contour))
    for k in args.harmonics:
        model = efd.fit(contour, k)
        t, _ = efd.sample(model, 720)
        concave = efd.concave(model, t, args.curvature)
        stretches = int(np.count_nonzero(concave & ~np.roll(concave, 1)))
        print(f"{k:3d} harmonics: {stretches} concave stretch(es), {100 * concave.mean():.0f}% of the contour concave")
    if args.plot:
        from .visualize import harmonics_figure

        with atomic_outputs(args.plot) as (plot,):
            harmonics_figure(contour, args.harmonics, curvature=args.curvature).savefig(plot, dpi=110, format="png")
    return EXIT_OK


COMMANDS = {"hands": _hands, "synth": _synth, "efd": _efd}


def main(argv=None) -> int:
    args = _parser().parse_args(argv)
    code, message = EXIT_OK, None
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        try:
            code = COMMANDS[args.command](args)
        except InputError as err:
            code, message = EXIT_INPUT, f"error: {err}"
        except NoFeasibleGrasp as err:
            code, message = EXIT_INFEASIBLE, f"no feasible grasp: {err.reason}"
        except OSError as err:
            code, message = EXIT_INPUT, f"error: cannot write {err.filename}: {err.strerror}"
    for w in caught:
        print(f"contourgrasp: warning: {w.message}", file=sys.stderr)
    if message:
        print(f"contourgrasp: {message}", file=sys.stderr)
    return code


if __name__ == "__main__":
    sys.exit(main())
