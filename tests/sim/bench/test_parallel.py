"""contourgrasp.sim.bench.parallel: worker processes and Ray give the serial run's trials; bad settings refused."""

import sys

import pytest

from small_bench import SMALL, serial_bench, trials_without_times  # noqa: F401 -- a fixture
from contourgrasp.cli import main
from contourgrasp.errors import SimulationError
from contourgrasp.sim.bench import RAY_INSTALL, Bench, executor, thesis_objects


def run_cli(argv, capsys) -> tuple[int, str]:
    code = main([str(a) for a in argv])
    return code, capsys.readouterr().err


def test_two_workers_give_the_serial_trials_bit_for_bit(serial_bench, tmp_path):
    assert main([*SMALL, "--workers", "2", "--out", str(tmp_path)]) == 0
    assert trials_without_times(tmp_path) == trials_without_times(serial_bench)
    table = (tmp_path / "table.md").read_text().splitlines()
    serial = (serial_bench / "table.md").read_text().splitlines()
    assert [line for line in table if "time" not in line] == [line for line in serial if "time" not in line]


def test_a_trial_runs_with_numpys_blas_on_one_thread(monkeypatch):
    from threadpoolctl import threadpool_limits

    from conftest import blas_threads
    from contourgrasp.sim.bench import trial_task

    bench, during, run = Bench(objects=thesis_objects(["can"]), planners=("paper",), trials=1), [], Bench.run
    monkeypatch.setattr(Bench, "run", lambda self, *task: during.append(blas_threads()) or run(self, *task))
    with threadpool_limits(limits=2, user_api="blas"):
        assert trial_task(bench, "paper", 0, 0).record.object == "can"
        assert during == [{1}] and blas_threads() == {2}


def test_a_local_ray_gives_the_serial_trials(serial_bench, tmp_path):
    pytest.importorskip("ray", reason="ray is not installed (pip install 'contourgrasp[cluster]')")
    assert main([*SMALL, "--ray", "--workers", "2", "--out", str(tmp_path)]) == 0
    assert trials_without_times(tmp_path) == trials_without_times(serial_bench)


@pytest.mark.parametrize("argv, message", [
    (["--workers", "0"], "argument --workers: must be a positive integer, got '0'"),
    (["--workers", "-2"], "argument --workers: must be a positive integer"),
    (["--workers", "two"], "argument --workers: must be a positive integer, got 'two'"),
    (["--ray", "127.0.0.1:1"], "cannot reach Ray at '127.0.0.1:1'"),
    (["--ray", "ray://127.0.0.1:1"], "cannot reach Ray at 'ray://127.0.0.1:1' (127.0.0.1:1)"),
    (["--ray", "127.0.0.1:port"], "cannot reach Ray at '127.0.0.1:port'"),
    (["--ray", "ray://:5"], "no host in the address"),
])
def test_bad_workers_and_unreachable_ray_exit_2_and_write_nothing(argv, message, tmp_path, capsys):
    if "--ray" in argv:
        pytest.importorskip("ray", reason="ray is not installed")
    out = tmp_path / "out"
    code, err = run_cli([*SMALL, *argv, "--out", out], capsys)
    assert code == 2 and message in err and len(err.strip().splitlines()) == 1, err
    assert not out.exists()


def test_ray_missing_names_the_install_command(tmp_path, capsys, monkeypatch):
    monkeypatch.setitem(sys.modules, "ray", None)  # import ray now raises ImportError
    out = tmp_path / "out"
    code, err = run_cli([*SMALL, "--ray", "--out", out], capsys)
    assert code == 2 and RAY_INSTALL in err and len(err.strip().splitlines()) == 1
    assert not out.exists()


@pytest.mark.parametrize("workers", [0, -1, 1.5, "2", True])
def test_executor_refuses_bad_worker_counts(workers):
    with pytest.raises(SimulationError, match="workers must be an integer"):
        executor(Bench(objects=thesis_objects(["can"]), trials=1), workers=workers)
