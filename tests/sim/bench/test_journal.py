"""contourgrasp.sim.bench.journal: trials written as they finish, a killed bench resumed, other settings refused."""

import json
import re
import os
import signal
import subprocess
import sys
import time

import pytest

from small_bench import SMALL, serial_bench, trials_without_times  # noqa: F401 -- a fixture
from contourgrasp.cli import main
from contourgrasp.sim.bench import JOURNAL, Bench, BenchTrial, digest, settings, thesis_objects, trial_from_dict
from contourgrasp.sim.trial import TrialRecord

RECORD = dict(object="can", seed=3, success=False, cause="dropped", fingers_in_contact=("thumb", "index"),
              first_contact=(("thumb", 0.25), ("index", 0.5)), push=0.001, lift=0.12, hold_drift=0.03,
              pose=(0.01, -0.02, 1.5), approach_depth=0.4, grasp_height=None, plan_error=None, sim_time=6.1, plan_time=0.1, wall_time=1.0)


def run_cli(argv, capsys) -> tuple[int, str]:
    code = main([str(a) for a in argv])
    return code, capsys.readouterr().err


def test_a_killed_bench_resumes_where_it_stopped(serial_bench, tmp_path, capsys):
    out = tmp_path / "out"
    env = os.environ | {"MPLBACKEND": "Agg"}
    bench = subprocess.Popen([sys.executable, "-m", "contourgrasp.cli", *SMALL, "--workers", "1", "--out", str(out)],
                             stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL, env=env)
    journal = out / JOURNAL
    deadline = time.monotonic() + 120
    while time.monotonic() < deadline and bench.poll() is None:
        if journal.exists() and journal.read_text().count("\n") >= 4:  # the settings and 3 of 8 trials
            break
        time.sleep(0.05)
    bench.send_signal(signal.SIGKILL)
    bench.wait()
    written = journal.read_text().count("\n") - 1
    assert 3 <= written < 8 and not (out / "trials.json").exists()
    code = main([*SMALL, "--workers", "1", "--resume", str(out)])
    printed = capsys.readouterr()
    assert code == 0, printed.err
    assert trials_without_times(out) == trials_without_times(serial_bench)
    assert f"8 trials ({written} kept from" in printed.out
    assert journal.read_text().count("\n") == 9


@pytest.mark.parametrize("workers", ["1", "2"])
def test_ctrl_c_ends_a_bench_in_one_line_keeping_its_journal(tmp_path, capsys, workers):
    """Ctrl-C reaches the whole process group (the bench and its workers): exit 130, one line, no traceback, and the
    journal resumes to the same trials."""
    out = tmp_path / "out"
    env = os.environ | {"MPLBACKEND": "Agg"}
    bench = subprocess.Popen([sys.executable, "-m", "contourgrasp.cli", *SMALL, "--trials", "4", "--workers", workers,
                              "--out", str(out)], stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True, env=env,
                             start_new_session=True, preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))
    journal = out / JOURNAL
    deadline = time.monotonic() + 120
    while time.monotonic() < deadline and bench.poll() is None:
        if journal.exists() and journal.read_text().count("\n") >= 3:
            break
        time.sleep(0.05)
    os.killpg(bench.pid, signal.SIGINT)
    _, err = bench.communicate(timeout=120)
    lines = [line for line in err.splitlines() if not line.startswith("bench:")]  # progress lines
    assert bench.returncode == 130, err
    assert lines == [f"contourgrasp: interrupted: the trials finished are kept in {journal}; continue with --resume "
                     f"{out}"], err
    assert main([*SMALL, "--trials", "4", "--workers", "1", "--resume", str(out)]) == 0
    capsys.readouterr()


@pytest.mark.parametrize("change, setting", [
    (["--trials", "3"], "other trials: 2 there, 3 here"),
    (["--objects", "can"], "other objects: case there, not here"),
    (["--planners", "paper,random"], "other planners: centroid-principal-axis there, not here; random here, not there"),
    (["--seed", "1"], "other seed: 0 there, 1 here"),
    (["--sensor", "ideal"], "other sensor: 'structured-light' there, 'ideal' here"),
    (["--tilt", "30"], "other tilt"),
    (["--robot-in-view"], "other robot in view"),
    (["--hand", "three-finger"], "other hand"),
])
def test_resume_refuses_another_configuration_and_writes_nothing(serial_bench, change, setting, capsys):
    before = {p.name: p.read_bytes() for p in serial_bench.iterdir()}
    code, err = run_cli([*SMALL, *change, "--resume", serial_bench], capsys)
    assert code == 2 and setting in err and len(err.strip().splitlines()) == 1, err
    assert {p.name: p.read_bytes() for p in serial_bench.iterdir()} == before


