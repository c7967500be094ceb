import json
import math

import pytest

import contourgrasp as cg
from contourgrasp.io.plan_file import atomic_outputs, plan_to_dict, write_json


def test_plan_json_schema():
    plan = cg.synthesize(cg.example_contour("can"), "three-finger", yaw_step=math.radians(10), top_k=3)
    data = json.loads(json.dumps(plan_to_dict(plan)))
    assert set(data) >= {"pose", "cost", "curvature_mode", "fingers", "efd", "alternatives", "timing_ms", "grid",
                         "safeguards", "quality"}
    assert set(data["pose"]) == {"x", "y", "yaw"}
    assert set(data["cost"]) == {"total", "curvature", "ratio", "miss", "quality"}
    assert data["quality"]["force_closure"] is True and data["quality"]["epsilon"] > 0  # three fingers around a can
    assert data["safeguards"] == {"finger_thickness": False, "clearance": 0.0, "friction": 0.5,
                                  "require_closure": False, "quality_gain": 0.0}
    finger_keys = {"name", "grasp_point", "t", "lambda", "curvature", "concave", "distance", "start",
                   "virtual_start", "missed", "gap"}
    assert all(set(f) == finger_keys for f in data["fingers"])
    assert len(data["efd"]["coefficients"]) == data["efd"]["harmonics"] == 4
    assert len(data["alternatives"]) == 3
    assert data["pose"]["x"] == pytest.approx(float(plan.pose[0]))


def test_atomic_outputs_leave_nothing_on_failure(tmp_path):
    with pytest.raises(RuntimeError):
        with atomic_outputs(tmp_path / "a.json", tmp_path / "b.png") as (a, b):
            write_json({"x": 1}, a)
            raise RuntimeError("plot failed")
    assert list(tmp_path.iterdir()) == []
    with atomic_outputs(tmp_path / "a.json", None) as (a, none):
        write_json({"x": 1}, a)
        assert none is None
    assert [p.name for p in tmp_path.iterdir()] == ["a.json"]
    assert (tmp_path / "a.json").stat().st_mode & 0o644 == 0o644


def test_missing_output_directory_is_an_input_error(tmp_path):
    with pytest.raises(cg.InputError, match="does not exist"):
        with atomic_outputs(tmp_path / "no" / "a.json"):
            pass
