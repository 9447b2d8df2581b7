"""Base.reduced (volerr.loop.select): the design reduced against a target is kept and reused
by the bytes of the target column, and a reused value gives term_gains' numbers bit for bit
(the lag search asks for a few dozen targets thousands of times)."""

import numpy as np

from volerr.loop import select


def _base(rng, n=40, p=5):
    A = rng.standard_normal((3 * n, p))
    y = rng.standard_normal(3 * n)
    return select.Base(A, y)


def test_equal_targets_reuse_one_reduction_and_distinct_ones_do_not():
    rng = np.random.default_rng(0)
    base = _base(rng)
    s1, s2 = rng.standard_normal((40, 3)), rng.standard_normal((40, 3))
    first = base.reduced(s1)
    assert base.reduced(s1.copy()) is first          # equal bytes: the kept value
    assert base.reduced(s2) is not first              # another target: its own
    assert not np.array_equal(base.reduced(s2)[0], first[0])


def test_kept_reductions_give_the_fresh_numbers_bit_for_bit():
    rng = np.random.default_rng(1)
    A = rng.standard_normal((120, 5))
    y = rng.standard_normal(120)
    targets = [rng.standard_normal((40, 3)) for _ in range(select.REDUCED_CACHE + 3)]
    basis = rng.standard_normal((40, 6))
    cuts = np.array([0, 1, 3, 6])
    kept = select.Base(A, y)
    for rnd in range(2):                 # the second round: kept or evicted and recomputed
        for s in targets:
            fresh = select.Base(A, y)
            for got, want in ((kept.term_gains(s.copy(), basis), fresh.term_gains(s, basis)),
                              (kept.term_gains(s.copy(), basis, cuts),
                               fresh.term_gains(s, basis, cuts))):
                assert np.array_equal(got[0], want[0]) and np.array_equal(got[1], want[1])
    assert len(kept._reduced) == select.REDUCED_CACHE
