"""Screening and selection of candidate effects (steps 4-5 of :func:`volerr.loop.run.run_loop`).

Screen: every candidate (P x C x basis, :mod:`volerr.loop.candidates`) is scored against the
current residual by the exact RSS reduction of adding its columns to the current design (a
score test through the Gram matrix: no refit), converted to a BIC change; searched basis
parameters (warm-up tau, step location, period) are profiled on their grid, refined, and cost
one extra parameter.  A candidate's columns are one target's sensitivity (n, 3) times its
bases (n,): the candidates on one target are scored together on the design reduced against
that sensitivity once (:meth:`Base.term_gains`: products over the n points, not the 3n rows).
Select: the best three by BIC are fitted fully; the first with dBIC <
-``BIC_GAIN`` and a significantly smaller cross-validated residual (paired t > ``CV_T`` on the
per-point squared errors) is accepted; repeat.  After acceptance every effect is re-tested
given the others (backward check) and dropped when it no longer earns its place.

Rows are weighted (robust weights of the points, :func:`robust_weights`): gross outliers do
not drive the choice.  Units: mm rows; BIC in natural-log units.
"""

from __future__ import annotations

import math
import re
from collections.abc import Mapping
from dataclasses import dataclass, field

import numpy as np

from . import candidates as cands
from .fitting import CV_T, cv_sq as _cv_sq, dense_group as _dense_group
from .fitting import full_base as _full_base, rank, stack as _stack
from ..estimate.blocks import BlockBase, blocks, rss_gain
from ..estimate.design import TWIST, rows_of
from ..machine.expressions import evaluate, lag_calls
from ..machine.lags import lag_key
from ..selection import stepwise
from ..selection.linalg import pinv_sym as _pinv_sym
from ..selection.rules import BIC_GAIN, delta_bic, paired_t

MAX_EFFECTS = 8
TOP_FIT = 3          # candidates fitted fully per forward step
SCREEN_POINTS = 3000  # training points a screening uses at most (leaders rescored on all)
N_SOURCES = 10       # residual sources reported
LAG_CACHE = 48       # lagged series (all points) kept while screening
STACK_COLUMNS = 64   # candidate columns scored in one matrix product (Base.score_many)
#: targets whose reduced design (Base.reduced: n x p floats each) a Base keeps: the
#: candidates of one target come together, a few targets interleave in a lag profile
REDUCED_CACHE = 8
#: caches of lagged series a context shares with its sub-contexts (and a second selection
#: on the same data: :func:`volerr.loop.run.selection_step`)
SHARED_LAG_CACHES = ("lags", "lag_orders", "lag_pts")
#: searched basis parameters whose profile is scored on the design reduced against the
#: candidate's one target (:meth:`Base.score_term`): time constants, whose gains on the grid
#: differ by far more than that scoring's rounding (measured: 1e-8 of the best apart or more,
#: rounding 1e-14); not a step's location, whose neighbouring values between two measured
#: positions can gain the same to 1e-12 (there the exact rows decide, as they always did)
REDUCED_SEARCH = ("lag_s", "tau_h")
#: the time constant of a lag in a basis text (the one number a lag profile varies): the
#: lagged column (group 1) and the time constant's characters (group 2)
_LAG_TAU = re.compile(r"lag\(\s*(\w+)\s*,\s*([^,)]+)")