def test_resume_needs_a_journal_and_one_folder(tmp_path, capsys):
    code, err = run_cli([*SMALL, "--resume", tmp_path], capsys)
    assert code == 2 and "nothing to resume" in err
    code, err = run_cli([*SMALL, "--resume", tmp_path, "--out", tmp_path / "other"], capsys)
    assert code == 2 and "name different folders" in err
    assert list(tmp_path.iterdir()) == []


def test_a_torn_last_line_is_dropped(tmp_path):
    bench = Bench(objects=thesis_objects(["can"]), planners=("paper",), trials=2)
    from contourgrasp.sim.bench import Journal, resume

    with Journal.start(tmp_path, bench) as journal:
        journal.append(BenchTrial("paper", 0, TrialRecord(**RECORD)))
    with open(tmp_path / JOURNAL, "a") as file:
        file.write('{"object": "can", "plan')  # killed while writing the second trial
    journal, done = resume(tmp_path, bench)
    journal.close()
    assert done == (BenchTrial("paper", 0, TrialRecord(**RECORD)),)
    assert (tmp_path / JOURNAL).read_text().count("\n") == 2 and (tmp_path / JOURNAL).read_text().endswith("}\n")


def test_a_record_read_back_equals_the_one_written():
    from contourgrasp.sim.bench import trial_to_dict

    result = BenchTrial("paper", 3, TrialRecord(**RECORD))
    again = trial_from_dict(json.loads(json.dumps(trial_to_dict(result))))
    assert again == result and again.record.first_contact == RECORD["first_contact"]
    assert trial_to_dict(again) == trial_to_dict(result)


def test_settings_name_what_decides_the_trials():
    one = Bench(objects=thesis_objects(["can", "case"]), planners=("paper",), trials=2)
    assert settings(one) == settings(Bench(objects=thesis_objects(["can", "case"]), planners=("paper",), trials=2))
    assert settings(one)["objects"] == ["can", "case"] and settings(one)["trials"] == 2
    assert digest(one.objects[0]) != digest(one.objects[1])


def test_the_scene_is_a_setting_only_when_it_is_not_single():
    single = Bench(objects=thesis_objects(["can"]), planners=("paper",), trials=1)
    assert "scene" not in settings(single)  # journals written before there were scenes resume
    assert settings(Bench(objects=thesis_objects(["can"]), planners=("paper",), trials=1, scene_kind="bin"))["scene"] \
        == "bin"


def test_attempts_are_a_setting_only_when_several_and_their_outcomes_are_kept():
    from dataclasses import replace

    from contourgrasp.sim.bench import trial_to_dict
    from contourgrasp.sim.bench.journal import _TrialLine

    assert "attempts" not in settings(Bench(objects=thesis_objects(["can"]), planners=("paper",), trials=1))
    assert settings(Bench(objects=thesis_objects(["can"]), planners=("paper",), trials=1, attempts=3))["attempts"] == 3
    result = BenchTrial("paper", 3, replace(TrialRecord(**RECORD), outcomes=(False, True), detected=(False, True)))
    line = json.loads(json.dumps(trial_to_dict(result)))
    _TrialLine.model_validate(line)  # the journal's schema takes them
    assert trial_from_dict(line) == result


def _journal_with(tmp_path, line: bytes, header: bytes | None = None):
    """A journal of a one-trial bench whose trial line (or header) is ``line`` (``header``), and that bench."""
    from contourgrasp.sim.bench import Journal

    bench = Bench(objects=thesis_objects(["can"]), planners=("paper",), trials=2)
    with Journal.start(tmp_path, bench) as journal:
        journal.append(BenchTrial("paper", 0, TrialRecord(**RECORD)))
    lines = (tmp_path / JOURNAL).read_bytes().split(b"\n")
    (tmp_path / JOURNAL).write_bytes(b"\n".join([header or lines[0], lines[1], line, b""]))
    return bench


def _good_line(**changes) -> bytes:
    from contourgrasp.sim.bench.report import trial_to_dict

    data = trial_to_dict(BenchTrial("paper", 1, TrialRecord(**RECORD))) | changes
    return json.dumps(data).encode()


