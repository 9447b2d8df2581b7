"""First-order lag of a sampled signal: ``lag(u, tau)`` solves ``tau dy/dt + y = u(t)``.

Heat flows from a source (a motor, the spindle, the coolant) into a structure (a ballscrew, a
column) through a thermal resistance and capacity: the structure's temperature follows the
sensor's reading as a first-order low-pass with time constant ``tau``.  An effect basis
``lag(T_motorX, 2400)`` (:mod:`volerr.machine.expressions`) is that filtered reading.

The filter is exact for a signal linear between its samples (what a logger gives): over a
step ``h = t_k - t_{k-1}`` with ``a = exp(-h / tau)``::

    y_k = a y_{k-1} + (1 - a) u_{k-1} + (u_k - u_{k-1}) (1 - (tau / h)(1 - a))

(a constant u is approached exponentially; a ramp of slope s is followed at ``u - s tau``).
The samples are taken in time order (the points of a file need not be; equal times share one
step of length 0); the filter starts in equilibrium, ``y_0 = u_0`` (the structure at the
sensor's first reading).  Data of several files are filtered file by file.

Units: ``tau`` and ``t`` in the same unit (seconds for ``lag(C, tau_s)`` over ``t_s``).  The
recurrence is summed in closed form with cumulative sums (no Python loop over the samples),
restarted every ``_SEGMENT`` time constants so that no exponential overflows.
"""

from __future__ import annotations

import numpy as np

#: time constants per closed-form segment (exp(300) is far from overflowing)
_SEGMENT = 300.0
#: the time columns a lag may run over, with their unit in seconds (t_s is the default)
TIME_COLUMNS = {"t_s": 1.0, "time_s": 1.0, "t_min": 60.0, "time_min": 60.0, "t_h": 3600.0,
                "time_h": 3600.0}


def lag(u, tau_s: float, t, groups=None) -> np.ndarray:
    """``u`` (N,) filtered through a first-order lag of time constant ``tau_s`` over the
    times ``t`` (N,), same unit as ``tau_s``; ``groups`` (N,) ints: filter each group (file)
    on its own.  A scalar ``u`` is returned unchanged.  Returns (N,) floats."""
    u = np.asarray(u, dtype=float)
    if u.ndim == 0:
        return u
    t = np.broadcast_to(np.asarray(t, dtype=float), u.shape)
    if groups is None or len(np.unique(groups)) < 2:
        return _lag_sorted(u.ravel(), float(tau_s), t.ravel()).reshape(u.shape)
    out = np.empty(u.size)
    flat_u, flat_t, g = u.ravel(), t.ravel(), np.asarray(groups).ravel()
    for k in np.unique(g):
        m = g == k
        out[m] = _lag_sorted(flat_u[m], float(tau_s), flat_t[m])
    return out.reshape(u.shape)


def _lag_sorted(u: np.ndarray, tau: float, t: np.ndarray) -> np.ndarray:
    if u.size < 2:
        return u.copy()
    if not tau > 0:
        return u.copy()
    order = np.argsort(t, kind="stable")
    us, ts = u[order], t[order]
    x = np.diff(ts) / tau                      # steps in time constants, >= 0
    one_minus_a = -np.expm1(-x)
    small = x < 1e-6
    with np.errstate(divide="ignore", invalid="ignore"):
        c = np.where(small, x / 2 - x * x / 6, 1.0 - one_minus_a / np.where(small, 1.0, x))
    g = one_minus_a * us[:-1] + c * np.diff(us)     # y_k = a_k y_{k-1} + g_k
    y = np.empty_like(us)
    y[0] = us[0]
    # log of 1 / prod a; a step of over 40 time constants forgets the past (a < 1e-17)
    L = np.concatenate([[0.0], np.cumsum(np.minimum(x, 40.0))])
    start = 0
    while start < len(us) - 1:
        stop = int(np.searchsorted(L, L[start] + _SEGMENT, side="right"))
        stop = max(min(stop, len(us)), start + 2)
        Ls = L[start:stop] - L[start]
        s = np.cumsum(g[start:stop - 1] * np.exp(Ls[1:]))
        y[start + 1:stop] = np.exp(-Ls[1:]) * (y[start] + s)
        start = stop - 1
    out = np.empty_like(y)
    out[order] = y
    return out


def lag_key(covariate: str, tau_s: float, time: str = "t_s") -> str:
    """The canonical basis text of a lag: ``lag(T_motorX, 2400.0)`` (over ``t_s``) or
    ``lag(T_motorX, 2400.0, t_min)`` (``tau_s`` always in seconds)."""
    tau = repr(round(float(tau_s), 6))
    return f"lag({covariate}, {tau})" if time == "t_s" else f"lag({covariate}, {tau}, {time})"


def lag_of_columns(columns: dict, covariate: str, tau_s: float, time: str = "t_s",
                   groups=None) -> np.ndarray:
    """The lag of a data column over the data's time column ``time`` (``t_min`` and ``t_h``
    converted to seconds); ``groups``: file index of each point."""
    t = np.asarray(columns[time], dtype=float) * TIME_COLUMNS.get(time, 1.0)
    return lag(columns[covariate], tau_s, t, groups)


def lag_symbol(covariate: str, tau_s: float, time: str = "t_s") -> str:
    """The identifier of a lag in derived expressions and generated code:
    ``lag__T_motorX__2400p0`` (``__t_min`` appended for another time column)."""
    tau = repr(round(float(tau_s), 6)).replace(".", "p").replace("-", "m").replace("+", "")
    return f"lag__{covariate}__{tau}" + ("" if time == "t_s" else f"__{time}")
