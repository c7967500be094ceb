"""Approach-depth benchmark: how far from the intended height the planned hand ends, on rendered frames.

The approach depth (section 3.1.1) puts the fingertips' plane ``approach_offset`` (1 cm) below the
object's top. For the five thesis objects, ``--seeds`` placements each, the simulation renders the
frame (:func:`contourgrasp.sim.render`) from a camera 0.7 m from the table with the simulation's
SR300 intrinsics, looking straight down and tilted 12.7 deg (:func:`contourgrasp.sim.tilted_view`);
``plan_grasp`` plans the five-finger hand,
and the script prints how far the hand frame's origin lies above the object's true top less 1 cm,
in millimetres, mean (largest) over the placements:

* ``exact``: depth without noise;
* ``raw``: the simulation's depth noise (about 2 mm at 0.7 m), nearest depth taken over the raw
  readings (:func:`contourgrasp.perception.denoised_depth` replaced by the readings themselves), as
  the thesis's minimum reads literally;
* ``filtered``: the same frames as the library plans them, nearest depth on the 3 x 3 median.

Usage::

    python benchmarks/approach_depth.py [--seeds N]
"""

from __future__ import annotations

import argparse
import sys
import warnings
from unittest import mock

import numpy as np

import contourgrasp
from contourgrasp import perception
from contourgrasp.sim import Camera, build_scene, render, tilted_view
from contourgrasp.tolerances import APPROACH_OFFSET

OBJECTS = ("can", "case", "bottle", "stone1", "stone2")
TILTS_DEG = (0.0, 12.7)
CAMERA = Camera(height=0.7)
HAND = "five-finger-linear"


def height_error(scene, view, rgb, depth) -> float:
    """How far (m) the planned hand frame lies above the object's top less the approach offset."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        plan = contourgrasp.plan_grasp(rgb, depth, CAMERA.intrinsics, hand=HAND)
    eye, R_world_camera = view
    hand_z = eye[2] + R_world_camera[2] @ plan.T_camera_hand[:3, 3]
    return hand_z - (scene.object_points()[:, 2].max() - APPROACH_OFFSET)


def main(argv=None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seeds", type=int, default=3, help="placements per object")
    args = parser.parse_args(argv)
    print("| object | tilt | exact (mm) | raw (mm) | filtered (mm) |\n|---|---:|---:|---:|---:|")
    every = {"exact": [], "raw": [], "filtered": []}
    for name in OBJECTS:
        for tilt in TILTS_DEG:
            errors = {key: [] for key in every}
            for seed in range(args.seeds):
                scene = build_scene(name, seed=seed, camera=CAMERA)
                view = tilted_view(np.radians(tilt), CAMERA.height)
                errors["exact"].append(height_error(scene, view, *render(scene, view=view)))
                noisy = render(scene, sensor="basic", seed=seed, view=view)
                with mock.patch.object(perception.camera, "denoised_depth", lambda depth, valid: depth):
                    errors["raw"].append(height_error(scene, view, *noisy))
                errors["filtered"].append(height_error(scene, view, *noisy))
            cells = []
            for key, values in errors.items():
                every[key] += values
                mm = 1000 * np.array(values)
                cells.append(f"{mm.mean():+.1f} ({mm[np.argmax(np.abs(mm))]:+.1f})")
            print(f"| {name} | {tilt:g} deg | " + " | ".join(cells) + " |")
    ranges = ", ".join(f"{key} {1000 * min(v):+.1f} to {1000 * max(v):+.1f} mm" for key, v in every.items())
    print(f"\nall frames: {ranges}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
