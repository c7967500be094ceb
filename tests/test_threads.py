"""numpy's BLAS on one thread within a block (contourgrasp.threads), the process's own setting after it."""

from threadpoolctl import threadpool_limits

from contourgrasp.threads import one_blas_thread
from conftest import blas_threads


def test_one_blas_thread_within_the_block_and_the_processs_own_after_it():
    with threadpool_limits(limits=2, user_api="blas"):
        assert blas_threads() == {2}
        with one_blas_thread():
            assert blas_threads() == {1}
        assert blas_threads() == {2}
