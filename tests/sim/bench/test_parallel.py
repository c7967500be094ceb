"""contourgrasp.sim.bench.parallel: worker processes and Ray give the serial run's trials; bad settings refused."""

import os
import subprocess
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


def test_clearing_tables_in_two_workers_gives_the_serial_runs(tmp_path):
    clear = ["bench", "--objects", "can,case", "--scene", "clutter", "--protocol", "clear", "--trials", "1",
             "--planners", "default"]
    assert main([*clear, "--workers", "1", "--out", str(tmp_path / "serial")]) == 0
    assert main([*clear, "--workers", "2", "--out", str(tmp_path / "two")]) == 0
    runs = trials_without_times(tmp_path / "two")
    assert runs == trials_without_times(tmp_path / "serial") and all(r["scene_objects"] >= 2 for r in runs)
    assert "## Clearing the table" in (tmp_path / "two" / "table.md").read_text()


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
    (["--ray", "[::1"], "cannot reach Ray at '[::1': Invalid IPv6 URL"),
])
def test_bad_workers_and_unreachable_ray_exit_2_and_write_nothing(argv, message, tmp_path, capsys):
    if "--ray" in argv:
        pytest.importorskip("ray", reason="ray is not installed")
    out = tmp_path / "out"
    code, err = run_cli([*SMALL, *argv, "--out", out], capsys)
    assert code == 2 and message in err and len(err.strip().splitlines()) == 1, err
    assert not out.exists()


def test_an_address_that_accepts_but_is_not_ray_fails_fast(tmp_path, capsys, monkeypatch):
    """A server that accepts the connection and says nothing (or speaks HTTP/1): refused in about the timeout, not
    after Ray's own minutes of retries."""
    import socket
    import threading
    import time

    from contourgrasp.sim.bench import parallel

    pytest.importorskip("ray", reason="ray is not installed")
    monkeypatch.setattr(parallel, "RAY_CONNECT_TIMEOUT", 1.0)
    with socket.create_server(("127.0.0.1", 0)) as server:
        accepted = []
        threading.Thread(target=lambda: accepted.append(server.accept()), daemon=True).start()
        out, started = tmp_path / "out", time.monotonic()
        code, err = run_cli([*SMALL, "--ray", f"127.0.0.1:{server.getsockname()[1]}", "--out", out], capsys)
        assert code == 2 and "does not answer as Ray does (gRPC)" in err and len(err.strip().splitlines()) == 1, err
        assert time.monotonic() - started < 10 and not out.exists()


def test_more_workers_than_cores_run_as_many_processes_as_cores(serial_bench, tmp_path, capsys):
    code, err = run_cli([*SMALL, "--workers", "1000", "--out", tmp_path], capsys)
    assert code == 0 and f"--workers 1000: this machine has {os.cpu_count()} cores" in err
    assert trials_without_times(tmp_path) == trials_without_times(serial_bench)


def test_a_ray_cluster_at_an_address_gives_the_serial_trials(serial_bench, tmp_path):
    """A real Ray head started by ``ray start`` on a free port, the bench sent to it by address."""
    import shutil
    import socket

    pytest.importorskip("ray", reason="ray is not installed")
    ray_command = shutil.which("ray", path=os.path.dirname(sys.executable))
    if ray_command is None:
        pytest.skip("the ray command is not installed beside this Python")
    with socket.create_server(("127.0.0.1", 0)) as probe:
        port = probe.getsockname()[1]
    env = os.environ | {"RAY_USAGE_STATS_ENABLED": "0"}
    start = [ray_command, "start", "--head", f"--port={port}", "--num-cpus=2", "--include-dashboard=false",
             "--disable-usage-stats"]
    subprocess.run(start, check=True, capture_output=True, timeout=180, env=env)
    try:
        done = subprocess.run([sys.executable, "-m", "contourgrasp.cli", *SMALL, "--ray", f"127.0.0.1:{port}",
                               "--out", str(tmp_path)], capture_output=True, text=True, timeout=600, env=env)
        assert done.returncode == 0, done.stderr[-2000:]
    finally:
        subprocess.run([ray_command, "stop", "--force"], capture_output=True, timeout=180, env=env)
    assert trials_without_times(tmp_path) == trials_without_times(serial_bench)


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
