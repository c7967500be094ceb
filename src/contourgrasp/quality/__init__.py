"""Grasp quality (thesis 6.1 item 2): 2-D force closure, the Ferrari-Canny epsilon and the squeeze's imbalance.

* :mod:`~contourgrasp.quality.wrench_space` -- contact wrenches, the grasp wrench space and its metrics
  (:func:`epsilon`, :func:`force_closure`, :func:`epsilon_many`, :func:`imbalance`), pure functions of
  numpy arrays; its compiled inner loop is :mod:`~contourgrasp.quality._kernels`.
"""

from .wrench_space import (GraspQuality, contact_wrenches, contour_normals, epsilon, epsilon_many, force_closure,
                           grasp_quality, imbalance)

__all__ = ["GraspQuality", "contact_wrenches", "contour_normals", "epsilon", "epsilon_many", "force_closure",
           "grasp_quality", "imbalance"]
