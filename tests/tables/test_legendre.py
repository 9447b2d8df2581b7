"""The one Legendre fit: leave-one-out errors equal explicit refits; weights act as numpy's
``legfit`` weights; the degree choice recovers an exact polynomial's degree."""

import numpy as np
import pytest

from volerr.tables import legendre


def _explicit_loo(x, y, degree, w):
    out = []
    for i in range(len(x)):
        keep = np.arange(len(x)) != i
        lo, hi = x.min(), x.max()  # the scaling of the full data (it does not change the fit)
        t = (x - 0.5 * (lo + hi)) / (0.5 * (hi - lo))
        c = np.polynomial.legendre.legfit(t[keep], y[keep], degree, w=w[keep])
        out.append(y[i] - np.polynomial.legendre.legval(t[i], c))
    return np.array(out)


@pytest.mark.parametrize("weighted", [False, True])
@pytest.mark.parametrize("degree", [0, 2, 4])
def test_loo_errors_equal_refits_without_the_point(weighted, degree):
    rng = np.random.default_rng(degree)
    x = np.sort(rng.uniform(-200, 500, 13))
    y = 1e-3 * np.sin(x / 90.0) + rng.normal(0, 1e-4, x.size)
    w = rng.uniform(0.5, 2.0, x.size) if weighted else np.ones(x.size)
    got = legendre.loo_errors(x, y, degree, w if weighted else None)
    np.testing.assert_allclose(got, _explicit_loo(x, y, degree, w), rtol=1e-8, atol=1e-15)


def test_choice_recovers_the_degree_of_an_exact_cubic():
    x = np.linspace(0.0, 600.0, 15)
    t = x / 600.0
    y = 0.01 * (1 - 3 * t + 2.5 * t ** 3) + np.random.default_rng(3).normal(0, 1e-7, x.size)
    f = legendre.fit(x, y)
    assert f.degree == 3
    q = np.linspace(0, 600, 7)
    np.testing.assert_allclose(f(q), 0.01 * (1 - 3 * q / 600 + 2.5 * (q / 600) ** 3),
                               atol=1e-6)


def test_weights_match_numpy_legfit():
    rng = np.random.default_rng(8)
    x = np.linspace(-50, 50, 11)
    y = rng.normal(size=x.size)
    w = rng.uniform(0.2, 3.0, x.size)
    f = legendre.LegendreFit(x, y, 3, w)
    np.testing.assert_allclose(f.coef, np.polynomial.legendre.legfit(x / 50.0, y, 3, w=w))