class Base:
    """The current design on the (weighted) training rows, column-scaled, with its Gram
    pseudo-inverse; :meth:`score` is the RSS reduction of adding columns."""

    def __init__(self, A, y, n_readings: int | None = None):
        self.scale = np.sqrt(np.mean(A ** 2, axis=0))
        self.scale[self.scale == 0] = 1.0
        self.A = A / self.scale
        self.Gi = _pinv_sym(self.A.T @ self.A)
        self.r = y - self.A @ (self.Gi @ (self.A.T @ y))
        self.rss = float(self.r @ self.r)
        #: readings (rows that carry one), the n of the BIC
        self.n = len(y) if n_readings is None else int(n_readings)
        self._reduced = {}      # Base.reduced: s bytes -> (A_s, r_s, w)

    def score(self, B) -> tuple[float, int]:
        """(RSS reduction, effective rank) of adding the columns B (rows, m)."""
        return self.score_many([B])[0]

    def score_many(self, groups) -> list:
        """[(RSS reduction, effective rank)] of adding each column group of ``groups`` (rows,
        m) alone.  The groups are stacked (at most ``STACK_COLUMNS`` columns at a time) and
        multiplied by the base's columns in one matrix product: the (rows, p) design is read
        once per stack, not once per group (a product with one or two columns is bound by
        that read).  Each group's numbers are its own (scaled to unit RMS, its Gram block,
        its eigen-decomposition); only the order of summation in the products differs from
        scoring it alone (rounding, 1e-15 relative)."""
        out, i = [], 0
        while i < len(groups):
            stack, width = [groups[i]], groups[i].shape[1]
            i += 1
            while i < len(groups) and width + groups[i].shape[1] <= STACK_COLUMNS:
                width += groups[i].shape[1]
                stack.append(groups[i])
                i += 1
            out += self._score_stack(stack)
        return out

    def _score_stack(self, stack) -> list:
        Ball = np.concatenate(stack, axis=1)
        sc = np.sqrt(np.mean(Ball ** 2, axis=0))
        sc[sc == 0] = 1.0
        Ball = Ball / sc
        C = self.A.T @ Ball
        GiC = self.Gi @ C
        g_all = Ball.T @ self.r
        out, a = [], 0
        for B in stack:
            b = a + B.shape[1]
            Bs = Ball[:, a:b]
            M = Bs.T @ Bs - C[:, a:b].T @ GiC[:, a:b]
            out.append(rss_gain(M, g_all[a:b], 1e-9 * len(Bs)))
            a = b
        return out

    def score_single(self, B) -> np.ndarray:
        """RSS reduction of each single column of B (rows, G) added alone (profiles)."""
        sc = np.sqrt(np.mean(B ** 2, axis=0))
        sc[sc == 0] = 1.0
        Bs = B / sc
        C = self.A.T @ Bs
        m = np.einsum("ij,ij->j", Bs, Bs) - np.einsum("ij,ij->j", C, self.Gi @ C)
        g = Bs.T @ self.r
        ok = m > 1e-9 * len(Bs)
        return np.where(ok, g * g / np.where(ok, m, 1.0), 0.0)

    def score_term(self, s, basis) -> np.ndarray:
        """:meth:`score_single` of the columns of one term, ``s`` (n, 3) weighted target
        column (the rows of a point: ``s[i] basis[i, j]``) times each basis column ``basis``
        (n, G): :meth:`term_gains`' RSS reductions."""
        return self.term_gains(s, basis)[0]

    def term_gains(self, s, basis, cuts=None) -> tuple[np.ndarray, np.ndarray]:
        """(RSS reduction, effective rank) of each column ``s[i] basis[i, j]`` (rows of point
        i) added alone, or of each group of columns ``cuts[k]:cuts[k + 1]`` (offsets, len +
        1) added together, without the (3n, G) rows: the design is reduced against ``s``
        once, ``A_s[i] = sum_k A[3i+k] s[i, k]`` (n, p), and every product is then over n
        points instead of 3n rows (``A^T B = A_s^T basis``, ``B^T B = basis^T diag(w) basis``
        with ``w = sum_k s^2``, ``B^T r = r_s^T basis``).  The same numbers as
        :meth:`score_many` of those rows up to the order of summation (rounding, raised by
        the difference in the Gram block to 1e-9 relative, measured)."""
        n = len(s)
        A_s, r_s, w = self.reduced(s)
        bb = w @ (basis * basis)                                # diag of B^T B, unscaled
        sc = np.sqrt(bb / (3 * n))
        sc[sc == 0] = 1.0
        C = A_s.T @ basis
        GiC = self.Gi @ C
        m = (bb - np.einsum("ij,ij->j", C, GiC)) / (sc * sc)
        g = (r_s @ basis) / sc
        floor = 1e-9 * 3 * n
        ok = m > floor
        gain = np.where(ok, g * g / np.where(ok, m, 1.0), 0.0)
        if cuts is None:
            return gain, ok.astype(int)
        out = [(gain[a], int(ok[a])) if b - a == 1 else rss_gain(
            ((basis[:, a:b] * w[:, None]).T @ basis[:, a:b] - C[:, a:b].T @ GiC[:, a:b])
            / np.outer(sc[a:b], sc[a:b]), g[a:b], floor) for a, b in zip(cuts[:-1], cuts[1:])]
        return np.array([x[0] for x in out], float), np.array([x[1] for x in out], int)

    def reduced(self, s) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """The design and residual reduced against ``s`` (n, 3) for :meth:`term_gains`:
        ``A_s`` (n, p), ``r_s`` (n,) and ``w = sum_k s^2`` (n,).  Kept for the last
        ``REDUCED_CACHE`` values of ``s`` (by its bytes): a screening asks for a few dozen
        targets thousands of times (2371 calls, 141 distinct ``s`` on the lag acceptance
        campaigns), and a kept value is the same computation's result, bit for bit."""
        key = (s.shape, s.strides, s.dtype.str, np.ascontiguousarray(s).tobytes())
        store = self._reduced
        if key in store:
            store[key] = store.pop(key)           # most recently used last
            return store[key]
        while len(store) >= REDUCED_CACHE:
            store.pop(next(iter(store)))
        n = len(s)
        store[key] = (np.einsum("ikp,ik->ip", self.A.reshape(n, 3, -1), s),
                      np.einsum("ik,ik->i", self.r.reshape(n, 3), s),
                      np.einsum("ik,ik->i", s, s))
        return store[key]

    def dbic(self, gain: float, m_eff: int) -> float:
        """BIC change of columns that lower the RSS by ``gain`` with ``m_eff`` parameters."""
        return delta_bic(self.n, self.rss - gain, self.rss, m_eff)


