"""The rules of model selection, stated once (the 3-D loop :mod:`volerr.loop.select`, the
drift loop :mod:`volerr.loop.drift.select` and the interim check :mod:`volerr.check._select`
apply them; their scorers stay their own).

* **BIC gain**: a term (an effect, a parameter, a sensor) enters when it lowers the BIC
  ``n ln(RSS/n) + m ln n`` (natural-log units; ``n`` readings, ``m`` parameters) by more than
  ``BIC_GAIN`` (:func:`delta_bic`).  Two explanations within ``BIC_TIE`` of each other are
  not told apart by the BIC (an *alternative*).
* **CV gain and its t**: where the evidence is the cross-validated residual, a term must
  lower it significantly: the paired t of the held-out per-point squared residuals without
  minus with it (:func:`paired_t`) above ``CV_T``; where the score is the cross-validated
  mean square of blocked folds (drift runs: few, long, autocorrelated folds), by at least
  ``CV_GAIN`` relative (:func:`cv_gain`).  Two explanations whose cross-validated RMS agree
  within ``CV_SAME`` are not told apart in practice.
* **Ties**: two scores are one fit when they agree to a tolerance far above the last bits of
  the arithmetic and far below any difference the data can show; the tie goes to the first
  in a stated order, never to rounding.  Two tolerances, one per kind of score:
  ``TIE_BIC_REL |d0| + TIE_BIC_ABS`` for BIC changes of column groups (:func:`tied`; columns
  that span one space differ between BLAS kernels in the last ~1e-12 of the residual), and
  ``TIE_SCORE_REL`` (relative) for cross-validated mean squares and chi-square reductions.
* **Significance k**: a coefficient ``|value| < SIG_K u`` (``u`` its standard uncertainty) is
  not significant: it is not part of an effect (:func:`significant`).
* **Lag earn**: a lag (a searched time constant) is taken only where it gains more than
  ``LAG_EARN`` BIC over the same covariate without one (the plain covariate is the limit
  tau -> 0).

* **Quantiles**: Student's t one-sided 95 % (:func:`t95`, a table) and Fisher's F(q; 1, nu)
  (:func:`f_quantile`, the square of the two-sided t from its closed form
  :func:`t_two_sided`; the threshold of a profile range, :mod:`volerr.loop.drift.tau_range`).

Reference: Schwarz (1978) for the BIC; Abramowitz & Stegun (1964) 26.7.3-4 for t.
"""

from __future__ import annotations

import math

import numpy as np

#: minimum BIC improvement (natural-log units) to accept a term
BIC_GAIN = 10.0
#: BIC difference below which two explanations are not told apart
BIC_TIE = 10.0
#: minimum paired t of the held-out improvement
CV_T = 3.0
#: relative drop of the cross-validated mean square a term must bring (blocked folds)
CV_GAIN = 0.01
#: cross-validated RMS within 1 %: two explanations not told apart in practice
CV_SAME = 0.01
#: BIC changes equal within ``TIE_BIC_REL |dBIC| + TIE_BIC_ABS`` are one fit (a tie)
TIE_BIC_REL = 1e-7
TIE_BIC_ABS = 1e-9
#: relative difference of two cross-validated scores (or chi-square values) below which they
#: are tied
TIE_SCORE_REL = 1e-9
#: coverage factor of the significance test of a coefficient
SIG_K = 2.0
#: BIC a lag must gain over the same covariate without one
LAG_EARN = 10.0


def delta_bic(n: int, rss_new: float, rss_old: float, m: int) -> float:
    """BIC change ``n ln(rss_new / rss_old) + m ln n`` of adding ``m`` parameters (both RSS
    floored at 1e-300)."""
    return n * math.log(max(rss_new, 1e-300) / max(rss_old, 1e-300)) + m * math.log(n)


def bic_accepts(dbic: float) -> bool:
    """Whether a BIC change earns a place: ``dbic <= -BIC_GAIN``."""
    return dbic <= -BIC_GAIN


def paired_t(d) -> float:
    """Paired t of the differences ``d`` (held-out squared residuals without minus with the
    term: positive when the term predicts held-out points better)."""
    d = np.asarray(d, float)
    return float(d.mean() / (d.std(ddof=1) / math.sqrt(len(d)) + 1e-300))


