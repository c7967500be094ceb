"""Contour model (thesis section 3.2): the input polygon, its Elliptic Fourier Descriptors and curvature.

* :mod:`~contourgrasp.contour.polygon` — checks and repair of the input polygon
  (:func:`clean_polygon`, :func:`repair_self_intersections`), its growth by a fingertip's radius
  (:func:`grow_polygon`)
* :mod:`~contourgrasp.contour.efd` — the EFD model: :func:`fit`, :func:`evaluate`,
  :func:`curvature`, :func:`concave` (eq 3.3-3.17)
* :mod:`~contourgrasp.contour.harmonics` — the adaptive number of harmonics
  (:func:`choose_harmonics`, :func:`fit_adaptive`; thesis 6.1 item 3)
"""

from .efd import (CURVATURE_MODES, EFD, CurvatureMode, concave, curvature, curvature_from_derivatives, evaluate,
                  evaluate_derivatives, fit, sample)
from .harmonics import HARMONICS_RULES, HarmonicsRule, choose_harmonics, fit_adaptive, harmonic_power
from .polygon import clean_polygon, first_self_intersection, grow_polygon, repair_self_intersections, signed_area

__all__ = [
    "CURVATURE_MODES", "CurvatureMode", "EFD", "HARMONICS_RULES", "HarmonicsRule", "choose_harmonics",
    "clean_polygon", "concave", "curvature", "curvature_from_derivatives", "evaluate", "evaluate_derivatives",
    "first_self_intersection", "fit", "fit_adaptive", "grow_polygon", "harmonic_power", "repair_self_intersections",
    "sample", "signed_area",
]