@dataclass
class Context:
    """What the columns of a candidate need: model, data, sensitivities (of the parameters, of
    the rigid twists at the two ends, of the nominal symbols), and the points (``pts``, with
    their sqrt robust weights ``sw``) on which they are scored."""

    model: object
    data: object
    sens: np.ndarray | None     # (N, 3, P) model sensitivity; None: generated per block
    twist: np.ndarray | None    # (N, 3, 12) rigid-twist sensitivity (fit.twist_sensitivity)
    pts: np.ndarray
    sw: np.ndarray
    ranges: dict
    cache: dict = field(default_factory=dict)
    sym: np.ndarray | None = None   # (N, 3, S) nominal-symbol sensitivity, or None

    def on(self, pts, sw) -> "Context":
        """The same context on other points (shares nothing that depends on the points)."""
        return Context(self.model, self.data, self.sens, self.twist, pts, sw, self.ranges,
                       {"fixed": self.cache.setdefault("fixed", {}),
                        **{k: self.cache.setdefault(k, {}) for k in SHARED_LAG_CACHES}},
                       self.sym)

    def basis_values(self, basis: str, full: bool = False) -> dict:
        """:meth:`values`, plus the lags of ``basis`` (:mod:`volerr.machine.lags`) filtered over
        all points of the data (file by file) and taken at the context's points: a lag is a
        property of the whole time series, not of the points a fit looks at."""
        vals = self.values(full)
        calls = lag_calls(basis) if "lag(" in basis else ()
        if not calls:
            return vals
        vals = dict(vals)
        for key, col, tau, time in calls:
            vals[key] = self.lag_series(key, col, tau, time) if full else \
                self.lag_at_points(key, col, tau, time)
        return vals

    def lag_at_points(self, key, col, tau, time) -> np.ndarray:
        """The lag ``key`` at the context's points (kept: a few thousand values each)."""
        if "_pts_key" not in self.cache:
            self.cache["_pts_key"] = hash(np.asarray(self.pts).tobytes())
        mine = self.cache.setdefault("lag_pts", {})
        at = (key, self.cache["_pts_key"])
        if at not in mine:
            mine[at] = self.lag_series(key, col, tau, time)[self.pts]
        return mine[at]

    def lag_series(self, key, col, tau, time) -> np.ndarray:
        """The lag ``key`` of column ``col`` at all points (the last ``LAG_CACHE`` kept)."""
        from ..machine.lags import lag_of_columns, time_order

        store = self.cache.setdefault("lags", {})
        if key in store:
            store[key] = store.pop(key)           # most recently used last
            return store[key]
        while len(store) >= LAG_CACHE:
            store.pop(next(iter(store)))
        orders = self.cache.setdefault("lag_orders", {})
        if time not in orders:
            orders[time] = time_order(self.data.covariates[time], self.data.file)
        store[key] = lag_of_columns(self.data.covariates, col, tau, time, self.data.file,
                                    orders[time])
        return store[key]

    def values(self, full: bool = False):
        """Basis variables at the context's points (all when ``full``): axis positions
        (rotary in rad), covariates and the probe offset components ``Xp Yp Zp`` (mm)."""
        from ..estimate.design import rotary_rad

        key = ("_values", full)
        if key not in self.cache:
            idx = slice(None) if full else self.pts
            probe = np.asarray(self.data.probe)
            vals = {**rotary_rad(self.model, self.data.positions), **self.data.covariates,
                    "Xp": probe[:, 0], "Yp": probe[:, 1], "Zp": probe[:, 2]}
            self.cache[key] = {k: np.asarray(v)[idx] for k, v in vals.items()}
        return self.cache[key]

    def sensitivities(self, idx, slot: str = "_block") -> tuple:
        """(sensitivity (n, 3, P), twist sensitivity (n, 3, 12), nominal-symbol sensitivity
        (n, 3, S)) at the points ``idx``: slices of the full arrays when the context holds
        them, else generated (kept for the last ``idx`` of each ``slot``)."""
        if self.sens is not None:
            sym = (self.sym[idx] if self.sym is not None
                   else self.data.subset(idx).symbol_sensitivity(self.model))
            return self.sens[idx], self.twist[idx], sym
        from ..estimate.design import twist_sensitivity

        last = self.cache.get(slot)
        if last is not None and np.array_equal(last[0], idx):
            return last[1]
        sub = self.data.subset(idx)
        out = (sub.sensitivity(self.model), twist_sensitivity(self.model, sub),
               sub.symbol_sensitivity(self.model))
        self.cache[slot] = (np.array(idx), out)
        return out

    def _column(self, target: str, sens, tw, sym) -> np.ndarray:
        if target in TWIST:
            return tw[:, :, TWIST[target]]
        if "." in target:           # a nominal symbol of the chain (probe.Zp, param.d ...)
            return sym[:, :, self.model.symbols.index(target)]
        return sens[:, :, self.model.parameters.index(target)]

    def target_column(self, target: str, full: bool = False) -> np.ndarray:
        """(n, 3) sensitivity of a chain target (a parameter, ``work.*`` or ``tool.*``) at the
        context's points (all points when ``full``)."""
        if full:
            return self._column(target, *self.sensitivities(np.arange(self.data.n), "_full"))
        key = ("target", target, full)
        if key not in self.cache:
            self.cache[key] = self._column(target, *self.sensitivities(self.pts, "_pts"))
        return self.cache[key]

    def columns(self, terms, full: bool = False) -> tuple[np.ndarray, list]:
        """(n, 3, m) columns of the parameters of ``terms`` [(parameter, target, basis)] at
        the context's points (all points when ``full``: not cached, memory stays bounded)."""
        key = ("cols", tuple(terms))
        if not full and key in self.cache:
            return self.cache[key]
        params = list(dict.fromkeys(t[0] for t in terms))
        if full:          # by blocks of points: no full sensitivity arrays
            out = np.empty((self.data.n, 3, len(params)))
            for s, idx in blocks(np.arange(self.data.n)):
                out[s] = self.columns_at(terms, idx)
            return out, params
        n = self.data.n if full else len(self.pts)
        out = np.zeros((n, 3, len(params)))
        for pn, target, basis in terms:
            b = np.broadcast_to(evaluate(basis, self.basis_values(basis, full)), (n,))
            out[:, :, params.index(pn)] += self.target_column(target, full) * b[:, None]
        if not full and len(self.pts) * len(params) <= 20000 * 3:
            self.cache[key] = (out, params)
        return out, params

    def term_basis(self, terms) -> np.ndarray:
        """(n,) the summed bases of ``terms`` at the context's points, each text evaluated
        once (kept: the candidates of one covariate on every target share its texts)."""
        store = self.cache.setdefault("term_bases", {})
        n = len(self.pts)
        out = None
        for _, _, text in terms:
            if text not in store:
                store[text] = np.broadcast_to(evaluate(text, self.basis_values(text)), (n,))
            out = store[text] if out is None else out + store[text]
        return out

    def columns_at(self, terms, idx) -> np.ndarray:
        """(n, 3, m) columns of ``terms`` at the data points ``idx`` (one block)."""
        params = list(dict.fromkeys(t[0] for t in terms))
        arrays = self.sensitivities(idx)
        out = np.zeros((len(idx), 3, len(params)))
        vals = self._values_at(idx)
        for pn, target, basis in terms:
            lagged = {k: self.lag_series(k, *rest)[idx] for k, *rest in lag_calls(basis)} \
                if "lag(" in basis else {}
            b = np.broadcast_to(evaluate(basis, _Taken(vals.base, idx, vals.taken, lagged)
                                         if lagged else vals), (len(idx),))
            out[:, :, params.index(pn)] += self._column(target, *arrays) * b[:, None]
        return out

    def _values_at(self, idx) -> "_Taken":
        """:meth:`values` of all points taken at ``idx`` as they are asked for (kept for the
        last ``idx``: the candidate groups of one block share them)."""
        last = self.cache.get("_vals_block")
        if last is None or not np.array_equal(last.idx, idx):
            last = _Taken(self.values(True), np.array(idx))
            self.cache["_vals_block"] = last
        return last

    def group(self, terms):
        """The columns of ``terms`` as a function of the points (for :class:`BlockBase`)."""
        return lambda idx: self.columns_at(terms, idx)

    def rows(self, cols) -> np.ndarray:
        """Weighted rows (3n, m) of columns (n, 3, m) at the context's points."""
        return (cols * self.sw[:, None, None]).reshape(-1, cols.shape[-1])

    def profile_rows(self, c, values) -> np.ndarray:
        """Weighted rows (3n, G) of a one-parameter searched candidate at ``values`` (its
        terms summed: a proportional warm-up of the probe offset has three)."""
        n = len(self.pts)
        cols = np.zeros((n, 3, len(values)))
        for target, basis in self.profile_terms(c, values):
            cols += self.target_column(target)[:, :, None] * basis[:, None, :]
        return (cols * self.sw[:, None, None]).reshape(-1, len(values))

    def profile_terms(self, c, values) -> list:
        """[(target, basis (n, G))] of a one-parameter searched candidate at ``values``, one
        per term: its columns are the sum of the target columns times the bases.  A lag
        term's basis is kept by its texts (the last ``LAG_CACHE``): the candidates of one
        sensor on every target share the texts of one basis form; other searched bases are
        kept per candidate (a few)."""
        key = ("profile", c.name, tuple(values))
        if key in self.cache:
            return self.cache[key]
        made = [c.search.make(v)[0] for v in values]
        n = len(self.pts)
        out = []
        for i, (_, target, _) in enumerate(made[0]):    # one parameter, its terms
            texts = [m[i][2] for m in made]
            basis = self._lag_basis_kept(texts) if c.search.what == "lag_s" else None
            if basis is None:
                basis = np.column_stack([np.broadcast_to(
                    evaluate(t, self.basis_values(t)), (n,)) for t in texts])
            out.append((target, basis))
        if c.search.what != "lag_s":        # hundreds of lag candidates: not kept
            self.cache[key] = out
        return out

    def _lag_basis_kept(self, texts) -> np.ndarray | None:
        """:meth:`_lag_profile_basis` of ``texts``, kept (the last ``LAG_CACHE`` sets)."""
        store = self.cache.setdefault("lag_bases", {})
        key = tuple(texts)
        if key in store:
            store[key] = store.pop(key)           # most recently used last
            return store[key]
        while len(store) >= LAG_CACHE:
            store.pop(next(iter(store)))
        store[key] = self._lag_profile_basis(texts)
        return store[key]

    def _lag_profile_basis(self, texts) -> np.ndarray | None:
        """(n, G) basis of the texts of one lag term at G time constants, evaluated once with
        the G lagged series stacked (G, n) in place of the first text's lag: the texts differ
        only in the time constant of their one lag, so every element is the same arithmetic on
        the same numbers as evaluating each text alone; None when they are not of that shape."""
        calls = _lag_calls_alike(texts)
        if calls is None:
            return None
        stacked = np.stack([self.lag_at_points(*cl[0]) for cl in calls])
        vals = {**self.values(), calls[0][0][0]: stacked}
        return np.broadcast_to(evaluate(texts[0], vals), stacked.shape).T


