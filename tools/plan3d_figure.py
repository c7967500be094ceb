"""docs/plan-3d.png: the `default` planner's 3-D plan of a simulated standing soup can (YCB 005), with its side view.

Usage: .venv/bin/python tools/plan3d_figure.py [docs/plan-3d.png]
"""

import argparse

from contourgrasp import load_hand, pipeline
from contourgrasp.io.planner_file import load_planner
from contourgrasp.sim import build_scene, render
from contourgrasp.sim.ycb import load_object
from contourgrasp.visualize import image_plan_figure


def main(out: str = "docs/plan-3d.png") -> None:
    hand = load_hand("five-finger-linear")
    scene = build_scene(load_object("ycb:005_tomato_soup_can"), seed=0, hand=hand)
    rgb, depth = render(scene, sensor="basic", seed=0)
    result = pipeline.plan_frame(rgb, depth, scene.camera.intrinsics, hand, load_planner("default").options)
    image_plan_figure(result, rgb).savefig(out, dpi=60)


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("out", nargs="?", default="docs/plan-3d.png", help="the PNG to write (default docs/plan-3d.png)")
    main(parser.parse_args().out)
