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


def lag(u, tau_s: float, t, groups=None, order=None) -> np.ndarray:
    """``u`` (N,) filtered through a first-order lag of time constant ``tau_s`` over the
    times ``t`` (N,), same unit as ``tau_s``; ``groups`` (N,) ints: filter each group (file)
    on its own; ``order``: :func:`time_order` of ``(t, groups)`` when already known.  A scalar
    ``u`` is returned unchanged.  Returns (N,) floats."""
    u = np.asarray(u, dtype=float)
    if u.ndim == 0:
        return u
    t = np.broadcast_to(np.asarray(t, dtype=float), u.shape).ravel()
    if order is None:
        order = time_order(t, groups)
    flat = u.ravel()
    y = _lag_sorted(flat[order], float(tau_s), t[order], presorted=True,
                    restart=None if groups is None else _starts(groups, order))
    out = np.empty(flat.size)
    out[order] = y
    return out.reshape(u.shape)


def time_order(t, groups=None) -> np.ndarray:
    """Indices that sort the points by (group, time), ties in their given order."""
    t = np.asarray(t, dtype=float).ravel()
    if groups is None:
        return np.argsort(t, kind="stable")
    return np.lexsort((t, np.asarray(groups).ravel()))


def _starts(groups, order) -> np.ndarray:
    """Mask (N-1,) of the sorted steps that begin a new group (the filter restarts there)."""
    g = np.asarray(groups).ravel()[order]
    return g[1:] != g[:-1]


def _lag_sorted(u: np.ndarray, tau: float, t: np.ndarray, presorted: bool = False,
                restart=None) -> np.ndarray:
    """The lag of ``u`` over ``t`` (any order; ``presorted``: already in time order, the
    result in that order; ``restart``: mask of steps where the filter starts afresh)."""
    if u.size < 2 or not tau > 0:
        return u.copy()
    order = None if presorted else np.argsort(t, kind="stable")
    us, ts = (u, t) if presorted else (u[order], t[order])
    x = np.diff(ts) / tau                      # steps in time constants, >= 0
    if restart is not None:
        x = np.where(restart, 1e12, x)         # a new file: the past is forgotten
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
    if presorted:
        return y
    out = np.empty_like(y)
    out[order] = y
    return out


def lag_key(covariate: str, tau_s: float, time: str = "t_s") -> str:
    """The canonical basis text of a lag: ``lag(T_motorX, 2400.0)`` (over ``t_s``) or
    ``lag(T_motorX, 2400.0, t_min)`` (``tau_s`` always in seconds)."""
    tau = repr(round(float(tau_s), 6))
    return f"lag({covariate}, {tau})" if time == "t_s" else f"lag({covariate}, {tau}, {time})"


def lag_of_columns(columns: dict, covariate: str, tau_s: float, time: str = "t_s",
                   groups=None, order=None) -> np.ndarray:
    """The lag of a data column over the data's time column ``time`` (``t_min`` and ``t_h``
    converted to seconds); ``groups``: file index of each point; ``order``: their
    :func:`time_order` when known."""
    t = np.asarray(columns[time], dtype=float) * TIME_COLUMNS.get(time, 1.0)
    return lag(columns[covariate], tau_s, t, groups, order)


def lag_symbol(covariate: str, tau_s: float, time: str = "t_s") -> str:
    """The identifier of a lag in derived expressions and generated code:
    ``lag__T_motorX__2400p0`` (``__t_min`` appended for another time column)."""
    tau = repr(round(float(tau_s), 6)).replace(".", "p").replace("-", "m").replace("+", "")
    return f"lag__{covariate}__{tau}" + ("" if time == "t_s" else f"__{time}")
