"""Where a bench's trials run: in this process, in worker processes, or as Ray tasks.

A trial is a pure function of the bench's settings, the object, the planner's
name and the trial's index (:func:`trial_task`: the seed is ``seed + trial``,
the planner is built afresh), so the records are the same, bit for bit apart
from the timing fields, whichever of :func:`serial`, :func:`processes` or
:func:`ray_tasks` runs them and in whatever order they finish. Each hands the
bench to its workers once; a task is then only (planner, object index, trial).

Each is a context manager yielding ``run(tasks)``, an iterator of the
:class:`~contourgrasp.sim.bench.config.BenchTrial` of ``tasks`` (as
:meth:`~contourgrasp.sim.bench.config.Bench.tasks` lists them) in the order
they finish.
"""

from __future__ import annotations

import contextlib
import logging
import multiprocessing
import os
import socket
import warnings
from concurrent.futures import ProcessPoolExecutor, as_completed
from concurrent.futures.process import BrokenProcessPool
from urllib.parse import urlsplit

from ...errors import ContourGraspWarning, SimulationError
from ...threads import one_blas_thread
from ...validation import integer
from .config import Bench, BenchTrial

#: Seconds to wait for a Ray cluster's address to accept a connection.
RAY_CONNECT_TIMEOUT = 10.0
#: Ports of a Ray address given without one: the Ray client's (``ray://``) and the cluster's (GCS).
RAY_CLIENT_PORT, RAY_GCS_PORT = 10001, 6379
#: The install command named when Ray is missing.
RAY_INSTALL = "pip install 'contourgrasp[cluster]'"

_bench: Bench | None = None  # a worker process's bench, set once by its initializer


def cores() -> int:
    """CPU cores this process may run on."""
    try:
        return len(os.sched_getaffinity(0))
    except AttributeError:  # macOS, Windows
        return os.cpu_count() or 1


def trial_task(bench: Bench, planner: str, index: int, trial: int) -> BenchTrial:
    """Trial ``trial`` (0-based) of ``planner`` on ``bench.objects[index]``, with numpy's BLAS on one thread
    (:mod:`contourgrasp.threads`: a second would spin a core the other workers need)."""
    with one_blas_thread():
        return BenchTrial(planner, trial, bench.run(planner, bench.objects[index], trial))


@contextlib.contextmanager
def serial(bench: Bench):
    """Run the trials one after another in this process."""
    yield lambda tasks: (trial_task(bench, *task) for task in tasks)


@contextlib.contextmanager
def processes(bench: Bench, workers: int):
    """Run the trials in ``workers`` processes (forkserver where the platform has it, else spawn).

    Neither start method copies this process's state (MuJoCo models, numba's
    threads) into the workers; they import the library afresh.

    Raises
    ------
    SimulationError
        A worker died (killed, out of memory); the trials written so far are kept (``--resume``).
    """
    method = "forkserver" if "forkserver" in multiprocessing.get_all_start_methods() else "spawn"
    context = multiprocessing.get_context(method)
    if method == "forkserver":
        context.set_forkserver_preload([__name__])
    pool = ProcessPoolExecutor(workers, mp_context=context, initializer=_set_bench, initargs=(bench,))

    def run(tasks):
        futures = [pool.submit(_pooled_trial, *task) for task in tasks]
        try:
            for future in as_completed(futures):
                yield future.result()
        except BrokenProcessPool as err:
            raise SimulationError(f"a bench worker process died ({err}); rerun with --resume to continue") from err
        finally:
            for future in futures:
                future.cancel()

    try:
        yield run
    finally:
        pool.shutdown(wait=True, cancel_futures=True)


def _set_bench(bench: Bench) -> None:
    global _bench
    _bench = bench


def _pooled_trial(planner: str, index: int, trial: int) -> BenchTrial:
    return trial_task(_bench, planner, index, trial)


@contextlib.contextmanager
def ray_tasks(bench: Bench, address: str | None, *, workers: int):
    """Run every trial as a Ray task: on the cluster at ``address``, or on a local Ray of ``workers`` CPUs.

    Without an address a Ray instance is started on this machine (no
    dashboard, at most its cores) and stopped at the end; with one, Ray must
    already run there with this library installed on its nodes. A task whose
    worker dies is retried by Ray (its default ``max_retries``).

    Raises
    ------
    SimulationError
        Ray is not installed (the message names the install command), or the
        cluster at ``address`` cannot be reached within :data:`RAY_CONNECT_TIMEOUT`.
    """
    try:
        import ray
    except ImportError as err:
        raise SimulationError(f"--ray needs the ray package: {RAY_INSTALL}") from err
    started = _connect(ray, address, workers)
    try:
        remote = ray.remote(trial_task)
        shared = ray.put(bench)

        def run(tasks):
            pending = [remote.remote(shared, *task) for task in tasks]
            try:
                while pending:
                    ready, pending = ray.wait(pending, num_returns=1)
                    yield ray.get(ready[0])
            finally:
                for ref in pending:
                    ray.cancel(ref)

        yield run
    finally:
        if started:
            ray.shutdown()


