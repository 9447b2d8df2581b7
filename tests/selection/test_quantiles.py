"""The quantile functions of the selection rules, side by side in
:mod:`volerr.selection.rules`: Fisher's F(q; 1, nu) from the closed form of Student's t
(:func:`f_quantile`, the profile range's threshold) against Abramowitz & Stegun's table, and
the one-sided 95 % t table (:func:`t95`) against the same closed form."""

import pytest

from volerr.selection import rules


def test_f_quantile():
    """F(0.95; 1, nu): tabulated values (Abramowitz & Stegun 1964, table 26.9: 161.45,
    18.513, 4.9646, 4.0847 at nu = 1, 2, 10, 40)."""
    for nu, want in ((1, 161.45), (2, 18.513), (10, 4.9646), (40, 4.0847)):
        assert rules.f_quantile(0.95, nu) == pytest.approx(want, rel=2e-4)


@pytest.mark.parametrize("df", [1, 2, 5, 10, 30])
def test_t95_table_agrees_with_the_closed_form(df):
    """A one-sided 95 % quantile is a two-sided 90 % one: P(abs(T) <= t95) = 0.90 within the
    table's three decimals; and F(0.90; 1, df) is its square."""
    assert rules.t_two_sided(rules.t95(df), df) == pytest.approx(0.90, abs=2e-4)
    assert rules.f_quantile(0.90, df) == pytest.approx(rules.t95(df) ** 2, rel=1e-3)