def _lag_calls_alike(texts) -> list | None:
    """:func:`lag_calls` of each of ``texts`` when they are one text with one lag that differ
    only in its time constant (else None): the first text parsed and checked, the others'
    time constants read from their lag's argument (``float`` of the same characters the
    parser reads), without parsing hundreds of texts that differ in one number."""
    first = lag_calls(texts[0])
    if len(first) != 1 or len({_LAG_TAU.sub(r"lag(\1, TAU", t) for t in texts}) != 1:
        return None
    (key, col, tau, time), = first
    out = []
    for t in texts:
        tau_t = float(_LAG_TAU.search(t).group(2))
        if not tau_t > 0:             # refused by the parser: let it say so
            return None
        out.append(((lag_key(col, tau_t, time), col, tau_t, time),))
    return out


class _Taken(Mapping):
    """The arrays of ``base`` (all points) at the points ``idx``, each taken when first asked
    for (a basis needs two or three of the dozens of variables), then ``extra`` (arrays
    already at ``idx``) over them; ``taken``: the cache of taken arrays (shared)."""

    def __init__(self, base: dict, idx, taken: dict | None = None, extra: dict | None = None):
        self.base, self.idx = base, idx
        self.taken = {} if taken is None else taken
        self.extra = extra or {}

    def __getitem__(self, key):
        if key in self.extra:
            return self.extra[key]
        if key not in self.taken:
            self.taken[key] = np.asarray(self.base[key])[self.idx]
        return self.taken[key]

    def __contains__(self, key) -> bool:
        return key in self.extra or key in self.base

    def __iter__(self):
        return iter({**dict.fromkeys(self.base), **dict.fromkeys(self.extra)})

    def __len__(self) -> int:
        return len(set(self.base) | set(self.extra))


