"""engine.rss_stack (the bordered RSS of tau_range's profile passes) against the RSS of a
Hermitian pseudo-inverse of each whole system, as tau_range computed it before session 9:
the same to rounding, a candidate dependent on the model (a duplicate column) giving the
model's own RSS."""

from __future__ import annotations

import numpy as np

from volerr.loop.drift.engine import rss_stack


def _whole(G, h, yy, cols):
    g = G[np.ix_(cols, cols)]
    b = np.linalg.pinv(g, rcond=1e-12, hermitian=True) @ h[cols]
    return max(yy - 2 * b @ h[cols] + b @ g @ b, 0.0)


def test_rss_stack_is_the_whole_systems_rss():
    rng = np.random.default_rng(44)
    Z = rng.normal(size=(200, 8))
    Z[:, 7] = Z[:, 2]                         # column 7 duplicates column 2
    y = Z[:, :3] @ [1.0, -2.0, 0.5] + 0.3 * Z[:, 5] + rng.normal(0, 0.1, 200)
    G, h, yy = Z.T @ Z, Z.T @ y, float(y @ y)
    fixed = np.array([[0, 1, 2], [0, 3, 4], [1, 2, 3]])
    cands = np.array([5, 6, 7])
    got = rss_stack(G, h, yy, fixed, cands)
    want = np.array([[_whole(G, h, yy, list(f) + [c]) for c in cands] for f in fixed])
    np.testing.assert_allclose(got, want, rtol=1e-10)
    # the duplicate adds nothing where its twin is in the model
    assert abs(got[0, 2] - _whole(G, h, yy, [0, 1, 2])) \
        <= 1e-10 * got[0, 2]
