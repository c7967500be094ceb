"""Where the object lies in the hand when a pose lifts it: the pose oracle's lifting poses in the hand frame.

Reads the ``--json`` output of ``benchmarks/pose_oracle.py`` and prints, per object, the object's
centre of mass in the hand frame (x, y, mm; the frame of the hand file, in which the fingers' starts
and trajectories are given) over the poses that lifted it: mean and standard deviation (the grid itself is centred on the
fingertips' hull centroid, printed first). The oracle places the hand so that the centroid of its fingertips'
open and closed points lies at the centre of mass plus the grid's offset, so the centre of mass lies at
that centroid minus the offset turned into the hand frame.

Usage::

    .venv/bin/python benchmarks/pose_oracle_frame.py ORACLE.json [--hand five-finger-linear | --hand-model inspire]
"""

import argparse
import json
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).parent))
from pose_oracle import _hand, swept_centre  # noqa: E402  (a sibling script, not a package)

from contourgrasp.errors import ContourGraspError  # noqa: E402
from contourgrasp.hand import rotation  # noqa: E402


def centres(rows, hull_centre) -> tuple[np.ndarray, np.ndarray]:
    """(n, 2) float every pose's centre of mass in the hand frame, m, and (n,) bool whether it lifted."""
    yaw = np.array([r["yaw"] for r in rows])
    offset = np.array([[r["dx"], r["dy"]] for r in rows])
    turned = np.einsum("nji,nj->ni", rotation(yaw), -offset)  # R(yaw)^T (-offset)
    return turned + hull_centre, np.array([r["success"] for r in rows], dtype=bool)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("oracle", help="the --json output of benchmarks/pose_oracle.py")
    parser.add_argument("--hand", default="five-finger-linear", help="the hand the oracle ran with")
    parser.add_argument("--hand-model", default=None)
    args = parser.parse_args(argv)
    try:
        outcomes = json.loads(Path(args.oracle).read_text())
        _, planned = _hand(args.hand, args.hand_model)
    except (OSError, ValueError, ContourGraspError) as err:
        parser.error(str(err))
    hull_centre = swept_centre(planned)
    print(f"hand {args.hand_model or args.hand}: fingertips' hull centroid at ({1000 * hull_centre[0]:.1f}, "
          f"{1000 * hull_centre[1]:.1f}) mm\n")
    print("| object | lifted | lifting poses: mean x, y, mm | sd x, y, mm |")
    print("|---|---:|---|---|")
    for name, rows in outcomes.items():
        where, lifted = centres(rows, hull_centre)
        cells = "- | -"
        if lifted.any():
            mean, spread = 1000 * where[lifted].mean(axis=0), 1000 * where[lifted].std(axis=0)
            cells = f"{mean[0]:.1f}, {mean[1]:.1f} | {spread[0]:.1f}, {spread[1]:.1f}"
        print(f"| {name} | {int(lifted.sum())} of {len(rows)} | {cells} |")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