@dataclass
class Scored:
    """A screened candidate: BIC change, RSS reduction, rank, its (fixed) candidate."""

    dbic: float
    gain: float
    rank: int
    cand: cands.Candidate
    params: list


def _profile(c: cands.Candidate, ctx: Context, base: Base) -> cands.Candidate:
    """Fix the searched basis parameter of ``c`` at its best value (grid, then refined)."""
    if c.search.what == "period":
        return c.fixed(_periodic_best(c, ctx, base))
    grid = list(c.search.grid)

    def best_of(values):
        terms = ctx.profile_terms(c, values)
        if c.search.what in REDUCED_SEARCH and len({t for t, _ in terms}) == 1:
            basis = terms[0][1] if len(terms) == 1 else sum(b for _, b in terms)
            g = base.score_term(ctx.target_column(terms[0][0]) * ctx.sw[:, None], basis)
        else:
            g = base.score_single(ctx.profile_rows(c, values))
        return values[int(np.argmax(g))]

    v0 = best_of(grid)
    i = grid.index(v0)
    lo, hi = grid[max(i - 1, 0)], grid[min(i + 1, len(grid) - 1)]
    if c.search.what == "location_mm":
        q = np.unique(ctx.data.positions[c.info["axis"]])
        mids = (q[1:] + q[:-1]) / 2
        fine = mids[(mids > lo) & (mids < hi)]
        if len(fine) > 40:
            fine = fine[np.linspace(0, len(fine) - 1, 40).astype(int)]
    else:
        # a lag's tau: 7 values (5 % steps) suffice here, the accepted one is refined on all
        # training points (volerr.loop.lags.profile_tau); hundreds of lag candidates
        fine = np.geomspace(max(lo, 1e-3), hi, 7 if c.search.what == "lag_s" else 15)
    if len(fine):
        v0 = best_of([v0] + [float(x) for x in fine])
    return c.fixed(v0)


def _periodic_best(c, ctx: Context, base: Base) -> float:
    """Best period of a periodic candidate by the residual periodogram, refined."""
    comp, axis, periods = c.info["component"], c.info["axis"], np.asarray(c.search.grid)
    s = ctx.target_column(comp) * ctx.sw[:, None]
    r = base.r.reshape(-1, 3)
    w = np.sum(r * s, axis=1)
    s2 = np.sum(s * s, axis=1)
    q = ctx.data.positions[axis][ctx.pts]

    def gain(per):
        ph = 2 * np.pi * np.outer(q, 1.0 / np.atleast_1d(per))
        sn, cs = np.sin(ph), np.cos(ph)
        a, b = w @ sn, w @ cs
        ss, cc, sc = s2 @ (sn * sn), s2 @ (cs * cs), s2 @ (sn * cs)
        det = np.maximum(ss * cc - sc * sc, 1e-300)
        return (a * a * cc - 2 * a * b * sc + b * b * ss) / det

    g = np.concatenate([gain(periods[i:i + 64]) for i in range(0, len(periods), 64)])
    i = int(np.argmax(g))
    f0 = 1.0 / periods[i]
    df = (1.0 / periods[min(i + 1, len(periods) - 1)] - 1.0 / periods[max(i - 1, 0)]) / 2 \
        or f0 * 1e-3
    fine = 1.0 / np.linspace(max(f0 - df, 1e-12), f0 + df, 41)
    return float(fine[int(np.argmax(gain(fine)))])


def _scored(c, ctx: Context, base: Base) -> "Scored":
    cols, params = ctx.columns(c.terms)
    gain, rank = base.score(ctx.rows(cols))
    m_eff = rank + cands.extra_parameters(c)
    return Scored(base.dbic(gain, m_eff), gain, rank, c, params)