def _connect(ray, address: str | None, workers: int) -> bool:
    """Initialise Ray (True) unless it already is (False)."""
    if ray.is_initialized():
        return False
    quiet = {"logging_level": logging.ERROR, "log_to_driver": False}
    if address:
        _reachable(address)
    try:
        if address:
            ray.init(address=address, **quiet)
        else:
            ray.init(num_cpus=max(1, min(workers, cores())), include_dashboard=False, **quiet)
    except (ConnectionError, RuntimeError, ValueError, TimeoutError) as err:
        message = str(err).strip().splitlines()[0] if str(err).strip() else type(err).__name__
        raise SimulationError(f"cannot start Ray{f' at {address!r}' if address else ''}: {message}") from err
    return True


def _reachable(address: str) -> None:
    """Refuse an address whose host does not accept a connection, or does not answer as a gRPC server (Ray's GCS
    and Ray Client both are), within :data:`RAY_CONNECT_TIMEOUT`: Ray itself would wait minutes on either."""
    if address in ("auto", "local"):
        return
    client = address.startswith("ray://")
    try:
        parts = urlsplit(address if "://" in address else f"//{address}")
        host, port = parts.hostname, parts.port or (RAY_CLIENT_PORT if client else RAY_GCS_PORT)
    except ValueError as err:  # a port that is not a number, an unclosed IPv6 bracket
        raise SimulationError(f"cannot reach Ray at {address!r}: {err}") from None
    if not host:
        raise SimulationError(f"cannot reach Ray at {address!r}: no host in the address")
    try:
        with socket.create_connection((host, port), timeout=RAY_CONNECT_TIMEOUT) as connection:
            answer = _http2_answer(connection)
    except OSError as err:
        reason = err.strerror or str(err) or type(err).__name__
        raise SimulationError(f"cannot reach Ray at {address!r} ({host}:{port}): {reason}") from None
    if answer is None:
        raise SimulationError(f"cannot reach Ray at {address!r} ({host}:{port}): the server there does not answer as "
                              f"Ray does (gRPC) within {RAY_CONNECT_TIMEOUT:g} s; is it Ray's port "
                              f"({RAY_GCS_PORT}, or {RAY_CLIENT_PORT} with ray://)?")


#: The HTTP/2 connection preface and an empty SETTINGS frame: what a gRPC client sends first.
HTTP2_PREFACE = b"PRI * HTTP/2.0\r\n\r\nSM\r\n\r\n" + bytes([0, 0, 0, 4, 0, 0, 0, 0, 0])
HTTP2_SETTINGS = 4


def _http2_answer(connection: socket.socket) -> bytes | None:
    """The first frame header a server sends after the HTTP/2 preface, or None when it sends none, or no SETTINGS."""
    connection.settimeout(RAY_CONNECT_TIMEOUT)
    try:
        connection.sendall(HTTP2_PREFACE)
        header = b""
        while len(header) < 9:
            chunk = connection.recv(9 - len(header))
            if not chunk:
                return None
            header += chunk
    except socket.timeout:
        return None
    return header if header[3] == HTTP2_SETTINGS else None


def executor(bench: Bench, *, workers: int | None = None, ray: bool = False, address: str | None = None):
    """The runner ``--workers`` and ``--ray`` choose: Ray tasks, ``workers`` processes, or this process (1).

    Raises
    ------
    SimulationError
        ``workers`` not an integer >= 1 (default: :func:`cores`).
    """
    workers = cores() if workers is None else integer("workers", workers, 1, error=SimulationError)
    if workers > cores() and not ray:
        warnings.warn(ContourGraspWarning(f"--workers {workers}: this machine has {cores()} cores; running "
                                          f"{cores()} processes"), stacklevel=2)
        workers = cores()
    if ray:
        return ray_tasks(bench, address, workers=workers)
    if workers == 1 or bench.size == 1:
        return serial(bench)
    return processes(bench, min(workers, bench.size))
