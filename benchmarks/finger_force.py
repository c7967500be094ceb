"""How hard each fingertip of a bundled hand model pushes along its closing path (the README's model forces).

Prints :func:`contourgrasp.sim.model_force.fingertip_forces` at 40, 60 and 80 % of the synergy's ramp:
the model closed in free air as ``hand-from-model`` closes it, every synergy actuator commanded fully
closed for an instant, the joint forces read and turned into each fingertip's force along its motion
(the virtual-work estimate of that function's docstring).

Usage::

    .venv/bin/python benchmarks/finger_force.py [inspire|jaco-three-finger ...]
"""

import argparse

from contourgrasp.sim import model_force, model_hand


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("models", nargs="*", default=list(model_hand.MODELS))
    for name in parser.parse_args().models:
        print(f"{name}: fingertip force along its path, N")
        for progress, row in model_force.fingertip_forces(name).items():
            print(f"  {100 * progress:3.0f} % of the ramp: " + ", ".join(f"{f} {v:.1f}" for f, v in row.items()))


if __name__ == "__main__":
    main()
