"""The contour model's public name: ``contourgrasp.efd`` is :mod:`contourgrasp.contour` (thesis 3.2).

README and users write ``from contourgrasp.efd import EFD, fit`` or
``contourgrasp.efd.choose_harmonics``; the code lives in the
:mod:`contourgrasp.contour` package (polygon checks, EFD model, adaptive
harmonics), which modules inside contourgrasp import directly.
"""

from .contour import (CURVATURE_MODES, EFD, HARMONICS_RULES, CurvatureMode, HarmonicsRule, __all__, choose_harmonics,
                      clean_polygon, concave, curvature, curvature_from_derivatives, evaluate, evaluate_derivatives,
                      first_self_intersection, fit, fit_adaptive, harmonic_power, repair_self_intersections, sample,
                      signed_area)
