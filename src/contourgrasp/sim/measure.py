"""How well the simulated hand follows its 2-D preset: fingertip paths closing in free space.

The synthesis assumes each fingertip's projection onto the image plane moves on
the segment ``start -> start + travel * closing_direction`` (eq 3.18). The
simulated fingers are planar chains built to do so (see
:mod:`contourgrasp.sim.hand_model`); what can still pull a tip off the segment
is dynamics: the soft joint limits the tip overshoots at the end, the base
servo giving way to the fingers' reaction, joint compliance. These functions
measure it.
"""

from __future__ import annotations

import numpy as np

from ..errors import SimulationError
from ..hand import polyline_distance
from .hand_model import HandDesign
from .scene import build_scene

#: Palm height for free-space closing: fingertips far above the table and the object.
FREE_SPACE_HEIGHT = 0.6


def fingertip_paths(hand="five-finger-linear", *, timing: str = "thesis", design: HandDesign = HandDesign(),
                    close_time: float = 1.0, hold_time: float = 0.5) -> dict[str, np.ndarray]:
    """Close the hand on nothing and record every fingertip, projected to the 2-D hand frame.

    Returns
    -------
    dict of str to (k, 2) float
        Per finger, the fingertip at every time step (hand frame, m), from the
        open hand to ``hold_time`` after the force ramp ended.

    Raises
    ------
    SimulationError
        A hand the simulation cannot build, or whose simulation is unstable.
    """
    scene = build_scene("can", seed=0, hand=hand, design=design, timing=timing)
    model, data = scene.model, scene.data
    sites = [model.site(f"{f.name}_tip").id for f in scene.hand.fingers]
    scene.set_hand(0.0, 0.0, FREE_SPACE_HEIGHT, 0.0)
    dt = model.opt.timestep
    ramp = round(close_time / dt)
    tracks = []
    for k in range(ramp + round(hold_time / dt)):
        scene.command([0.0, 0.0, FREE_SPACE_HEIGHT, 0.0], min(1.0, (k + 1) / ramp))
        scene.step()
        position, rotation = scene.palm_pose()
        tracks.append((data.site_xpos[sites] - position) @ rotation)  # hand frame; drop z below
    if scene.unstable:
        raise SimulationError(f"hand {scene.hand.hand.name!r}: the simulated hand is unstable (NaN or huge "
                              "accelerations): its fingers are too small or too large to simulate")
    paths = np.stack(tracks)[:, :, :2]
    return {f.name: paths[:, i] for i, f in enumerate(scene.hand.fingers)}


def fingertip_path_error(hand="five-finger-linear", **kwargs) -> dict[str, float]:
    """Per finger, the largest distance (mm) between its projected free-space path and the preset's segment.

    Keyword arguments go to :func:`fingertip_paths`.
    """
    from ..io.hand_file import load_hand

    preset = load_hand(hand)
    paths = fingertip_paths(preset, **kwargs)
    return {f.name: 1000.0 * float(polyline_distance(paths[f.name], [f.start, f.end]).max()) for f in preset.fingers}
