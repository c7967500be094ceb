"""How hard each fingertip of a bundled hand model pushes along its closing path (the README's model forces).

The model is closed in free air as ``hand-from-model`` closes it (palm held, gravity off, the synergy's
actuators ramped from open to closed over 3 s, held pre-shapes kept). At 40, 60 and 80 % of the ramp,
with every synergy actuator commanded fully closed, the actuators' joint forces ``tau`` are read and
each fingertip's force along its direction of motion ``d`` is the virtual-work estimate
``tau . (J^T d) / |J^T d|^2`` (``J`` the fingertip's translational Jacobian): the force an object in the
fingertip's way would feel while the joints are still short of their targets.

Usage::

    .venv/bin/python benchmarks/finger_force.py [inspire|jaco-three-finger ...]
"""

import argparse

import mujoco
import numpy as np

from contourgrasp.sim import model_hand

RAMP_STEPS = 1500
PROGRESS = (0.4, 0.6, 0.8)


def finger_forces(name: str) -> dict[float, dict[str, float]]:
    """Per ramp progress, per fingertip, its force along its motion, N."""
    spec = model_hand.model_spec(name)
    m = model_hand.load_model(spec.path)
    m.opt.gravity[:] = 0.0
    d = mujoco.MjData(m)
    palm = model_hand._palm_body(m, spec, spec.path)
    subtree = model_hand._subtree(m, palm)
    tips = [model_hand._fingertip(m, tip, subtree, spec.path) for tip in spec.fingertips]
    acts = model_hand._actuators(m, spec.actuators, subtree, spec.path)
    lo, hi = m.actuator_ctrlrange[acts, 0], m.actuator_ctrlrange[acts, 1]
    for a, value in model_hand._held(m, spec, subtree, spec.path):
        d.ctrl[a] = value
    forces = {}
    for k in range(RAMP_STEPS + 1):
        d.ctrl[acts] = lo + min(1.0, k / RAMP_STEPS) * (hi - lo)
        before = [model_hand._point(d, tip) for tip in tips]
        mujoco.mj_step(m, d)
        if k not in {round(p * RAMP_STEPS) for p in PROGRESS}:
            continue
        commanded = d.ctrl.copy()
        d.ctrl[acts] = hi
        mujoco.mj_forward(m, d)
        tau = d.qfrc_actuator.copy()
        row = {}
        for name_, tip, start in zip(spec.names or spec.fingertips, tips, before, strict=True):
            motion = model_hand._point(d, tip) - start
            jac = np.zeros((3, m.nv))
            kind, index = tip
            (mujoco.mj_jacSite if kind == "site" else mujoco.mj_jacBody)(m, d, jac, None, index)
            along = jac.T @ (motion / max(float(np.linalg.norm(motion)), 1e-12))
            row[name_] = float(tau @ along / max(float(along @ along), 1e-12))
        d.ctrl[:] = commanded
        mujoco.mj_forward(m, d)
        forces[k / RAMP_STEPS] = row
    return forces


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("models", nargs="*", default=list(model_hand.MODELS))
    for name in parser.parse_args().models:
        print(f"{name}: fingertip force along its path, N")
        for progress, row in finger_forces(name).items():
            print(f"  {100 * progress:3.0f} % of the ramp: " + ", ".join(f"{f} {v:.1f}" for f, v in row.items()))


if __name__ == "__main__":
    main()