@pytest.mark.parametrize("line, says", [
    (b"{}", "line 3: not a trial of this bench (object: Field required)"),
    (b"[1, 2]", "line 3: not a trial of this bench"),
    (b"null", "line 3: not a trial of this bench"),
    (_good_line(colour="red"), "line 3: not a trial of this bench (colour: Extra inputs are not permitted)"),
    (_good_line(success="yes"), "line 3: not a trial of this bench (success: Input should be a valid boolean)"),
    (_good_line(object="case"), "line 3: a trial this bench does not run (paper on case, trial 1)"),
    (_good_line(planner="default"), "line 3: a trial this bench does not run (default on can, trial 1)"),
    (_good_line(trial=7), "line 3: a trial this bench does not run (paper on can, trial 7)"),
    (b'{"object": ' + b"9" * 5000 + b"}", "line 3: not a trial (Exceeds the limit (4300 digits)"),
    (b"\xff\xfe{\x00}\x00", "not a bench journal (not UTF-8 text"),
])
def test_resume_names_the_line_of_a_journal_it_cannot_read(tmp_path, line, says):
    from contourgrasp.errors import SimulationError
    from contourgrasp.sim.bench import resume

    bench = _journal_with(tmp_path, line)
    before = (tmp_path / JOURNAL).read_bytes()
    with pytest.raises(SimulationError, match=re.escape(says)):
        resume(tmp_path, bench)
    assert (tmp_path / JOURNAL).read_bytes() == before


def test_resume_names_a_header_of_other_objects_without_a_traceback(tmp_path):
    from contourgrasp.errors import SimulationError
    from contourgrasp.sim.bench import resume

    header = json.dumps({"bench": {"objects": [1, 2]}}).encode()
    bench = _journal_with(tmp_path, _good_line(), header=header)
    with pytest.raises(SimulationError, match=re.escape("other objects: 1, 2 there, not here; can here, not there")):
        resume(tmp_path, bench)


def test_fuzz_resume_reads_a_journal_or_names_its_line(tmp_path_factory):
    """Random trial lines (JSON values, records with a field changed to an absurd value, bytes): resume gives trials
    or a SimulationError naming the journal; nothing else, and the journal is never changed."""
    from hypothesis import HealthCheck, given, settings
    from hypothesis import strategies as st

    from contourgrasp.errors import SimulationError
    from contourgrasp.sim.bench import resume
    from contourgrasp.sim.bench.report import trial_to_dict

    good = trial_to_dict(BenchTrial("paper", 1, TrialRecord(**RECORD)))
    absurd = st.sampled_from([None, True, -1, 10**30, 1e308, float("nan"), "", "x" * 300, [], {}, [1, "a"], {"x": 1}])
    changed = st.builds(lambda key, value: json.dumps(good | {key: value}).encode(), st.sampled_from(sorted(good)), absurd)
    values = st.recursive(st.none() | st.booleans() | st.integers() | st.floats() | st.text(max_size=5),
                          lambda inner: st.lists(inner, max_size=3) | st.dictionaries(st.text(max_size=3), inner, max_size=3),
                          max_leaves=8).map(lambda v: json.dumps(v).encode())
    lines = changed | values | st.binary(max_size=40)

    @settings(max_examples=150, deadline=None, suppress_health_check=list(HealthCheck))
    @given(line=lines)
    def check(line):
        folder = tmp_path_factory.mktemp("journal")
        bench = _journal_with(folder, line.replace(b"\n", b" "))
        before = (folder / JOURNAL).read_bytes()
        try:
            journal, trials = resume(folder, bench)
            journal.close()
            assert len(trials) == (2 if line.strip() else 1)  # a blank line is no trial
        except SimulationError as err:
            assert str(err).startswith(str(folder / JOURNAL)) and "\n" not in str(err)
            assert (folder / JOURNAL).read_bytes() == before

    check()


def test_the_protocol_is_a_setting_only_when_clearing_and_a_run_s_counts_are_kept():
    from dataclasses import replace

    from contourgrasp.sim.bench import trial_to_dict
    from contourgrasp.sim.bench.journal import _TrialLine

    assert "protocol" not in settings(Bench(objects=thesis_objects(["can"]), planners=("paper",), trials=1))
    clearing = Bench(objects=thesis_objects(["can"]), planners=("paper",), trials=1, scene_kind="bin", protocol="clear")
    assert settings(clearing)["protocol"] == "clear"
    result = BenchTrial("paper", 0, replace(TrialRecord(**RECORD), outcomes=(True, False), detected=(True, False),
                                            scene_objects=3, cleared=1, ended="failed twice in a row"))
    line = json.loads(json.dumps(trial_to_dict(result)))
    _TrialLine.model_validate(line)
    assert trial_from_dict(line) == result