def _scored_many(cs, ctx: Context, base) -> list:
    """:func:`_scored` of several candidates; one pass over the rows for a :class:`BlockBase`;
    for a :class:`Base` the candidates on one target (nearly all) together per target, on
    the design reduced against it (:meth:`Base.term_gains`: a screening's
    thousands of columns without their rows), the others in stacks of ``STACK_COLUMNS``
    (their rows made a stack at a time)."""
    if isinstance(base, BlockBase):
        res = base.score_many([ctx.group(c.terms) for c in cs])
        return [Scored(base.dbic(g, r + cands.extra_parameters(c)), g, r, c,
                       c.parameters) for c, (g, r) in zip(cs, res)]
    out, by_target, rest = [None] * len(cs), {}, []
    for i, c in enumerate(cs):
        t = _one_target(c)
        (rest if t is None else by_target.setdefault(t, [])).append(i)
    for t, idx in by_target.items():
        bases = [[ctx.term_basis([x for x in cs[i].terms if x[0] == p])
                  for p in cs[i].parameters] for i in idx]
        cuts = np.cumsum([0] + [len(b) for b in bases])
        g, ok = base.term_gains(ctx.target_column(t) * ctx.sw[:, None],
                                np.column_stack([b for bs in bases for b in bs]), cuts)
        for i, gain, r in zip(idx, g.tolist(), ok.tolist()):
            gain = gain if r else 0.0
            out[i] = Scored(base.dbic(gain, r + cands.extra_parameters(cs[i])), gain, r,
                            cs[i], cs[i].parameters)
    for k in range(0, len(rest), STACK_COLUMNS):
        part = [cs[i] for i in rest[k:k + STACK_COLUMNS]]
        made = [ctx.columns(c.terms) for c in part]
        res = base.score_many([ctx.rows(cols) for cols, _ in made])
        for i, c, (_, params), (g, r) in zip(rest[k:k + STACK_COLUMNS], part, made, res):
            out[i] = Scored(base.dbic(g, r + cands.extra_parameters(c)), g, r, c, params)
    return out


def _one_target(c) -> str | None:
    """The target of a candidate whose terms all act on one target (its parameters' columns
    are that target's sensitivity times their bases), else None."""
    targets = {t for _, t, _ in c.terms}
    return next(iter(targets)) if len(targets) == 1 else None


def screen(candidates, ctx: Context, base: Base, skip=()) -> list:
    """Score every candidate against the residual of ``base``; sorted by BIC change."""
    cs = []
    fixed = ctx.cache.setdefault("fixed", {})
    for c in candidates:
        if c.name in skip:
            continue
        if c.search is not None:
            # profiled once; later screenings reuse the value and re-profile the leaders
            c = fixed[c.name] if c.name in fixed else _profile(c, ctx, base)
            fixed[c.name] = c
        cs.append(c)
    out = [sc for sc in _scored_many(cs, ctx, base) if sc.rank]
    out.sort(key=lambda x: x.dbic)
    for i, sc in enumerate(out[:2 * TOP_FIT]):
        if sc.cand.search is not None:
            c = _profile(sc.cand, ctx, base)
            fixed[c.name] = c
            out[i] = _scored(c, ctx, base)
    out = [x for x in out if x.rank]
    rank(out, _order(candidates))
    return out


def rescore(scored: list, ctx: Context, base: Base, candidates, top: int) -> list:
    """The ``top`` leaders of a screening (on a subset of points) scored exactly on all
    training points, then the rest as they were."""
    head = _scored_many([x.cand for x in scored[:top]], ctx, base)
    head = [x for x in head if x.rank]
    rank(head, _order(candidates))
    return head + scored[top:]


def _order(candidates: list) -> dict:
    """Candidate name -> its position in the candidate list: the order in which candidates
    that fit the data identically (on a CMM ``EZX`` depending on ``Y`` and ``EZY`` depending
    on ``X``; a growing tool and ``EZB`` at one tool length) are named (:func:`fitting.rank`)."""
    return {c.name: i for i, c in enumerate(candidates)}


def sources(scored: list, n_points: int, accepted=()) -> list:
    """The ranked residual sources: best basis per (parameter, covariate), top ``N_SOURCES``."""
    seen, out = set(), []
    acc = {(a.cand.info.get("parameter"), a.cand.info.get("covariate")) for a in accepted}
    for s in scored:
        key = (s.cand.info.get("parameter"), s.cand.info.get("covariate"))
        if key in seen:
            continue
        seen.add(key)
        out.append({"parameter": key[0], "covariate": key[1],
                    "basis": s.cand.info.get("basis"), "kind": s.cand.kind,
                    "name": s.cand.name,
                    "explained_um": round(1e3 * math.sqrt(max(s.gain, 0.0) / n_points), 4),
                    "delta_bic": round(s.dbic, 2), "accepted": key in acc})
        if len(out) >= N_SOURCES:
            break
    return out


@dataclass
class Accepted:
    """An accepted effect: its candidate, parameters, columns (N, 3, m) and evidence."""

    cand: cands.Candidate
    params: list
    cols: np.ndarray            # (N, 3, m) at all points
    evidence: dict


@dataclass
class Selection:
    """Result of :func:`select`: accepted effects, the final design, the screenings."""

    accepted: list
    design: object              # blocks.Design: declared + effect columns
    first: list                 # screening on the declared model's residual
    last: list                  # screening on the final residual
    n_candidates: int


