"""The compiled ball radius of contourgrasp.quality._kernels against Qhull and against every plane tried."""

import itertools

import numpy as np

from contourgrasp.quality import wrench_space as q
from contourgrasp import tolerances as tol
from contourgrasp.quality._kernels import ball_radii


def _every_plane(w, ok):
    """The least distance over all supporting planes through three wrenches, no plane skipped."""
    best = np.inf
    for a, b, c in itertools.combinations(np.flatnonzero(ok), 3):
        normal = np.cross(w[b] - w[a], w[c] - w[a])
        length = np.linalg.norm(normal)
        if length <= tol.WRENCH_PLANE:
            continue
        unit = normal / length
        h = unit @ w[a]
        side = w[ok] @ unit - h
        if np.all(side <= tol.WRENCH_ZERO):
            best = min(best, h)
        if np.all(side >= -tol.WRENCH_ZERO):
            best = min(best, -h)
    return best


def _grasps(rng, g, fingers):
    p = rng.normal(0, 0.04, (g, fingers, 2))
    p[: g // 4, 1] = p[: g // 4, 0]  # coincident contacts: triples spanning no plane
    n = -p + rng.normal(0, 0.02, p.shape)
    return p, n, rng.random((g, fingers)) < 0.85


def test_skipping_planes_changes_no_radius():
    rng = np.random.default_rng(3)
    p, n, valid = _grasps(rng, 200, 5)
    w = q._edge_wrenches(p, n / np.linalg.norm(n, axis=-1, keepdims=True), 0.4,
                         np.zeros((200, 2)), np.full(200, 0.05))
    ok = np.repeat(valid, 2, axis=1)
    i, j, k = q._triples(10)
    got = ball_radii(w, ok, i, j, k, tol.WRENCH_PLANE, tol.WRENCH_ZERO)
    want = [_every_plane(w[s], ok[s]) for s in range(200)]
    np.testing.assert_allclose(got, want, rtol=0, atol=1e-12)  # the same planes, summed in another order
    assert np.count_nonzero(np.isfinite(got) & (got > 0)) > 50


def test_radius_matches_qhull_on_many_five_finger_grasps():
    rng = np.random.default_rng(11)
    p, n, valid = _grasps(rng, 300, 5)
    many = q.epsilon_many(p, n, valid, mu=0.5, centre=(0.0, 0.0), rho=0.05)
    one = [q.epsilon(p[s][valid[s]], n[s][valid[s]], mu=0.5, centre=(0.0, 0.0), rho=0.05) for s in range(300)]
    np.testing.assert_allclose(many, one, atol=1e-9)
    assert 30 < np.count_nonzero(many) < 300
