import json
import math
import os
import stat
import threading
from pathlib import Path

import pytest

import contourgrasp as cg
from contourgrasp.errors import OutputError
from contourgrasp.io.plan_file import atomic_outputs, plan_to_dict, write_json


def test_plan_json_schema():
    plan = cg.synthesize(cg.example_contour("can"), "three-finger", yaw_step=math.radians(10), top_k=3)
    data = json.loads(json.dumps(plan_to_dict(plan)))
    assert set(data) >= {"pose", "cost", "curvature_mode", "fingers", "efd", "alternatives", "timing_ms", "grid",
                         "safeguards", "quality"}
    assert set(data["pose"]) == {"x", "y", "yaw"}
    assert set(data["cost"]) == {"total", "curvature", "ratio", "miss", "quality", "centring"}
    assert data["quality"]["force_closure"] is True and data["quality"]["epsilon"] > 0  # three fingers around a can
    assert 0.0 <= data["quality"]["imbalance"] <= 1.0
    assert data["safeguards"] == {"finger_thickness": False, "clearance": 0.0, "friction": 0.5,
                                  "require_closure": False, "quality_gain": 0.0, "max_imbalance": 1.0,
                                  "centring_gain": 0.0}
    finger_keys = {"name", "grasp_point", "t", "lambda", "curvature", "concave", "distance", "start",
                   "virtual_start", "missed", "gap"}
    assert all(set(f) == finger_keys for f in data["fingers"])
    assert len(data["efd"]["coefficients"]) == data["efd"]["harmonics"] == 4
    assert data["efd"]["outline_grown_by"] == 0.0  # the fingertips reach the can as points
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


def test_every_target_is_checked_before_anything_is_replaced(tmp_path):
    out = tmp_path / "out.json"
    out.write_text("old")
    (tmp_path / "adir").mkdir()
    with pytest.raises(OutputError, match="adir: cannot write, it is a directory"):
        with atomic_outputs(out, tmp_path / "adir") as (a, b):
            write_json({"x": 1}, a)
    assert out.read_text() == "old" and sorted(p.name for p in tmp_path.iterdir()) == ["adir", "out.json"]


def test_a_target_given_twice_or_equal_to_an_input_is_refused(tmp_path):
    out = tmp_path / "x"
    with pytest.raises(OutputError, match="given twice"):
        with atomic_outputs(out, tmp_path / "sub" / ".." / "x"):
            pass
    contour = tmp_path / "c.csv"
    contour.write_text("input")
    with pytest.raises(OutputError, match="would overwrite the input file"):
        with atomic_outputs(tmp_path / "." / "c.csv", inputs=[None, "example:can", contour]):
            pass
    assert contour.read_text() == "input" and not out.exists()


def test_an_existing_output_keeps_its_mode(tmp_path):
    out = tmp_path / "out.json"
    out.write_text("old")
    out.chmod(0o600)
    with atomic_outputs(out) as (tmp,):
        write_json({"x": 1}, tmp)
    assert stat.S_IMODE(out.stat().st_mode) == 0o600 and json.loads(out.read_text()) == {"x": 1}


def test_a_failed_rename_restores_the_outputs_already_replaced(tmp_path, monkeypatch):
    a, b = tmp_path / "a.json", tmp_path / "b.json"
    a.write_text("old a")
    real = os.replace
    calls = []

    def failing(src, dst):
        calls.append(dst)
        if Path(dst) == b:
            raise PermissionError(13, "Permission denied", str(dst))
        return real(src, dst)

    monkeypatch.setattr("contourgrasp.io.plan_file.os.replace", failing)
    with pytest.raises(OutputError, match=f"cannot write {b}: Permission denied; no output was changed"):
        with atomic_outputs(a, b) as (ta, tb):
            write_json({"new": 1}, ta)
            write_json({"new": 2}, tb)
    monkeypatch.undo()
    assert a.read_text() == "old a" and not b.exists()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a.json"]


def test_write_errors_name_the_target_not_the_temporary_file(tmp_path):
    out = tmp_path / "out.json"
    with pytest.raises(OutputError) as err:
        with atomic_outputs(out) as (tmp,):
            raise OSError(28, "No space left on device", str(tmp))
    assert str(err.value) == f"cannot write {out}: No space left on device"


@pytest.mark.parametrize("value", [math.inf, -math.inf, math.nan, 1e300 * 1e300])
def test_write_json_refuses_non_finite_numbers(tmp_path, value):
    with pytest.raises(OutputError, match=r"fingers\[0\]\.virtual_start\[1\] = .*JSON has no NaN or infinity"):
        write_json({"fingers": [{"virtual_start": [0.0, value]}]}, tmp_path / "p.json")
    assert not (tmp_path / "p.json").exists()


def test_concurrent_writers_never_leave_a_partial_file(tmp_path):
    out = tmp_path / "plan.json"
    payloads = [{"writer": w, "data": [w] * 20000} for w in range(2)]
    stop = threading.Event()
    seen = []

    def writer(data):
        for _ in range(15):
            with atomic_outputs(out) as (tmp,):
                write_json(data, tmp)

    def reader():
        while not stop.is_set():
            if out.exists():
                seen.append(json.loads(out.read_text())["writer"])

    threads = [threading.Thread(target=writer, args=(p,)) for p in payloads]
    watcher = threading.Thread(target=reader)
    watcher.start()
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    stop.set()
    watcher.join()
    assert json.loads(out.read_text()) in payloads and set(seen) <= {0, 1}
    assert [p.name for p in tmp_path.iterdir()] == ["plan.json"]


def test_a_device_is_written_through_not_replaced(tmp_path):
    before = os.stat("/dev/null")
    with atomic_outputs("/dev/null", tmp_path / "a.txt") as (null, a):
        null.write_text("discarded")
        a.write_text("kept")
    after = os.stat("/dev/null")
    assert stat.S_ISCHR(after.st_mode) and (after.st_ino, after.st_rdev) == (before.st_ino, before.st_rdev)
    assert (tmp_path / "a.txt").read_text() == "kept" and not list(Path("/dev").glob(".null.*"))


def test_a_fifo_is_written_through_to_its_reader(tmp_path):
    fifo = tmp_path / "fifo"
    os.mkfifo(fifo)
    read = []
    reader = threading.Thread(target=lambda: read.append(fifo.read_text()))
    reader.start()
    with atomic_outputs(fifo) as (out,):
        out.write_text("through the pipe")
    reader.join(timeout=10)
    assert read == ["through the pipe"] and stat.S_ISFIFO(os.stat(fifo).st_mode)


def test_a_symbolic_link_keeps_pointing_at_its_replaced_target(tmp_path):
    (tmp_path / "target.json").write_text("old")
    (tmp_path / "link.json").symlink_to("target.json")
    (tmp_path / "dangling.json").symlink_to("new.json")
    with atomic_outputs(tmp_path / "link.json", tmp_path / "dangling.json") as (link, dangling):
        link.write_text("new")
        dangling.write_text("created")
    assert (tmp_path / "link.json").is_symlink() and (tmp_path / "target.json").read_text() == "new"
    assert (tmp_path / "dangling.json").is_symlink() and (tmp_path / "new.json").read_text() == "created"
