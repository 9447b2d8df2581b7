"""Power of a check before it is run: how large a change of each reference parameter the
check's readings detect, from the information of its readings and the reference's covariance
(:mod:`volerr.check._system` on the planned readings, readings zero).

A change ``Delta`` of parameter ``j`` alone moves ``chi2`` of the no-change fit by a
noncentral chi-square (1 dof) with noncentrality ``lambda = (Delta / s_j)^2``, ``s_j`` the
standard uncertainty of the change estimated with ``j`` free (check and reference); the check
names it when the reduction exceeds the selection threshold ``c``
(:func:`volerr.check._select.threshold`), so

    power(Delta) = P(chi2_1(lambda) > c) = Phi(sqrt(lambda) - sqrt(c)) + Phi(-sqrt(lambda) - sqrt(c))

and the change detected with probability ``POWER`` is ``(sqrt(c) + z_POWER) s_j`` (to the
neglected far tail).  The false-alarm rate of the threshold is below 5 % (Bonferroni over the
parameters).  References: Cohen (1988) for power of chi-square tests; Teunissen (2000),
"Testing theory", for the minimal detectable bias of geodetic networks, the same construction.
"""

from __future__ import annotations

import math

import numpy as np

from . import _select

#: detection probability a check is planned for
POWER = 0.95


def power(size: float, std: float, c: float) -> float:
    """Probability that a change ``size`` (the parameter's unit) with standard uncertainty
    ``std`` of its estimate passes the threshold ``c`` (module docstring)."""
    from scipy.stats import norm

    if not std > 0 or not math.isfinite(std):
        return 0.0
    s = abs(size) / std
    return float(norm.cdf(s - math.sqrt(c)) + norm.cdf(-s - math.sqrt(c)))


def detectable(std: float, c: float) -> float:
    """The change detected with probability :data:`POWER` (module docstring)."""
    from scipy.stats import norm

    return (math.sqrt(c) + float(norm.ppf(POWER))) * std


def change_std(system) -> np.ndarray:
    """(p,) standard uncertainty of each parameter's change estimated alone (check and
    reference), inf where the check does not see it."""
    out = np.full(system.p, np.inf)
    G = np.diag(system.data_information())
    ref = np.diag(system.Sinv)
    for j in range(system.p):
        if G[j] > 1e-6 * max(ref[j], 1e-300):
            out[j] = float(system.solve([j]).change()[1][0])
    return out


def detectable_table(system, ref, per_um: np.ndarray, detect_um: float) -> dict:
    """``{NAME: {"size", "unit", "power", "size_95"}}``: ``size`` the change that moves the
    volumetric error by ``detect_um`` somewhere in the working volume (``per_um`` um per
    unit), ``power`` its detection probability, ``size_95`` the change detected with 95 %."""
    c = _select.threshold(system.n_readings, system.p)
    s = change_std(system)
    out = {}
    for j, name in enumerate(ref.names):
        size = detect_um / per_um[j] if per_um[j] > 0 else float("inf")
        out[name] = {"size": _num(size), "unit": ref.units[j],
                     "power": round(power(size, s[j], c), 4) if math.isfinite(size) else None,
                     "size_95": _num(detectable(s[j], c)), "std": _num(s[j])}
    return out


def _num(v: float):
    return round(float(v), 6) if math.isfinite(v) else None
