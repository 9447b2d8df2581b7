"""Estimability and per-file visibility (volerr.calibrate.estimability) against rank computed
directly with numpy's SVD on designs with planted dependencies."""

import numpy as np
from hypothesis import given, settings, strategies as st

from volerr.calibrate import estimability


def _in_span(A, j) -> bool:
    """Column j of A lies in the span of the others (independent reference: SVD rank)."""
    others = np.delete(A, j, axis=1)
    r0 = np.linalg.matrix_rank(others, tol=1e-9 * np.linalg.norm(A, 2))
    r1 = np.linalg.matrix_rank(np.column_stack([others, A[:, j]]),
                               tol=1e-9 * np.linalg.norm(A, 2))
    return r1 == r0


@settings(max_examples=60, deadline=None)
@given(seed=st.integers(0, 10_000), n_dep=st.integers(0, 3))
def test_estimable_matches_rank(seed, n_dep):
    """Columns with planted dependencies, then scaled to very different units (mm, rad, um
    per mm ...): the verdict is the rank analysis of the unscaled columns."""
    rng = np.random.default_rng(seed)
    p = 8
    A = rng.normal(size=(60, p))
    for k in range(n_dep):                         # column p-1-k a combination of two others
        i, j = rng.choice(p - 1 - k, 2, replace=False)
        A[:, p - 1 - k] = rng.normal() * A[:, i] + rng.normal() * A[:, j]
    if seed % 5 == 0:
        A[:, 3] = 0.0                              # a parameter no reading sees
    scaled = A * 10.0 ** rng.uniform(-6, 3, p)
    est, partners = estimability.estimable(scaled.T @ scaled)
    for j in range(p):
        expected = np.any(A[:, j]) and not _in_span(A, j)
        assert bool(est[j]) == bool(expected), (j, est, partners)
        if not est[j] and np.any(A[:, j]):
            assert partners[j], j                  # who it is confounded with is named


def test_seen_by_removes_the_files_own_setup():
    rng = np.random.default_rng(1)
    n = 40
    setup = np.ones((n, 1))                        # an offset of the file's readings
    a = rng.normal(size=(n, 1))                    # a parameter the readings see
    b = np.full((n, 1), 3.0)                       # acts exactly as the file's offset
    c = np.zeros((n, 1))                           # does not act at all
    A = np.hstack([setup, a, b, c])
    seen = estimability.seen_by([A.T @ A], [[0]])[0]
    assert list(seen[1:]) == [True, False, False]
