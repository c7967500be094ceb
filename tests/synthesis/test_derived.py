"""Values derived once per model and hand (synthesis._derived)."""

import numpy as np

import contourgrasp as cg
from contourgrasp import contour
from contourgrasp.synthesis import _derived


def test_derived_arrays_are_computed_once_and_go_with_their_model():
    model = contour.fit(cg.example_contour("can"))
    polygon = _derived.polygon(model)
    assert _derived.polygon(model) is polygon
    np.testing.assert_array_equal(polygon[1], contour.sample(model)[1])
    twin = contour.fit(cg.example_contour("can"))
    assert _derived.polygon(twin) is not polygon
    key = id(model)
    del model
    assert key not in _derived._DERIVED
