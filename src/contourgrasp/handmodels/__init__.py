"""Hand files from MuJoCo models of hands (``contourgrasp hand-from-model``, ``bench --hand-model``).

* :mod:`~contourgrasp.handmodels.derive` -- close the model in free air by one synergy and fit its hand file
  (:func:`derive_hand`)
* :mod:`~contourgrasp.handmodels.lookup` -- the model's palm, fingertips, actuators and geoms, found by name
* :mod:`~contourgrasp.handmodels.fit` -- the thesis's trajectories, chains and palm fitted to recorded paths
* :mod:`~contourgrasp.handmodels.mount` -- the model as the bench's simulated hand (:func:`mount_model`)
* :mod:`~contourgrasp.handmodels.force` -- how hard each fingertip pushes along its closing

Needs ``mujoco`` (the ``[sim]`` extra).
"""

from .derive import MODELS, Derivation, ModelSpec, derive_hand, fit_table
from .fit import FingerFit, fit_finger
from .force import fingertip_forces
from .mount import MountedHand, mount_model

__all__ = ["Derivation", "FingerFit", "MODELS", "ModelSpec", "MountedHand", "derive_hand", "fingertip_forces",
           "fit_finger", "fit_table", "mount_model"]
