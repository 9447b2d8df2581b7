"""The profile of a residual sum of squares over ``x = ln tau`` (a lag's time constant): the
RSS at a few values of ``x`` around a start, re-centred where the least lies at the edge of
the range, and a parabola through them whose vertex is the estimate and whose curvature
``q`` (``RSS ~ q (x - x*)^2 + ...``) gives its uncertainty (the profile-likelihood
curvature: the other parameters re-fitted at every ``tau``).

Two re-centring rules, one per caller (both kept as they were measured):

* :func:`profile_argmin` (the 3-D loop, :mod:`volerr.loop.lags`): re-centre on the least
  value while it is the first or last of the range, then a parabola through the best seven
  values around it, its vertex kept within them;
* :func:`profile_vertex` (the drift loop's jackknife, :mod:`volerr.loop.drift.fit`): a
  parabola through all values; where its vertex lies at the edge of the range (or the
  profile is not convex: the least value), search again around it.
"""

from __future__ import annotations

import math

import numpy as np


def profile_argmin(rss_at, x0: float, steps, tries: int = 4):
    """``rss_at(xs) -> (rss (len(xs),), payload list)`` at ``xs = x0 + steps`` (re-centred
    at most ``tries`` times while the least is at an edge): (vertex x, curvature coefficient
    q, least RSS, payload at the least), or None where the profile is not convex."""
    for _ in range(tries):
        xs = x0 + steps
        rss, payload = rss_at(xs)
        k = int(np.argmin(rss))
        if 0 < k < len(xs) - 1:
            break
        x0 = xs[k]
    lo, hi = max(k - 3, 0), min(k + 4, len(xs))
    q, b, _ = np.polyfit(xs[lo:hi] - xs[k], rss[lo:hi], 2)
    if not q > 0:
        return None
    x_best = xs[k] + float(np.clip(-b / (2 * q), xs[lo] - xs[k], xs[hi - 1] - xs[k]))
    return x_best, float(q), float(rss[k]), payload[k]


def profile_vertex(rss_at, half: float, n: int = 7, tries: int = 3) -> tuple[float, bool]:
    """``rss_at(x0, xs) -> rss (n,)`` at ``x0 + xs``, ``xs`` n values over ``+- half``: (the
    offset ``x`` of the least RSS from the start, whether it lies at the edge of the range
    searched after ``tries`` re-centrings)."""
    xs = np.linspace(-half, half, n)
    x0 = 0.0
    for _ in range(tries):
        rss = rss_at(x0, xs)
        q, lin, _ = np.polyfit(xs, rss, 2)
        x = float(np.clip(-lin / (2 * q), -half, half)) if q > 0 \
            else float(xs[int(np.argmin(rss))])
        if abs(x) < half * (1 - 1e-9):
            return x0 + x, False
        x0 += x             # the least RSS at the edge: search again around it
    return x0, True


def tau_std(tau: float, q: float, rss_min: float, dof: int) -> float:
    """Standard uncertainty of ``tau`` from the profile's curvature: ``u(x) = sqrt(2 s^2 /
    RSS''(x))`` with ``RSS'' = 2 q`` and ``s^2 = RSS / dof``; ``u(tau) = tau u(x)``."""
    s2 = rss_min / max(dof, 1)
    return tau * math.sqrt(2 * s2 / (2 * q))
