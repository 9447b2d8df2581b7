"""Lags in generated modules: ``lag(C, tau_s)`` of an effect basis (:mod:`volerr.machine.lags`).

In the derivation a lag is a plain real symbol (``lag__T_motorX__2400p0``, see
:func:`volerr.machine.lags.lag_symbol`): the error model is linear in it and no derivative
with respect to it is needed.  A generated function whose arguments hold the lag's column and
time column computes it first, from the whole series it is given, with the module's own copy
of the filter (the source of :func:`volerr.machine.lags._lag_sorted`, printed into the
module: generated modules import numpy only).  The keyword ``lags`` ({canonical lag text:
values}) lets a caller pass the lag of a longer series evaluated at a subset of its points
(the runtime's blockwise fits do).
"""

from __future__ import annotations

import inspect

from volerr.machine import lags as _runtime_lags
from volerr.machine.expressions import lag_calls

#: sources printed into (and hashed by) a module with lags
SOURCES = ("runtime/machine/lags.py", "derive/lags.py")


def layout_lags(layout) -> list:
    """((symbol, key, column, tau_s, time column), ...) of every lag in the layout's effects."""
    out = {}
    for e in layout.effects:
        for t in e.terms:
            for key, col, tau, time in lag_calls(t.basis):
                out[key] = (_runtime_lags.lag_symbol(col, tau, time), key, col, tau, time)
    return [out[k] for k in sorted(out)]


def attach(functions: list, lags: list, covariates) -> None:
    """Give every function whose arguments include covariates the ``lags`` keyword and the
    lines that compute the layout's lags first (in place)."""
    if not lags:
        return
    for f in functions:
        if not set(covariates) & set(f.args):
            continue
        f.keywords = ["lags=None"]
        f.prelude = [f"{sym} = _lagged(lags, {key!r}, {col}, {float(tau)!r}, {time}, "
                     f"{_runtime_lags.TIME_COLUMNS[time]!r})"
                     for sym, key, col, tau, time in lags]


def helper_lines() -> list:
    """Source lines of the module-level helpers ``_lagged`` and ``_lag_sorted``."""
    body = inspect.getsource(_runtime_lags._lag_sorted)
    body = body.replace("np.", "numpy.").replace("_SEGMENT", repr(_runtime_lags._SEGMENT))
    lagged = '''def _lagged(lags, key, u, tau_s, t, seconds_per_unit):
    """The lag ``key`` (tau_s seconds) of column u over time t: from ``lags`` when given
    there, else filtered over the series given (time order, equilibrium at the start; exact
    for u linear between samples)."""
    if lags is not None and key in lags:
        return numpy.asarray(lags[key], dtype=float)
    u = numpy.asarray(u, dtype=float)
    if u.ndim == 0:
        return u
    t = numpy.broadcast_to(numpy.asarray(t, dtype=float) * seconds_per_unit, u.shape)
    return _lag_sorted(u.ravel(), float(tau_s), t.ravel()).reshape(u.shape)
'''
    return ["", ""] + lagged.splitlines() + ["", ""] + body.rstrip("\n").splitlines()
