"""The procedural objects as a camera 40 deg from top-down sees them (``docs/procedural.png``)::

    python tools/procedural_figure.py [--out docs/procedural.png] [--count 18] [--first 0]

One tile per seed from ``--first``: :func:`contourgrasp.sim.procedural.procedural_object` settled on
the table (:func:`contourgrasp.sim.build_scene`), rendered without noise, cropped around it.
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np
from matplotlib.figure import Figure

from contourgrasp.sim import build_scene, object_truth, render, tilted_view
from contourgrasp.sim.procedural import procedural_object

COLUMNS = 6


def procedural_figure(count: int, first: int) -> Figure:
    rows = -(-count // COLUMNS)
    fig = Figure(figsize=(2.2 * COLUMNS, 1.8 * rows), layout="constrained")
    axes = fig.subplots(rows, COLUMNS, squeeze=False).ravel()
    for ax, seed in zip(axes, range(first, first + count)):
        obj = procedural_object(seed)
        scene = build_scene(obj, seed=0)
        view = tilted_view(np.radians(40.0), scene.camera.height)
        rgb, _ = render(scene, sensor="ideal", view=view)
        v, u = np.nonzero(object_truth(scene, view)[0])
        cv, cu = int(np.median(v)), int(np.median(u))
        ax.imshow(rgb[max(cv - 100, 0):cv + 100, max(cu - 135, 0):cu + 135])
        ax.set_title(f"{obj.name}, {1000 * obj.mass:.0f} g", fontsize=7)
    for ax in axes:
        ax.set_axis_off()
    return fig


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=Path("docs/procedural.png"))
    parser.add_argument("--count", type=int, default=18)
    parser.add_argument("--first", type=int, default=0)
    args = parser.parse_args(argv)
    procedural_figure(args.count, args.first).savefig(args.out, dpi=90)
    print(f"wrote {args.out}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
