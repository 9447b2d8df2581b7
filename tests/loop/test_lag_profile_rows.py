"""Issue 42 item 7: a lag candidate's profile rows at all its time constants in one
evaluation (``Context._lag_profile_basis``): the G lagged series stacked in place of the one
lag of the first text.  Each column must be bit for bit the basis of its own text, computed
here with numpy from the same lagged series (not through volerr's expression evaluator), and
texts of another shape fall back to one evaluation per text (None)."""

import numpy as np

from volerr.loop.select import Context
from volerr.machine.lags import lag_key


class _Points:
    """What the method reads of a context: the basis variables at the points and the lagged
    series at the points (here: made-up series, one per time constant)."""

    def __init__(self, n, taus, seed=3):
        rng = np.random.default_rng(seed)
        self._values = {"X": rng.uniform(-400.0, 400.0, n), "T_a": rng.normal(21.0, 1.0, n),
                        "t_s": np.arange(n) * 15.0}
        self.lagged = {lag_key("T_a", tau): rng.normal(20.5, 1.5, n) for tau in taus}
        self.asked = []

    def values(self, full=False):
        return self._values

    def lag_at_points(self, key, col, tau, time):
        self.asked.append((key, col, tau, time))
        return self.lagged[key]


TAUS = (600.0, 612.5, 1800.0, 3600.1)


def test_each_column_is_its_own_texts_basis_bit_for_bit():
    pts = _Points(257, TAUS)
    texts = [f"X*(lag(T_a, {tau!r}) - 20)" for tau in TAUS]
    got = Context._lag_profile_basis(pts, texts)
    assert got.shape == (257, len(TAUS))
    X = pts.values()["X"]
    for g, tau in enumerate(TAUS):
        want = X * (pts.lagged[lag_key("T_a", tau)] - 20.0)
        assert np.array_equal(got[:, g], want), tau
    # each lag asked for once, in the order of the texts
    assert [a[2] for a in pts.asked] == list(TAUS)


def test_offset_term_without_a_position():
    pts = _Points(64, TAUS[:2])
    got = Context._lag_profile_basis(pts, [f"(lag(T_a, {t!r}) - 20)" for t in TAUS[:2]])
    for g, tau in enumerate(TAUS[:2]):
        assert np.array_equal(got[:, g], pts.lagged[lag_key("T_a", tau)] - 20.0)


def test_other_shapes_fall_back_to_one_evaluation_per_text():
    pts = _Points(16, TAUS[:2])
    # two lags in one text; texts that differ in more than the time constant
    assert Context._lag_profile_basis(
        pts, ["lag(T_a, 600.0) - lag(T_a, 612.5)", "lag(T_a, 612.5) - lag(T_a, 600.0)"]) is None
    assert Context._lag_profile_basis(
        pts, ["X*(lag(T_a, 600.0) - 20)", "(lag(T_a, 612.5) - 20)"]) is None
    assert Context._lag_profile_basis(pts, ["X*(T_a - 20)", "X*(T_a - 20)"]) is None


def test_time_constants_read_from_the_texts_are_the_parsers():
    """The profile reads the time constant of texts of one shape from their lag's argument
    (``_lag_calls_alike``, no parse per text): each text's (key, column, tau, time column)
    equals what the parser gives (``lag_calls``), integers, exponents, spaces and another
    time column included; a time constant the parser refuses (not > 0) gives None, so that
    the texts are evaluated one by one and the parser says what is wrong."""
    import pytest

    from volerr.errors import InputError
    from volerr.loop.select import _lag_calls_alike
    from volerr.machine.expressions import lag_calls

    for form in ("X*(lag(T_a, {}) - 20)", "(lag( T_a ,{} , t_min) - 20)*Y"):
        texts = [form.format(t) for t in ("600", "612.5", "1e3", " 3600.1 ", "2400.0")]
        assert _lag_calls_alike(texts) == [lag_calls(t) for t in texts]
    zero = ["X*lag(T_a, 600.0)", "X*lag(T_a, 0.0)"]
    assert _lag_calls_alike(zero) is None
    with pytest.raises(InputError):
        lag_calls(zero[1])
    assert _lag_calls_alike(["lag(T_a, 60) - lag(T_b, 60)"] * 2) is None
