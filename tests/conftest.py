"""Shared test helpers: analytic shapes in meters."""

import numpy as np
import pytest


def disc(radius: float, centre=(0.0, 0.0), n: int = 360) -> np.ndarray:
    theta = np.linspace(0, 2 * np.pi, n, endpoint=False)
    return np.c_[centre[0] + radius * np.cos(theta), centre[1] + radius * np.sin(theta)]


def rotate(points: np.ndarray, angle: float, about=(0.0, 0.0)) -> np.ndarray:
    c, s = np.cos(angle), np.sin(angle)
    about = np.asarray(about)
    return (np.asarray(points) - about) @ np.array([[c, -s], [s, c]]).T + about


@pytest.fixture
def circle():
    return disc(0.04)


def blas_threads() -> set[int]:
    """The thread counts of numpy's BLAS libraries loaded in this process."""
    from threadpoolctl import threadpool_info

    return {pool["num_threads"] for pool in threadpool_info() if pool["user_api"] == "blas"}
