"""Threads of numpy's BLAS while contourgrasp plans in a loop (the ROS node, the bench's trials).

numpy's OpenBLAS starts a thread per core and, after each call, lets them spin
a while for the next one. A plan's BLAS calls are small (the table's RANSAC
votes, 3 x 3 fits), so a second thread plans no faster; it spins a core through
every plan, which the ROS node pays in CPU time (twice its wall time) and the
bench's workers in time taken from each other (README, "Latency";
``benchmarks/bench_throughput.py``). :func:`one_blas_thread` limits BLAS to one
thread for a block and gives the process its own setting back after it.
"""

from __future__ import annotations

from threadpoolctl import ThreadpoolController

_controller: ThreadpoolController | None = None


def one_blas_thread():
    """A context manager: numpy's BLAS on one thread within it, as it was after it.

    Examples
    --------
    >>> from threadpoolctl import threadpool_info
    >>> with one_blas_thread():
    ...     {pool["num_threads"] for pool in threadpool_info() if pool["user_api"] == "blas"} <= {1}
    True
    """
    global _controller
    if _controller is None:  # finding the loaded libraries takes ~1 ms; a limit then 7 us
        _controller = ThreadpoolController()
    return _controller.limit(limits=1, user_api="blas")
