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

Several time constants at once (``lag(u, taus, ...)``, the trial time constants of a profile,
:mod:`volerr.loop.drift.tau_range`): where every group is evenly sampled, contiguous and in
time order, ``a`` and ``c`` are constants per time constant and the recurrence of all of
them is carried from target to target (every ``step``-th point and the points asked for),
each block's inputs summed by one matrix product; elsewhere one time constant at a time.
"""

from __future__ import annotations

import numpy as np

#: time constants per closed-form segment (exp(300) is far from overflowing)
_SEGMENT = 300.0
#: the time columns a lag may run over, with their unit in seconds (t_s is the default)
TIME_COLUMNS = {"t_s": 1.0, "time_s": 1.0, "t_min": 60.0, "time_min": 60.0, "t_h": 3600.0,
                "time_h": 3600.0}


def lag(u, tau_s, t, groups=None, order=None, rows=None, step: int = 1) -> np.ndarray:
    """``u`` (N,) filtered through a first-order lag of time constant ``tau_s`` over the
    times ``t`` (N,), same unit as ``tau_s``; ``groups`` (N,) ints: filter each group (file)
    on its own; ``order``: :func:`time_order` of ``(t, groups)`` when already known.  A scalar
    ``u`` is returned unchanged.  Returns (N,) floats.

    ``tau_s`` (T,) time constants at once (module docstring): returns (N, T), column j the
    lag at ``tau_s[j]``, or only the points ``rows`` (indices), (len(rows), T); ``step``:
    ``rows`` are about every ``step``-th point of a group (evenly sampled groups then cost
    N / ``step`` per time constant)."""
    if np.ndim(tau_s):
        return _lag_taus(u, np.asarray(tau_s, dtype=float), t, groups, order, rows, step)
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


def _lag_taus(u, taus, t, groups, order, rows, step) -> np.ndarray:
    """:func:`lag` of ``u`` (N,) at the time constants ``taus`` (T,), at ``rows``:
    (len(rows), T)."""
    u = np.asarray(u, dtype=float).ravel()
    t = np.broadcast_to(np.asarray(t, dtype=float), u.shape)
    rows = np.arange(u.size) if rows is None else np.asarray(rows)
    run = np.zeros(u.size, int) if groups is None else np.asarray(groups).ravel()
    got = _lag_even_groups(u, taus, t, run, rows, step)
    if got is None:               # a group not evenly sampled: one time constant at a time
        order = time_order(t, groups) if order is None else order
        got = np.column_stack([lag(u, float(tau), t, groups, order)[rows] for tau in taus])
    return got


def _lag_even_groups(u, taus, t, run, rows, step):
    """(len(rows), T) lags of ``u`` at ``taus`` group by group (``run``), each group from
    equilibrium at its first point; None unless every group's points are contiguous, in
    time order and evenly spaced."""
    out = np.empty((len(rows), len(taus)))
    for r in np.unique(run):
        idx = np.flatnonzero(run == r)
        dt = np.diff(t[idx])
        if len(idx) > 1 and (idx[-1] - idx[0] + 1 != len(idx) or not dt[0] > 0
                             or np.ptp(dt) > 1e-9 * dt[0]):
            return None
        want = np.flatnonzero(run[rows] == r)
        u0 = u[idx[0]]
        if len(idx) < 2:
            out[want] = u0
            continue
        out[want] = _lag_even(u[idx] - u0, float(np.mean(dt)) / taus, rows[want] - idx[0],
                              step) + u0
    return out


def _lag_even(u, x, at, step) -> np.ndarray:
    """The lag recursion of ``u`` (M,) (``u[0]`` = 0) with steps ``x`` = dt / tau (T,), at
    the readings ``at`` (M',): carried from target to target (``at`` and every ``step``-th
    reading), each block's inputs summed by one matrix product, the carry a cumulative sum
    in segments over which the weights stay below exp(300)."""
    oma = -np.expm1(-x)
    small = x < 1e-6
    c = np.where(small, x / 2 - x * x / 6, 1.0 - oma / np.where(small, 1.0, x))
    tg = np.arange(0, len(u), step)
    if len(at) and not (np.all(at % step == 0) and at[-1] < len(u)):
        tg = np.union1d(tg, at)
    ell = np.diff(tg)                                        # block lengths (readings)
    K = int(ell.max()) if len(ell) else 1
    back = np.arange(K - 1, -1, -1)                          # steps before the block's end
    J = tg[1:, None] - back[None, :]
    ok = back[None, :] < ell[:, None]
    J = np.where(ok, J, 1)
    dec = np.exp(-back[:, None] * x[None, :])                # (K, T)
    P = np.where(ok, u[J - 1], 0.0) @ (oma * dec) + np.where(ok, u[J] - u[J - 1], 0.0) @ (c * dec)
    L = np.concatenate([[0.0], np.cumsum(ell, dtype=float)])   # readings from the start
    y = np.zeros((len(tg), len(x)))
    seg = max(1, int(_SEGMENT / (float(x.max()) * K)))
    for a in range(1, len(tg), seg):
        b = min(a + seg, len(tg))
        m = (L[a:b] - L[a - 1])[:, None] * x[None, :]
        y[a:b] = np.exp(-m) * (y[a - 1] + np.cumsum(P[a - 1:b - 1] * np.exp(m), axis=0))
    return y[np.searchsorted(tg, at)]


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