def cv_gain(new: float, current: float, gain: float = CV_GAIN) -> bool:
    """Whether a cross-validated mean square ``new`` is below ``current`` by ``gain``
    (relative)."""
    return new <= current * (1 - gain)


def tied(d0: float, d1: float) -> bool:
    """Whether two BIC changes are one fit: equal within ``TIE_BIC_REL |d0| + TIE_BIC_ABS``.
    Columns that span the same space on these data (a tool that grows and a Z error of the
    axis holding it, seen at one tool length) give the same residual up to the last bits of
    the arithmetic, which differ between BLAS kernels; the tolerance is far above those bits
    and far below any difference the data can show."""
    return abs(d1 - d0) <= TIE_BIC_REL * abs(d0) + TIE_BIC_ABS


def significant(value: float, u: float | None) -> bool:
    """Whether a coefficient is significant: ``|value| >= SIG_K u`` (no uncertainty: yes)."""
    return u is None or not abs(value) < SIG_K * u


#: one-sided 95 % quantiles of Student's t, df = 1 .. 30 (beyond: the normal 1.645)
T95_ONE_SIDED = (6.314, 2.920, 2.353, 2.132, 2.015, 1.943, 1.895, 1.860, 1.833, 1.812,
                 1.796, 1.782, 1.771, 1.761, 1.753, 1.746, 1.740, 1.734, 1.729, 1.725,
                 1.721, 1.717, 1.714, 1.711, 1.708, 1.706, 1.703, 1.701, 1.699, 1.697)


def t95(df: int) -> float:
    """One-sided 95 % quantile of Student's t with ``df`` degrees of freedom (table)."""
    return T95_ONE_SIDED[df - 1] if df <= len(T95_ONE_SIDED) else 1.645


def f_quantile(q: float, nu: float) -> float:
    """F(q; 1, nu): the q quantile of Fisher's F with 1 and ``nu`` (a whole number) degrees
    of freedom, the square of Student's t two-sided: P(abs(T) <= t) = q, from the closed form
    of Abramowitz & Stegun (1964, *Handbook of Mathematical Functions*, 26.7.3-4) solved by
    bisection (no scipy at run time)."""
    n = int(round(nu))
    lo, hi = 0.0, 1e4
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        if t_two_sided(mid, n) < q:
            lo = mid
        else:
            hi = mid
    return (0.5 * (lo + hi)) ** 2


def t_two_sided(t: float, n: int) -> float:
    """P(abs(T) <= t) for Student's T with ``n`` >= 1 degrees of freedom (A & S 26.7.3-4)."""
    th = math.atan(t / math.sqrt(n))
    sn, cs = math.sin(th), math.cos(th)
    if n % 2:
        term, acc = cs, (cs if n > 1 else 0.0)
        for k in range(3, n - 1, 2):           # cos th (1 + 2/3 cos^2 + 2 4/(3 5) cos^4 ...)
            term *= (k - 1) / k * cs * cs
            acc += term
        return 2.0 / math.pi * (th + sn * acc)
    term, acc = 1.0, 1.0
    for k in range(2, n - 1, 2):               # 1 + 1/2 cos^2 + 1 3/(2 4) cos^4 ...
        term *= (k - 1) / k * cs * cs
        acc += term
    return sn * acc


def significantly_below(err_new, err_old) -> bool:
    """Whether the cross-validated mean squares ``err_new`` of n equal blocks of held-out
    readings are significantly below ``err_old`` (the same blocks): the paired t over the
    blocks of ``err_old - err_new`` (:func:`paired_t`) at least the one-sided 95 % Student
    quantile with n - 1 degrees of freedom (:func:`t95`), the mean difference positive.  The
    mean of those differences is the difference of the pooled cross-validated mean squares
    (the score the selection minimises); the test asks that it stand out of its
    block-to-block scatter.  The rule by which a more complex model family (the drift loop's
    lag model) replaces a simpler one (a static regression, a constant)."""
    d = np.asarray(err_old, float) - np.asarray(err_new, float)
    return len(d) >= 2 and d.mean() > 0 and paired_t(d) >= t95(len(d) - 1)
