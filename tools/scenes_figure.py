"""The scenes of several objects as the planner sees them (``docs/scenes.png``)::

    python tools/scenes_figure.py [--out docs/scenes.png] [--seeds 3] [--split ycb-test]

One row per kind (``clutter``, ``bin``), one column per seed: the picture of
:func:`contourgrasp.sim.render` (depth noise aside, colour is what the planner
gets) with the target's pixel (:func:`contourgrasp.sim.target_pixel`) circled.
The target of seed ``s`` is the split's object ``s``, its neighbours drawn from
the others, as ``contourgrasp bench --scene`` does.
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np
from matplotlib.figure import Figure

from contourgrasp.sim import build_clutter, render, target_pixel
from contourgrasp.sim.ycb import OBJECT_SETS, load_object


def scenes_figure(seeds: int, split: str) -> Figure:
    objects = [load_object(f"ycb:{name}") for name in OBJECT_SETS[split]]
    fig = Figure(figsize=(3.2 * seeds, 5.0), layout="constrained")
    axes = fig.subplots(2, seeds, squeeze=False)
    for row, kind in zip(axes, ("clutter", "bin")):
        for seed, ax in enumerate(row):
            target = objects[seed % len(objects)]
            scene = build_clutter(target, [o for o in objects if o is not target], kind=kind, seed=seed)
            rgb, _ = render(scene)
            u, v = target_pixel(scene)
            ax.imshow(rgb)
            ax.plot(u, v, "o", mfc="none", mec="red", ms=9, mew=1.5)
            tilt = np.degrees(np.arccos(-scene.view[1][2, 2]))
            ax.set_title(f"{kind}, seed {seed}: {target.name}\n+ {len(scene.neighbours)} neighbour(s), "
                         f"tilt {tilt:.0f} deg", fontsize=7)
            ax.set_axis_off()
    return fig


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", type=Path, default=Path("docs/scenes.png"))
    parser.add_argument("--seeds", type=int, default=3)
    parser.add_argument("--split", default="ycb-test", choices=("ycb-train", "ycb-test"))
    args = parser.parse_args(argv)
    scenes_figure(args.seeds, args.split).savefig(args.out, dpi=110)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