def select(candidates, ctx: Context, A0, y, folds, w_rows, screen_points: int) -> Selection:
    """Forward selection with held-out evidence, then the backward check.  ``ctx`` is on the
    training points; screening uses at most ``screen_points`` of them (a random subset), the
    leaders are then scored exactly on all training points."""
    train = ctx.pts
    ctx_s = ctx
    if len(train) > screen_points:
        sub = np.sort(np.random.default_rng(1).choice(len(train), screen_points, replace=False))
        ctx_s = ctx.on(train[sub], ctx.sw[sub])
    tr_s = rows_of(ctx_s.pts)
    ytr_s = y[tr_s] * w_rows[tr_s]

    def dense(design):       # the base on the screening points (a few thousand: dense)
        return Base(design.rows(ctx_s.pts) * w_rows[tr_s, None], ytr_s,
                    ctx.data.readings_per_point()[ctx_s.pts].sum())

    def full(design):
        return dense(design) if ctx_s is ctx else _full_base(design, train, w_rows, y)

    st = {"A": A0, "cv": _cv_sq(A0, y, folds, train, w_rows), "first": None, "last": []}
    rejected: set = set()

    def propose(accepted):        # screen on the current residual, then the leaders in turn
        base = full(st["A"])
        scored = screen(candidates, ctx_s, dense(st["A"]) if ctx_s is not ctx else base,
                        rejected | {a.cand.name for a in accepted})
        if ctx_s is not ctx:
            scored = rescore(scored, ctx, base, candidates, 2 * N_SOURCES)
        st["last"] = scored
        if st["first"] is None:
            st["first"] = scored
        if len(accepted) >= MAX_EFFECTS:
            return None
        from .lags import prefer_plain
        scored = _lag_leaders_refined(scored, st["A"], ctx, train, w_rows, y, _order(candidates))
        prefer_plain(scored, TOP_FIT)
        return _first_earning(scored, st, base, ctx, (train, w_rows, y, folds), rejected,
                              len(accepted) + 1)

    # one screening more after the last effect (as before): it fixes profiles the final
    # screening reuses
    accepted = stepwise.forward(propose, lambda hit, chosen: True, MAX_EFFECTS + 1)
    A_all, first, last = st["A"], st["first"], st["last"]
    if accepted:
        accepted = _backward(A0, accepted, train, w_rows, y)
        accepted = _merge(A0, accepted, first[:2 * N_SOURCES], ctx, train, w_rows, y)
        from . import lags
        lags.refine(accepted, A0, ctx, train, w_rows, y)
        lags.alternatives(accepted, (first or [])[:2 * N_SOURCES] + last[:2 * N_SOURCES], A0,
                          ctx, train, w_rows, y, folds)
        A_all = _stack(A0, accepted)
        base = full(A_all)
        names = {a.cand.name for a in accepted}
        if ctx_s is not ctx:
            last = rescore(screen(candidates, ctx_s, dense(A_all), names),
                           ctx, base, candidates, 2 * N_SOURCES)
        else:
            last = screen(candidates, ctx, base, names)
    _same_cause(accepted)
    return Selection(accepted, A_all, first or [], last, len(candidates))


def _first_earning(scored, st, base, ctx, fit_data, rejected: set, step: int):
    """The first of the ``TOP_FIT`` leaders that earns its place (the rule of
    :mod:`volerr.selection.rules`: dBIC <= -``BIC_GAIN`` and the paired t of the held-out
    improvement >= ``CV_T``), as an :class:`Accepted` (``st``'s design and cross-validated
    residual updated), or None; a leader refused by the t is not tried again."""
    train, w_rows, y, folds = fit_data
    for x in scored[:TOP_FIT]:
        if x.dbic > -BIC_GAIN:          # (not bic_accepts, NaN included as before)
            return None
        x = _lag_refined(x, st["A"], ctx, train, w_rows, y)
        cols, _ = ctx.columns(x.cand.terms, full=True)
        A_try = st["A"].plus([cols])
        cv_old, cv_new = st["cv"], _cv_sq(A_try, y, folds, train, w_rows)
        t = paired_t(cv_old - cv_new)
        if t < CV_T:
            rejected.add(x.cand.name)
            continue
        alts = [o.cand.name for o in scored[:2 * N_SOURCES] if o.cand.name != x.cand.name
                and o.gain >= 0.98 * x.gain]
        st["A"], st["cv"] = A_try, cv_new
        return Accepted(x.cand, x.params, cols, {
            "delta_bic": round(x.dbic, 2),
            "rss_reduction_fraction": round(x.gain / base.rss, 5),
            "cv_rms_before_um": round(1e3 * math.sqrt(cv_old.mean()), 4),
            "cv_rms_after_um": round(1e3 * math.sqrt(cv_new.mean()), 4),
            "cv_paired_t": round(t, 2), "step": step,
            "indistinguishable_from": alts[:5]})
    return None


