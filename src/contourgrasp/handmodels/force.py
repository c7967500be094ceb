"""How hard each fingertip of a MuJoCo hand model pushes along its closing path.

The model is closed as :mod:`contourgrasp.handmodels.derive` closes it to derive a hand file (its
docstring: palm fixed, gravity and contacts off, the synergy ramped from open to closed), and the
drives' joint forces are read part way through. Not part of the hand file: the planner's squeeze
balance takes every finger as pushing equally hard (docs/hand-models.md, "The bench on the models", and
``docs/studies.md``, for what weighing them did).
"""

from __future__ import annotations

import math
import os

import numpy as np

os.environ.setdefault("MUJOCO_GL", "disable")
import mujoco  # noqa: E402

from .. import tolerances as tol  # noqa: E402
from .. import validation  # noqa: E402
from ..errors import HandError  # noqa: E402
from .derive import simulate_closing, model_spec  # noqa: E402
from .lookup import load_model  # noqa: E402

#: Where along the synergy's ramp :func:`fingertip_forces` reads the forces by default.
FORCE_PROGRESS = (0.4, 0.6, 0.8)


def fingertip_forces(model, *, fingertips=None, actuators=None, palm=None, progress=FORCE_PROGRESS,
                     close_time: float = 3.0) -> dict[float, dict[str, float]]:
    """How hard each fingertip of a hand model pushes along its closing path, N, at points of the closing.

    The model is closed in free air as :func:`~contourgrasp.handmodels.derive.derive_hand` closes it (palm fixed,
    gravity and contacts off, the synergy ramped from open to closed over ``close_time``, held
    pre-shapes kept). At each fraction ``progress`` of the ramp, every synergy actuator is commanded
    fully closed for an instant and the joint forces it then applies, ``tau``, are read; a fingertip's
    force along its direction of motion ``d`` is the virtual-work estimate
    ``tau . (J^T d) / |J^T d|^2`` (``J`` the fingertip's translational Jacobian): the force an object
    in the fingertip's way would feel while the finger's joints are still short of their targets. It
    is what a servo's force limit or a motor's torque gives at the tip, not a contact simulation: a
    finger whose drive saturates pushes with its limit over its lever.

    Parameters
    ----------
    model : str, Path or ModelSpec
        As :func:`~contourgrasp.handmodels.derive.derive_hand`; ``fingertips``, ``actuators`` and ``palm`` override
        its spec.
    progress : sequence of float
        Fractions of the ramp, each in (0, 1].
    close_time : float
        The ramp, s, in (0, ``tolerances.MAX_MODEL_CLOSING_TIME``].

    Returns
    -------
    dict
        progress -> finger name -> force, N (negative: the drive holds the finger back there; NaN: the
        fingertip is not moving then, slower than ``tolerances.FINGERTIP_MOVING``).

    Raises
    ------
    HandFileError, HandError, SimulationError
        As :func:`~contourgrasp.handmodels.derive.derive_hand`; HandError also for a ``progress`` outside (0, 1]
        or none, or a ``close_time`` out of range.

    Examples
    --------
    >>> forces = fingertip_forces("jaco-three-finger", progress=(0.6,))
    >>> {name: round(force, 1) for name, force in forces[0.6].items()}
    {'thumb': 3.1, 'index': 3.1, 'pinky': 3.1}
    """
    spec = model_spec(model, fingertips=fingertips, actuators=actuators, palm=palm)
    fractions = [validation.bounded("progress", p, 1.0, strict=True, error=HandError) for p in progress]
    if not fractions:
        raise HandError("progress must name at least one fraction of the closing")
    m = load_model(spec.path)
    run, acts, held, lo, hi, _ = simulate_closing(m, spec, close_time, 0.0)
    names = spec.names or spec.fingertips
    settle, ramp, _ = run.steps
    steps = {p: settle + round(p * ramp) for p in fractions}
    forces = {}

    def probe(k, d):
        if k in steps.values():
            forces[k] = dict(zip(names, _pushes(m, d, run.tips, acts, hi), strict=True))

    run(acts, lo, hi, held, spec.path, probe=probe)
    return {p: forces[k] for p, k in steps.items()}


def _pushes(m, d, tips, acts, closed) -> list[float]:
    """Each fingertip's force along its motion (:func:`fingertip_forces`), every synergy actuator at ``closed``."""
    commanded = d.ctrl.copy()
    d.ctrl[acts] = closed
    mujoco.mj_forward(m, d)
    tau = d.qfrc_actuator.copy()
    pushes = []
    for tip in tips:
        jac = np.zeros((3, m.nv))
        kind, index = tip
        (mujoco.mj_jacSite if kind == "site" else mujoco.mj_jacBody)(m, d, jac, None, index)
        velocity = jac @ d.qvel  # the way the tip is moving
        speed = float(np.linalg.norm(velocity))
        along = jac.T @ (velocity / max(speed, 1e-12))
        pushes.append(float(tau @ along / (along @ along)) if speed >= tol.FINGERTIP_MOVING else math.nan)
    d.ctrl[:] = commanded
    mujoco.mj_forward(m, d)
    return pushes
