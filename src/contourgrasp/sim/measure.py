"""Measurements of the simulation as an instrument: fingertip paths, and how much a hold creeps.

How well the simulated hand follows its 2-D preset: fingertip paths closing in free space.

The synthesis assumes each fingertip's projection onto the image plane moves on
the segment ``start -> start + travel * closing_direction`` (eq 3.18). The
simulated fingers are planar chains built to do so (see
:mod:`contourgrasp.sim.tendon_hand`); what can still pull a tip off the segment
is dynamics: the soft joint limits the tip overshoots at the end, the base
servo giving way to the fingers' reaction, joint compliance. These functions
measure it.

How much a hold inside its friction cones creeps (:func:`squeeze_creep`): the
reason for :data:`~contourgrasp.sim.mjcf.IMPRATIO` (see :mod:`contourgrasp.sim.mjcf`).
"""

from __future__ import annotations

import os

import numpy as np

os.environ.setdefault("MUJOCO_GL", "disable")
import mujoco  # noqa: E402

from ..errors import SimulationError  # noqa: E402
from ..hand import polyline_distance  # noqa: E402
from .tendon_hand import HandDesign  # noqa: E402
from .objects import ObjectSpec, Part  # noqa: E402
from .mjcf import IMPRATIO, grip_contact, solver_option  # noqa: E402
from .scene import build_scene  # noqa: E402

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


def squeeze_creep(margin: float, *, impratio: float = IMPRATIO, noslip: int = 0, mass: float = 0.05,
                  hold_time: float = 2.0) -> float:
    """m: how far a box squeezed between two pads falls while gravity pulls it for ``hold_time`` s.

    The scene's solver settings (:func:`~contourgrasp.sim.mjcf.solver_option`, with ``impratio`` and MuJoCo's
    ``noslip_iterations`` as given) and its grip contact (:func:`~contourgrasp.sim.mjcf.grip_contact`);
    the pads slide on rails and are pushed together with a constant force; the box of ``mass`` kg is
    squeezed at rest between them without gravity for 0.5 s before gravity is turned on. ``margin`` is the friction cone's limit over the load, mu 2F / (m g): above 1 Coulomb friction
    holds the box still, below 1 it slides.

    Examples
    --------
    >>> squeeze_creep(2.0) < 2e-4 < 1.0 < squeeze_creep(0.5)
    True
    """
    box = ObjectSpec("box", (Part("box", size=(0.015, 0.03, 0.03)),), mass=mass, friction_hand=0.6,
                     friction_table=0.4)
    pads = "".join(f'<body name="{n}" pos="{x} 0 0.3"><joint name="{n}" type="slide" axis="{-np.sign(x)} 0 0"/>'
                   f'<geom name="{n}" type="sphere" size="0.01" mass="0.1" contype="0" conaffinity="0"/></body>'
                   for n, x in (("left", -0.03), ("right", 0.03)))
    model = mujoco.MjModel.from_xml_string(f"""<mujoco>{solver_option(impratio, noslip)}<worldbody>{pads}
      <body name="box" pos="0 0 0.3"><freejoint/><geom name="box" type="box" size="0.015 0.03 0.03" mass="{mass}"
        contype="0" conaffinity="0"/></body></worldbody>
      <contact>{"".join(f'<pair geom1="box" geom2="{n}" {grip_contact(box)}/>' for n in ("left", "right"))}</contact>
      <actuator><motor joint="left"/><motor joint="right"/></actuator></mujoco>""")
    data = mujoco.MjData(model)
    data.ctrl[:] = margin * mass * 9.81 / (2 * box.friction_hand)
    model.opt.gravity[:] = 0
    mujoco.mj_step(model, data, nstep=250)  # squeezed at rest, then let go into gravity
    start = data.body("box").xpos[2]
    model.opt.gravity[:] = (0, 0, -9.81)
    mujoco.mj_step(model, data, nstep=round(hold_time / model.opt.timestep))
    return float(start - data.body("box").xpos[2])