def _lag_leaders_refined(scored: list, A_all, ctx, train, w_rows, y, order: dict) -> list:
    """The leaders (``2 TOP_FIT``) with the time constant of every lag candidate among them
    that explains at least ``lags.NEAR`` of the best one's RSS reduction refined on all
    training points, scored there and sorted again.  Screening fixes a time constant on a
    subset and a 5 % grid: correlated sensors (two motors on one duty cycle) are then
    compared at taus a few per cent off by different amounts, and the wrong one can lead
    (MB1, 10^5 points: T_motorY ahead of the planted T_motorX at 4 % off its tau)."""
    from .lags import NEAR, profile_tau

    head = scored[:2 * TOP_FIT]
    g0 = max((x.gain for x in head), default=0.0)
    near = [x for x in head if x.cand.search is not None and x.cand.search.what == "lag_s"
            and x.gain >= NEAR * g0]
    if not near:
        return scored
    base = _full_base(A_all, train, w_rows, y)
    cs = []
    for x in head:
        c = x.cand
        if any(x is n for n in near):
            tau, std = profile_tau(c, ctx, base, float(c.info["lag_s"]))
            c = c.fixed(tau)
            c.info["lag_std_s"] = None if std is None else round(std, 1)
        cs.append(c)
    head = [x for x in _scored_many(cs, ctx, base) if x.rank]
    rank(head, order)
    return head + scored[2 * TOP_FIT:]


def _lag_refined(x: Scored, A_all, ctx, train, w_rows, y) -> Scored:
    """A lag candidate with its time constant refined on all training points before it is
    judged (screening fixed it on a subset and a grid: a few per cent off leave a residual
    that a second, spurious effect would take up); other candidates as they are."""
    if x.cand.search is None or x.cand.search.what != "lag_s":
        return x
    from .lags import profile_tau

    base = _full_base(A_all, train, w_rows, y)
    tau, std = profile_tau(x.cand, ctx, base, float(x.cand.info["lag_s"]))
    cand = x.cand.fixed(tau)
    cand.info["lag_std_s"] = None if std is None else round(std, 1)
    return Scored(x.dbic, x.gain, x.rank, cand, x.params)


def _backward(A0, selected, train, w_rows, y) -> list:
    """Drop an effect that, given all the others, no longer gains dBIC < -BIC_GAIN (a later
    effect made it redundant); each kept effect gets ``delta_bic_given_others``."""
    def without(sel, i):          # cost of dropping effect i: minus its dBIC given the others
        base = _full_base(_stack(A0, sel[:i] + sel[i + 1:]), train, w_rows, y)
        gain, rank = base.score(_dense_group(sel[i].cols))
        return -base.dbic(gain, rank + cands.extra_parameters(sel[i].cand)), None

    def drop(res, sel):
        return not (-res[0] <= -BIC_GAIN or len(sel) == 1)

    sel, last = stepwise.backward(selected, without, drop)
    for s_, (cost, _) in zip(sel, last or []):
        s_.evidence["delta_bic_given_others"] = round(-cost, 2)
    for k, s_ in enumerate(sel):
        s_.evidence["step"] = k + 1
    return sel


def _merge(A0, accepted, pool, ctx: Context, train, w_rows, y) -> list:
    """Parsimony across overlapping candidates: two accepted effects are replaced by ONE
    candidate of the first screening when it explains the data at least as well by BIC (e.g.
    a yaw of Y, taken first as squareness and then as a yaw of X).  Repeated while it helps."""
    sel = stepwise.merge(accepted, lambda s: _merged(A0, s, pool, ctx, train, w_rows, y))
    for k, s_ in enumerate(sel):
        s_.evidence["step"] = k + 1
    return sel


def _merged(A0, sel, pool, ctx: Context, train, w_rows, y):
    """``sel`` with the best pair replaced by one candidate of ``pool``, or None."""
    best = (0.0, None)
    for i in range(len(sel)):
        for j in range(i + 1, len(sel)):
            others = [s_ for k, s_ in enumerate(sel) if k not in (i, j)]
            base = _full_base(_stack(A0, others), train, w_rows, y)
            pair = np.concatenate([sel[i].cols, sel[j].cols], axis=2)
            xs = [x for x in pool
                  if x.cand.name not in (sel[i].cand.name, sel[j].cand.name)]
            scores = base.score_many([_dense_group(pair)] +
                                     [ctx.group(x.cand.terms) for x in xs])
            g_ij, r_ij = scores[0]
            m_ij = r_ij + sum(cands.extra_parameters(s_.cand) for s_ in (sel[i], sel[j]))
            for x, (g_c, r_c) in zip(xs, scores[1:]):
                m_c = r_c + cands.extra_parameters(x.cand)
                d = base.dbic(g_c, m_c) - base.dbic(g_ij, m_ij)
                if r_c and d < best[0]:
                    best = (d, (i, j, x))
    if best[1] is None:
        return None
    i, j, x = best[1]
    cols, _ = ctx.columns(x.cand.terms, full=True)
    ev = dict(sel[i].evidence)
    ev["replaces"] = [sel[i].cand.name, sel[j].cand.name]
    ev["delta_bic_vs_replaced"] = round(best[0], 2)
    merged = Accepted(x.cand, x.params, cols, ev)
    return [s_ for k, s_ in enumerate(sel) if k not in (i, j)] + [merged]


def _same_cause(accepted) -> None:
    """Mark accepted effects that modulate the same parameter by the same covariate (e.g. a
    linear and a saturating drift of the set-up): one cause, two bases."""
    for a in accepted:
        key = (a.cand.info.get("parameter"), a.cand.info.get("covariate"))
        same = [b.cand.name for b in accepted if b is not a and
                (b.cand.info.get("parameter"), b.cand.info.get("covariate")) == key]
        if same:
            a.evidence["same_cause_as"] = same
