"""The contour model's public name: ``contourgrasp.efd`` is :mod:`contourgrasp.contour` (thesis 3.2).

README and users write ``from contourgrasp.efd import EFD, fit`` or
``contourgrasp.efd.choose_harmonics``; the code lives in the
:mod:`contourgrasp.contour` package (polygon checks, EFD model, adaptive
harmonics), which modules inside contourgrasp import directly.
"""

from .contour import *  # noqa: F403 -- this module is that package's other name
from .contour import __all__  # noqa: F401
