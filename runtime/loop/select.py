"""Screening and selection of candidate effects (steps 4-5 of :func:`volerr.loop.run.run_loop`).

Screen: every candidate (P x C x basis, :mod:`volerr.loop.candidates`) is scored against the
current residual by the exact RSS reduction of adding its columns to the current design (a
score test through the Gram matrix: no refit), converted to a BIC change; searched basis
parameters (warm-up tau, step location, period) are profiled on their grid, refined, and cost
one extra parameter.  Select: the best three by BIC are fitted fully; the first with dBIC <
-``BIC_GAIN`` and a significantly smaller cross-validated residual (paired t > ``CV_T`` on the
per-point squared errors) is accepted; repeat.  After acceptance every effect is re-tested
given the others (backward check) and dropped when it no longer earns its place.

Rows are weighted (robust weights of the points, :func:`robust_weights`): gross outliers do
not drive the choice.  Units: mm rows; BIC in natural-log units.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from volerr.loop import candidates as cands
from volerr.loop.fit import Problem, point_norm, rows_of, twist_columns
from volerr.machine.expressions import evaluate

BIC_GAIN = 10.0      # minimum BIC improvement (natural-log units) to accept an effect
CV_T = 3.0           # minimum paired t of the held-out improvement
MAX_EFFECTS = 8
TOP_FIT = 3          # candidates fitted fully per forward step
N_SOURCES = 10       # residual sources reported


def _pinv_sym(G, tol=1e-12):
    """Pseudo-inverse of a symmetric PSD matrix by eigh (small matrices only)."""
    w, V = np.linalg.eigh(G)
    ok = w > tol * max(float(w[-1]), 1e-300)
    return (V[:, ok] / w[ok]) @ V[:, ok].T


class Base:
    """The current design on the (weighted) training rows, column-scaled, with its Gram
    pseudo-inverse; :meth:`score` is the RSS reduction of adding columns."""

    def __init__(self, A, y):
        self.scale = np.sqrt(np.mean(A ** 2, axis=0))
        self.scale[self.scale == 0] = 1.0
        self.A = A / self.scale
        self.Gi = _pinv_sym(self.A.T @ self.A)
        self.r = y - self.A @ (self.Gi @ (self.A.T @ y))
        self.rss = float(self.r @ self.r)
        self.n = len(y)

    def score(self, B) -> tuple[float, int]:
        """(RSS reduction, effective rank) of adding the columns B (rows, m)."""
        sc = np.sqrt(np.mean(B ** 2, axis=0))
        sc[sc == 0] = 1.0
        Bs = B / sc
        C = self.A.T @ Bs
        M = Bs.T @ Bs - C.T @ self.Gi @ C
        w, V = np.linalg.eigh((M + M.T) / 2)
        ok = w > 1e-9 * len(Bs)          # columns (unit RMS) not inside the base span
        if not ok.any():
            return 0.0, 0
        g = V[:, ok].T @ (Bs.T @ self.r)
        return float(np.sum(g * g / w[ok])), int(ok.sum())

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

    def dbic(self, gain: float, m_eff: int) -> float:
        new = max(self.rss - gain, 1e-300)
        return self.n * math.log(new / self.rss) + m_eff * math.log(self.n)


@dataclass
class Context:
    """What the columns of a candidate need: model, data, sensitivities, frame, rows."""

    model: object
    data: object
    sens: np.ndarray
    frame: tuple
    rows: np.ndarray          # weighted training rows
    sqrt_w: np.ndarray        # sqrt of the robust weights on those rows
    ranges: dict
    cache: dict = field(default_factory=dict)

    def values(self):
        from volerr.loop.fit import rotary_rad

        if "_values" not in self.cache:
            self.cache["_values"] = {**rotary_rad(self.model, self.data.positions),
                                     **self.data.covariates}
        return self.cache["_values"]

    def target_column(self, target: str) -> np.ndarray:
        """(N, 3) sensitivity of a chain target (a parameter, ``work.*`` or ``tool.*``)."""
        key = ("target", target)
        if key not in self.cache:
            if "." in target:
                side, k = target.split(".")
                self.cache[key] = twist_columns(side, k, self.data, self.frame)
            else:
                self.cache[key] = self.sens[:, :, self.model.parameters.index(target)]
        return self.cache[key]

    def columns(self, terms) -> tuple[np.ndarray, list]:
        """(N, 3, m) columns of the parameters of ``terms`` [(parameter, target, basis)]."""
        key = tuple(terms)
        if key not in self.cache:
            params = list(dict.fromkeys(t[0] for t in terms))
            out = np.zeros((self.data.n, 3, len(params)))
            for pn, target, basis in terms:
                b = np.broadcast_to(evaluate(basis, self.values()), (self.data.n,))
                out[:, :, params.index(pn)] += self.target_column(target) * b[:, None]
            self.cache[key] = (out, params)
            if len(self.cache) > 3000:      # profiles make many; keep memory bounded
                for k in list(self.cache)[:1000]:
                    if k != "_values" and not (isinstance(k, tuple) and k[0] == "target"):
                        del self.cache[k]
        return self.cache[key]

    def profile_rows(self, c, values) -> np.ndarray:
        """Weighted training rows (rows, G) of a one-term searched candidate at ``values``."""
        key = ("profile", c.name, tuple(values))
        if key not in self.cache:
            (_, target, _), = c.search.make(values[0])[0]
            pts = self.rows[::3] // 3
            vals = self.values()
            sub = {k: np.asarray(v)[pts] if np.ndim(v) else v for k, v in vals.items()}
            basis = np.column_stack([np.broadcast_to(evaluate(c.search.make(v)[0][0][2], sub),
                                                     (len(pts),)) for v in values])
            t = self.target_column(target)[pts]                      # (n, 3)
            B = (t[:, :, None] * basis[:, None, :]).reshape(-1, len(values))
            self.cache[key] = B * self.sqrt_w[:, None]
        return self.cache[key]

    def train_rows(self, cols) -> np.ndarray:
        return cols.reshape(-1, cols.shape[-1])[self.rows] * self.sqrt_w[:, None]


@dataclass
class Scored:
    """A screened candidate: BIC change, RSS reduction, rank, its (fixed) candidate, columns."""

    dbic: float
    gain: float
    rank: int
    cand: cands.Candidate
    cols: np.ndarray
    params: list


def _profile(c: cands.Candidate, ctx: Context, base: Base) -> cands.Candidate:
    """Fix the searched basis parameter of ``c`` at its best value (grid, then refined)."""
    if c.search.what == "period":
        return c.fixed(_periodic_best(c, ctx, base))
    grid = list(c.search.grid)

    def best_of(values):
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
        fine = np.geomspace(max(lo, 1e-3), hi, 15)
    if len(fine):
        v0 = best_of([v0] + [float(x) for x in fine])
    return c.fixed(v0)


def _periodic_best(c, ctx: Context, base: Base) -> float:
    """Best period of a periodic candidate by the residual periodogram, refined."""
    comp, axis, periods = c.info["component"], c.info["axis"], np.asarray(c.search.grid)
    n = len(ctx.rows) // 3
    s = (ctx.target_column(comp).reshape(-1)[ctx.rows] * ctx.sqrt_w).reshape(n, 3)
    r = base.r.reshape(n, 3)
    w = np.sum(r * s, axis=1)
    s2 = np.sum(s * s, axis=1)
    q = ctx.data.positions[axis][ctx.rows[::3] // 3]

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


def screen(candidates, ctx: Context, base: Base, skip=()) -> list:
    """Score every candidate against the residual of ``base``; sorted by BIC change."""
    out = []

    def scored(c):
        cols, params = ctx.columns(c.terms)
        gain, rank = base.score(ctx.train_rows(cols))
        m_eff = rank + (1 if c.search is not None else 0)
        return Scored(base.dbic(gain, m_eff), gain, rank, c, cols, params)

    fixed = ctx.cache.setdefault("fixed", {})
    for c in candidates:
        if c.name in skip:
            continue
        if c.search is not None:
            # profiled once; later screenings reuse the value and re-profile the leaders
            c = fixed[c.name] if c.name in fixed else _profile(c, ctx, base)
            fixed[c.name] = c
        s = scored(c)
        if s.rank:
            out.append(s)
    out.sort(key=lambda s: s.dbic)
    for i, s in enumerate(out[:2 * TOP_FIT]):
        if s.cand.search is not None and not s.cand.info.get("_fresh_for") == id(base):
            c = _profile(s.cand, ctx, base)
            c.info["_fresh_for"] = id(base)
            fixed[c.name] = c
            out[i] = scored(c)
    for s in out:
        s.cand.info.pop("_fresh_for", None)
    out = [s for s in out if s.rank]
    out.sort(key=lambda s: s.dbic)
    _prefer_first_of_ties(out, candidates)
    return out


def _prefer_first_of_ties(scored: list, candidates: list) -> None:
    """Among candidates that fit the data identically (e.g. on a CMM ``EZX`` depending on ``Y``
    and ``EZY`` depending on ``X``), put the one listed first by
    :func:`volerr.loop.candidates.build` in front: the choice does not depend on rounding."""
    if len(scored) < 2:
        return
    order = {c.name: i for i, c in enumerate(candidates)}
    d0 = scored[0].dbic
    ties = [i for i, s in enumerate(scored) if abs(s.dbic - d0) <= 1e-7 * abs(d0) + 1e-9]
    first = min(ties, key=lambda i: order.get(scored[i].cand.name, len(order)))
    scored.insert(0, scored.pop(first))


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
    cols: np.ndarray
    evidence: dict


@dataclass
class Selection:
    """Result of :func:`select`: accepted effects, the final design, the screenings."""

    accepted: list
    A: np.ndarray               # (3N, k + m) declared + effect columns
    first: list                 # screening on the declared model's residual
    last: list                  # screening on the final residual
    n_candidates: int


def _cv_sq(A, y, folds, train, w_rows) -> np.ndarray:
    """Per-point squared cross-validated residual (weighted rows)."""
    prob = Problem(A * w_rows[:, None], y * w_rows)
    r = prob.loo_residuals(train) if folds is None else prob.cv_residuals(folds, train)
    return point_norm(r) ** 2


def select(candidates, ctx: Context, A0, y, train, folds, w_rows) -> Selection:
    """Forward selection with held-out evidence, then the backward check."""
    tr = rows_of(train)
    ytr = y[tr] * ctx.sqrt_w
    A_all = A0
    cv_old = _cv_sq(A_all, y, folds, train, w_rows)
    accepted, rejected, first, last = [], set(), None, []
    while True:
        base = Base(A_all[tr] * ctx.sqrt_w[:, None], ytr)
        scored = screen(candidates, ctx, base, rejected | {a.cand.name for a in accepted})
        last = scored
        if first is None:
            first = scored
        if len(accepted) >= MAX_EFFECTS:
            break
        hit = None
        for s in scored[:TOP_FIT]:
            if s.dbic > -BIC_GAIN:
                break
            A_try = np.concatenate([A_all, s.cols.reshape(-1, s.cols.shape[-1])], axis=1)
            cv_new = _cv_sq(A_try, y, folds, train, w_rows)
            d = cv_old - cv_new
            t = float(d.mean() / (d.std(ddof=1) / math.sqrt(len(d)) + 1e-300))
            if t < CV_T:
                rejected.add(s.cand.name)
                continue
            alts = [o.cand.name for o in scored if o.cand.name != s.cand.name
                    and o.gain >= 0.98 * s.gain]
            hit = Accepted(s.cand, s.params, s.cols, {
                "delta_bic": round(s.dbic, 2),
                "rss_reduction_fraction": round(s.gain / base.rss, 5),
                "cv_rms_before_um": round(1e3 * math.sqrt(cv_old.mean()), 4),
                "cv_rms_after_um": round(1e3 * math.sqrt(cv_new.mean()), 4),
                "cv_paired_t": round(t, 2), "step": len(accepted) + 1,
                "indistinguishable_from": alts[:5]})
            A_all, cv_old = A_try, cv_new
            break
        if hit is None:
            break
        accepted.append(hit)
    if accepted:
        accepted = _backward(A0, accepted, ctx, ytr)
        A_all = _stack(A0, accepted)
        base = Base(A_all[tr] * ctx.sqrt_w[:, None], ytr)
        last = screen(candidates, ctx, base, {a.cand.name for a in accepted})
    _same_cause(accepted)
    return Selection(accepted, A_all, first or [], last, len(candidates))


def _stack(A0, sel):
    return np.concatenate([A0] + [s.cols.reshape(-1, s.cols.shape[-1]) for s in sel], axis=1)


def _backward(A0, selected, ctx: Context, ytr) -> list:
    """Drop an effect that, given all the others, no longer gains dBIC < -BIC_GAIN (a later
    effect made it redundant); each kept effect gets ``delta_bic_given_others``."""
    tr = ctx.rows

    def dbic_without(sel, i):
        base = Base(_stack(A0, sel[:i] + sel[i + 1:])[tr] * ctx.sqrt_w[:, None], ytr)
        gain, rank = base.score(ctx.train_rows(sel[i].cols))
        return base.dbic(gain, rank + (1 if sel[i].cand.search is not None else 0))

    sel = list(selected)
    while sel:
        scores = [dbic_without(sel, i) for i in range(len(sel))]
        worst = int(np.argmax(scores))
        if scores[worst] <= -BIC_GAIN or len(sel) == 1:
            for s_, d in zip(sel, scores):
                s_.evidence["delta_bic_given_others"] = round(d, 2)
            break
        sel.pop(worst)
    for k, s_ in enumerate(sel):
        s_.evidence["step"] = k + 1
    return sel


def _same_cause(accepted) -> None:
    """Mark accepted effects that modulate the same parameter by the same covariate (e.g. a
    linear and a saturating drift of the set-up): one cause, two bases."""
    for a in accepted:
        key = (a.cand.info.get("parameter"), a.cand.info.get("covariate"))
        same = [b.cand.name for b in accepted if b is not a and
                (b.cand.info.get("parameter"), b.cand.info.get("covariate")) == key]
        if same:
            a.evidence["same_cause_as"] = same
