"""Estimability and per-file visibility (volerr.calibrate.estimability) against rank computed
directly with numpy's SVD on designs with planted dependencies."""

import numpy as np
from hypothesis import example, given, settings, strategies as st

from volerr.calibrate import estimability


def _distance(A, j) -> float:
    """Distance of column j of A, scaled to unit length, to the span of the others, likewise
    scaled (independent reference: numpy's SVD least squares on the columns themselves, not
    on a Gram matrix; 0 for a zero column)."""
    norms = np.linalg.norm(A, axis=0)
    if norms[j] == 0:
        return 0.0
    U = A / np.where(norms > 0, norms, 1.0)
    others = np.delete(U, j, axis=1)
    x = np.linalg.lstsq(others, U[:, j], rcond=1e-12)[0]
    return float(np.linalg.norm(U[:, j] - others @ x))


@settings(max_examples=60, deadline=None)
@given(seed=st.integers(0, 10_000), n_dep=st.integers(0, 3))
@example(seed=35, n_dep=2)
@example(seed=35, n_dep=3)
def test_estimable_matches_rank(seed, n_dep):
    """Columns with planted dependencies, then scaled to very different units (mm, rad, um
    per mm ...): the verdict is the one of the rank analysis of the unscaled columns with the
    estimability tolerance (a column farther than DISTANCE_TOL from the span of the others),
    including near-degenerate columns (seed 35, n_dep 2: a column entering a dependency with
    a coefficient 7e-5, in the span exactly, which the Gram matrix alone resolved only to
    3e-4).  Columns within a factor 2 of the tolerance are the stated resolution, not
    checked (none among these examples)."""
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
        d = _distance(A, j)
        if 0.5 * estimability.DISTANCE_TOL < d < 2 * estimability.DISTANCE_TOL:
            continue
        expected = d > estimability.DISTANCE_TOL
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
