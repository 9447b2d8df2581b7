"""The group lasso over the drift loop's lag bank (Yuan & Lin 2006, "Model selection and
estimation in regression with grouped variables", JRSS B 68, 49-67) as a diagnosis: which
sources (a sensor with all its lags, the heat input with all its exponents and lags) a
channel needs, and whether 15 s and 60 s sampling name the same ones (issue 44, done-when 2).
Research script, outside the package; the rule and every choice: benchmarks/research/group_lasso/glasso_prereg.md
(committed before any figure).

Steps, per window and sampling (the bank is the package's, nothing is rebuilt here):

1. the series, split and bank as ``volerr loop`` builds them (``series.read_runs``,
   ``split.held_out``, ``basis.library``, ``basis.folds``, ``fit._candidates``: the columns the
   regularised fit takes, ``shrink``), the columns times ``1/sqrt(w)``, ``w = (1 + tau/T)^2``
   the shrink weights (so a plain group norm of the scaled coefficients ``c = W b`` is the
   weighted penalty ``||W_g b_g||``);
2. per fit (all training readings, and without each fold) the Gram matrix from the folds'
   cross-products (``shrink._blocks``), centred per run (the free zeros), and per group the
   eigen-decomposition of its block;
3. per channel, along the grid ``lambda_max 10^(-k/4)`` (k = 0..``N_LAMBDA``-1) from the
   largest, block coordinate descent alternating with Newton steps on the nonzero groups
   (:func:`solve`; converged on the KKT conditions), warm started; every fold's squared
   error from its cross-products (as ``shrink.fit``); lambda of least CV mean square, a tie to
   the larger; the one-standard-error lambda beside it (ESL 7.10);
4. the diagnosis: the groups with a nonzero coefficient at the chosen lambda, fitted on all
   training readings; per group the column of largest abs(c_j) (its tau, its exponent).

Objective per fit, in the scaled coordinates (um, columns of unit training RMS over
sqrt(w)):  ``0.5 (y'y - 2 c'h + c'G c) + lambda sum_g sqrt(p_g) ||c_g||``, ``G`` and ``h`` centred
per run.

Run:  .venv/bin/python benchmarks/research/group_lasso/fl_loops.py (the loop's JSON: baselines, lag terms), then
.venv/bin/python benchmarks/research/group_lasso/glasso.py --step 1 and --step 4 (benchmarks/research/group_lasso/out/glasso_<window>_<step>.json),
then .venv/bin/python benchmarks/research/group_lasso/glasso.py --compare (the tables: benchmarks/research/group_lasso/out/compare.txt).
Figures and what they mean: benchmarks/research/group_lasso/glasso_results.md.
"""

from __future__ import annotations

import json
import math
import sys
import time
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
OUT = HERE / "out"

N_LAMBDA = 21          # quarter decades: lambda_max down to 1e-5 lambda_max
KKT_TOL = 1e-6         # converged: largest KKT violation below this share of lambda_max
BCD_SWEEPS = 10        # block coordinate descent sweeps between Newton rounds
MAX_ROUNDS = 200       # rounds of descent and Newton at most (reported if reached)
MAX_NEWTON = 50        # Newton steps per round at most
ZERO_REL = 1e-10       # a group this small against the largest is zero
EIG_FLOOR = 1e-14      # Newton: the Hessian's eigenvalues floored at this share of the largest
SHORTEST_60S = 240.0   # the 60 s grid's shortest lag (4 readings)
TAU_FACTOR = 1.5       # dominant time constants agree within this factor (plus the grids)


# ---- the bank (the package's) -------------------------------------------------------------
def series_of(path: Path, window: str):
    """The series with its held-out mask, as ``volerr loop`` builds it for FL_THERMAL (no
    directed channel: the channels are modelled as they are)."""
    from volerr.loop.drift.series import read_runs, stack_runs
    from volerr.loop.drift.split import held_out

    runs, left = read_runs([str(path)])
    s = stack_runs(runs, left)
    s.test, _ = held_out(s, window, ())
    return s


def bank(s, weighted: bool = True) -> dict:
    """The regularised fit's columns (``fit._regularised``), their groups and the fits'
    centred Gram matrices (module steps 1-2)."""
    from volerr.loop.drift import basis, fit, shrink

    s.memo.clear()
    cols, X = basis.library(s)
    fold, rule = basis.folds(s)
    n_runs = len(s.runs)
    Z = np.column_stack([s.indicators(), X])
    cands = fit._candidates(s, cols, False, basis.many_runs(s))
    keep = sorted({int(a) for c in cands for a, b in c if b < 0})
    kcols = [cols[j] for j in keep]
    scale = 1.0 / np.sqrt(shrink.weights(kcols, shrink.fold_time(s, fold))) if weighted \
        else np.ones(len(keep))
    Zs = Z[:, [n_runs + j for j in keep]] * scale
    blocks = shrink._blocks(Zs, s.run, n_runs, fold)
    K = int(fold.max()) + 1
    names = list(dict.fromkeys(c.source for c in kcols))
    groups = [_span([c.source == g for c in kcols]) for g in names]
    fits = [_centred(blocks, k, groups) for k in range(-1, K)]
    anchored = basis.whole_runs(rule)
    tests = [(blocks[k],) + shrink._centres(fits[k + 1][:2], blocks[k], anchored)
             for k in range(K)]
    grid = basis.tau_grid(s)
    return {"s": s, "cols": kcols, "Zs": Zs, "fold": fold, "K": K, "anchored": anchored,
            "names": names, "groups": groups, "fits": fits, "tests": tests,
            "half_step": 0.5 * math.log(grid[1] / grid[0]), "tau_grid": grid}


def _span(mask) -> slice:
    """The columns of a group: contiguous in the bank (a source's plain column and lags, the
    heat input's exponents and lags), as a slice."""
    i = np.flatnonzero(mask)
    assert len(i) and i[-1] - i[0] + 1 == len(i), "a group's columns are not contiguous"
    return slice(int(i[0]), int(i[-1]) + 1)


def _centred(blocks, leave, groups):
    """(per-run means (n_runs, p), counts, the Gram matrix centred per run, per group the
    eigen-decomposition (d, U) of its block) over the folds but ``leave`` (-1: none)."""
    parts = [b for k, b in enumerate(blocks) if k != leave]
    G = sum(b[0] for b in parts)
    sums, cnt = sum(b[1] for b in parts), sum(b[2] for b in parts)
    mu = sums / np.maximum(cnt, 1.0)[:, None]
    Gc = G - (sums.T * (1.0 / np.maximum(cnt, 1.0))) @ sums
    Gc = 0.5 * (Gc + Gc.T)
    eig = []
    for g in groups:
        d, U = np.linalg.eigh(Gc[g, g])
        eig.append((np.clip(d, d[-1] * 1e-13, None), U))
    return mu, cnt, Gc, eig


# ---- the solver ---------------------------------------------------------------------------
def _block(rho_norm_sq_terms, d, lam):
    """mu > 0 with ``sum rho_i^2 mu^2 / (d_i + mu)^2 = lam^2`` (``rho_norm_sq_terms`` =
    rho^2): the group's exact update is then ``(D + mu)^-1 rho`` in its eigenbasis.
    Safeguarded Newton on ``F(mu) = mu phi(mu) - lam``, ``phi = ||(D + mu)^-1 rho||``."""
    r2 = rho_norm_sq_terms
    nr = math.sqrt(float(r2.sum()))
    lo, hi = lam * d[0] / (nr - lam), lam * d[-1] / (nr - lam)
    m = math.sqrt(lo * hi) if lo > 0 else 0.5 * hi
    for _ in range(100):
        q = r2 / (d + m) ** 2
        phi = math.sqrt(float(q.sum()))
        if phi == 0.0:
            return hi
        F = m * phi - lam
        if abs(F) <= 1e-14 * lam:
            break
        if F > 0:
            hi = m
        else:
            lo = m
        dF = phi - m * float((q / (d + m)).sum()) / phi
        new = m - F / dF if dF > 0 else 0.5 * (lo + hi)
        m = new if lo < new < hi else 0.5 * (lo + hi)
        if hi - lo <= 1e-15 * hi:
            break
    return m


def solve(G, h, groups, eig, lam_g, c, tol):
    """The group lasso ``0.5 c'G c - h'c + sum_g lam_g ||c_g||`` from ``c`` (changed in place):
    block coordinate descent (:func:`_sweeps`: exact block updates, it decides which groups
    are zero) alternating with Newton's method on the groups it leaves nonzero
    (:func:`_newton`: between-group correlation makes descent alone crawl at small lambda);
    converged when every group's KKT violation is below ``tol``.  Returns (c, BCD sweeps,
    Newton steps, converged)."""
    sweeps = steps = 0
    for _ in range(MAX_ROUNDS):
        c, n, ok = _sweeps(G, h, groups, eig, lam_g, c, tol, BCD_SWEEPS)
        sweeps += n
        if ok:
            return c, sweeps, steps, True
        c, n = _newton(G, h, groups, lam_g, c, tol)
        steps += n
        if _kkt(h - G @ c, c, groups, lam_g) <= tol:
            return c, sweeps, steps, True
    return c, sweeps, steps, False


def _sweeps(G, h, groups, eig, lam_g, c, tol, most):
    """At most ``most`` sweeps of block coordinate descent, groups in order, each group's
    update exact; stops early once converged.  Returns (c, sweeps, converged)."""
    r = h - G @ c
    for sweep in range(1, most + 1):
        for gi, g in enumerate(groups):
            cg = c[g]
            rg = r[g] + G[g, g] @ cg
            lam = lam_g[gi]
            if float(rg @ rg) <= lam * lam * (1.0 + 1e-12):    # at the threshold: 0
                new = np.zeros(g.stop - g.start)
            else:
                d, U = eig[gi]
                rho = U.T @ rg
                m = _block(rho ** 2, d, lam)
                new = U @ (rho / (d + m))
            delta = new - cg
            if np.any(delta):
                r -= G[:, g] @ delta
                c[g] = new
        if _kkt(r, c, groups, lam_g) <= tol:
            return c, sweep, True
    return c, most, False


def _objective(G, h, groups, lam_g, c) -> float:
    starts = [g.start for g in groups]
    norms = np.sqrt(np.add.reduceat(c * c, starts))
    return 0.5 * float(c @ G @ c) - float(h @ c) + float(lam_g @ norms)


def _newton(G, h, groups, lam_g, c, tol):
    """Damped Newton steps (Armijo backtracking on the objective) on the nonzero groups, the
    others held at zero (the objective is smooth there); a group whose norm falls below
    ``ZERO_REL`` of the largest is set to zero (block coordinate descent then decides it).
    Returns (c, steps)."""
    steps = 0
    for _ in range(MAX_NEWTON):
        act = [i for i, g in enumerate(groups) if c[g].any()]
        if not act:
            break
        idx = np.concatenate([np.arange(g.start, g.stop) for g in (groups[i] for i in act)])
        grad = G[idx] @ c - h[idx]
        H = G[np.ix_(idx, idx)]
        pos, sl = 0, []
        for i in act:
            g = groups[i]
            n = float(np.linalg.norm(c[g]))
            u = c[g] / n
            s_ = slice(pos, pos + len(u))
            grad[s_] += lam_g[i] * u
            H[s_, s_] += lam_g[i] / n * (np.eye(len(u)) - np.outer(u, u))
            pos += len(u)
            sl.append(s_)
        if max(float(np.linalg.norm(grad[s_])) for s_ in sl) <= tol:
            break
        w, V = np.linalg.eigh(H)
        w = np.maximum(w, w[-1] * EIG_FLOOR)
        step = -(V @ ((V.T @ grad) / w))
        f0, slope, t = _objective(G, h, groups, lam_g, c), float(grad @ step), 1.0
        for _ in range(40):
            trial = c.copy()
            trial[idx] += t * step
            if _objective(G, h, groups, lam_g, trial) <= f0 + 1e-4 * t * slope:
                break
            t *= 0.5
        else:
            break
        c = trial
        steps += 1
        big = max(float(np.linalg.norm(c[groups[i]])) for i in act)
        for i in act:
            if float(np.linalg.norm(c[groups[i]])) < ZERO_REL * big:
                c[groups[i]] = 0.0
    return c, steps


def _kkt(r, c, groups, lam_g) -> float:
    """Largest violation of the optimality conditions: ``||r_g|| <= lam_g`` where ``c_g = 0``,
    ``r_g = lam_g c_g / ||c_g||`` elsewhere (``r = h - G c``)."""
    worst = 0.0
    for gi, g in enumerate(groups):
        n = float(np.linalg.norm(c[g]))
        if n == 0.0:
            worst = max(worst, float(np.linalg.norm(r[g])) - lam_g[gi])
        else:
            worst = max(worst, float(np.linalg.norm(r[g] - lam_g[gi] * c[g] / n)))
    return worst


# ---- one channel --------------------------------------------------------------------------
def channel(b: dict, y: np.ndarray) -> dict:
    """The group lasso of one channel ``y`` (N,) um on the bank ``b`` (module steps 3-4)."""
    from volerr.selection.rules import TIE_SCORE_REL

    s, fold, K, groups = b["s"], b["fold"], b["K"], b["groups"]
    n_runs, run = len(s.runs), s.run
    idx = [np.flatnonzero(fold == k) for k in range(K)]
    zy = [b["Zs"][i].T @ y[i] for i in idx]
    ys = [np.bincount(run[i], y[i], n_runs) for i in idx]
    first = s.run_zeros(y)
    sqp = np.array([math.sqrt(g.stop - g.start) for g in groups])

    def rhs(k):           # centred Zs'y of the fit without fold k (k = -1: all)
        mu = b["fits"][k + 1][0]
        ysum = sum(ys[j] for j in range(K) if j != k)
        return sum(zy[j] for j in range(K) if j != k) - mu.T @ ysum, ysum

    h_all, _ = rhs(-1)
    lam_max = max(float(np.linalg.norm(h_all[g])) / sqp[i] for i, g in enumerate(groups))
    lams = lam_max * 10.0 ** (-np.arange(N_LAMBDA) / 4.0)
    tol = KKT_TOL * lam_max
    coef = np.zeros((K + 1, len(lams), b["Zs"].shape[1]))
    sweeps, unconv = 0, 0
    for k in range(-1, K):
        mu, cnt, G, eig = b["fits"][k + 1]
        h, _ = rhs(k)
        c = np.zeros(len(h))
        for li, lam in enumerate(lams):
            c, n, _, ok = solve(G, h, groups, eig, lam * sqp, c, tol)
            sweeps, unconv = max(sweeps, n), unconv + (not ok)
            coef[k + 1, li] = c
    fold_mse = np.zeros((K, len(lams)))
    for k in range(K):
        mu, cnt = b["fits"][k + 1][:2]
        (_, S, n), Gt, m = b["tests"][k]
        ysum = sum(ys[j] for j in range(K) if j != k)
        cz = first if b["anchored"] else np.where(cnt > 0, ysum / np.maximum(cnt, 1.0), first)
        hk = zy[k] - S.T @ cz - m.T @ ys[k] + m.T @ (n * cz)
        yy = float(y[idx[k]] @ y[idx[k]]) - 2 * cz @ ys[k] + n @ cz ** 2
        B = coef[k + 1].T
        sse = yy - 2 * B.T @ hk + np.einsum("il,il->l", B, Gt @ B)
        fold_mse[k] = np.maximum(sse, 0.0) / len(idx[k])
    cv = (fold_mse * np.array([len(i) for i in idx])[:, None]).sum(0) / sum(len(i) for i in idx)
    best = 0                     # from the largest lambda: a tie keeps the larger
    for j in range(1, len(lams)):
        if cv[j] < cv[best] * (1 - TIE_SCORE_REL):
            best = j
    se = float(np.std(fold_mse[:, best], ddof=1) / math.sqrt(K))
    one_se = min(j for j in range(len(lams)) if cv[j] <= cv[best] + se)
    c = coef[0, best]
    out = {"lambda_rel": float(lams[best] / lam_max), "lambda_1se_rel":
           float(lams[one_se] / lam_max), "cv_rms_um": math.sqrt(float(cv[best])),
           "cv_rms_1se_um": math.sqrt(float(cv[one_se])), "max_sweeps": sweeps,
           "not_converged": unconv, "at_grid_end": best == len(lams) - 1}
    out.update(diagnosis(b, c))
    out["sources_1se"] = diagnosis(b, coef[0, one_se])["sources"]
    pred = _predict(b, c, h_all, rhs(-1)[1], first, y)
    te = s.test
    out["mae_um"] = float(np.mean(np.abs(y[te] - pred[te])))
    out["mae_1se_um"] = float(np.mean(np.abs(
        y[te] - _predict(b, coef[0, one_se], h_all, rhs(-1)[1], first, y)[te])))
    return out


def _predict(b, c, h_all, ysum, first, y):
    """Every reading by the fit on all training readings (a run's zero fitted where it has
    training readings, else its first reading), as ``shrink._predict``."""
    mu, cnt = b["fits"][0][:2]
    s = b["s"]
    zero = np.where(cnt > 0, ysum / np.maximum(cnt, 1.0) - mu @ c, first)
    return zero[s.run] + b["Zs"] @ c


def diagnosis(b: dict, c: np.ndarray) -> dict:
    """The sources with a nonzero coefficient and each one's dominant column (the largest
    abs(c_j); a tie to the shorter tau): its tau (s) and, for the heat input, its exponent."""
    out = {"sources": [], "tau_s": {}, "p": {}, "norm_share": {}}
    tot = float(c @ c)
    for name, g in zip(b["names"], b["groups"]):
        cg = c[g]
        if not np.any(cg):
            continue
        a = np.abs(cg)
        j = min(np.flatnonzero(a == a.max()), key=lambda i: b["cols"][g.start + i].tau_s)
        col = b["cols"][g.start + j]
        out["sources"].append(name)
        out["tau_s"][name] = float(col.tau_s)
        if col.p is not None:
            out["p"][name] = col.p
        out["norm_share"][name] = round(float(cg @ cg) / tot, 4)
    return out


# ---- the six windows ----------------------------------------------------------------------
def run_all(weighted: bool = True, steps=(1, 4), names=None) -> dict:
    """Every window and sampling: the group lasso per channel, the loop's baselines, CPU;
    each window-sampling also written to benchmarks/research/group_lasso/out/glasso_<window>_<step><tag>.json."""
    from threadpoolctl import threadpool_limits

    sys.path.insert(0, str(HERE.parents[2] / "tests"))
    from helpers.fl_runs import WINDOWS

    res = {}
    with threadpool_limits(limits=1, user_api="blas"):
        for name, (window, _) in WINDOWS.items():
            if names and name not in names:
                continue
            for step in steps:
                doc = json.loads((OUT / f"loop_{name}_{step}.json").read_text())
                t0 = time.process_time()
                s = series_of(OUT / f"fl_{name}_{step}.csv", window)
                b = bank(s, weighted)
                t1 = time.process_time()
                chans = {ch: channel(b, y) for ch, y in s.channels.items()}
                t2 = time.process_time()
                for ch, r in chans.items():
                    base = doc["channels"][ch]["baselines"]
                    r["bound_um"] = 1.05 * min(base["static"]["mae_um"],
                                               base["constant"]["mae_um"]) + 0.2
                    r["family"] = doc["channels"][ch]["family"]
                    r["mae_reported_um"] = doc["channels"][ch]["mae_after_um"]
                    r["lag_sources"] = lag_sources(doc, ch)
                res[f"{name}_{step}"] = {"channels": chans, "cpu_bank_s": t1 - t0,
                                         "cpu_glasso_s": t2 - t1,
                                         "half_step": b["half_step"],
                                         "n_columns": int(b["Zs"].shape[1]),
                                         "groups": {n: g.stop - g.start for n, g in
                                                    zip(b["names"], b["groups"])}}
                tag = "" if weighted else "_unweighted"
                (OUT / f"glasso_{name}_{step}{tag}.json").write_text(
                    json.dumps(res[f"{name}_{step}"], indent=1, default=str))
                print(name, step, f"{t2 - t1:.1f} s", flush=True)
    return res


def lag_sources(doc: dict, ch: str) -> list:
    """The sources of the lag model's reported terms of channel ``ch`` (the loop's JSON;
    the heat input named ``heat``)."""
    out = set()
    for e in doc["effects"]:
        if e["channels"] != [ch]:
            continue
        for t in e["terms"]:
            cov = e["covariate"]
            out.add("heat" if cov.startswith("S_rpm") else cov)
    return sorted(out)


def taus_agree(a: float, b: float, ha: float, hb: float, strict: bool) -> bool:
    """Dominant time constants agree (benchmarks/research/group_lasso/glasso_prereg.md)."""
    if a < SHORTEST_60S and b < SHORTEST_60S:
        return True
    if a <= 0 or b <= 0:
        return False
    slack = 0.0 if strict else ha + hb
    return abs(math.log(a / b)) <= math.log(TAU_FACTOR) + slack + 1e-12


def compare(res: dict, key_sources: str = "sources") -> dict:
    """15 s against 60 s: Jaccard, equal sets, tau agreement; MAE against the bound."""
    from helpers.fl_runs import WINDOWS

    rows, eq, jac, within, within60 = [], 0, [], 0, 0
    tau_ok = tau_ok_strict = tau_n = 0
    for name in WINDOWS:
        a, b = res[f"{name}_1"], res[f"{name}_4"]
        for ch in a["channels"]:
            ca, cb = a["channels"][ch], b["channels"][ch]
            sa, sb = set(ca[key_sources]), set(cb[key_sources])
            j = len(sa & sb) / len(sa | sb) if sa | sb else 1.0
            jac.append(j)
            eq += sa == sb
            within += ca["mae_um"] <= ca["bound_um"]
            within60 += cb["mae_um"] <= cb["bound_um"]
            for src in sorted(sa & sb):
                if key_sources != "sources":
                    continue
                tau_n += 1
                tau_ok += taus_agree(ca["tau_s"][src], cb["tau_s"][src], a["half_step"],
                                     b["half_step"], False)
                tau_ok_strict += taus_agree(ca["tau_s"][src], cb["tau_s"][src],
                                            a["half_step"], b["half_step"], True)
            rows.append((name, ch, sorted(sa), sorted(sb), j))
    return {"equal_sets": eq, "jaccard_mean": float(np.mean(jac)), "within_bound_15s": within,
            "within_bound_60s": within60, "tau_agree": tau_ok, "tau_agree_strict": tau_ok_strict,
            "tau_pairs": tau_n, "rows": rows}


def lag_terms_all(doc: dict, ch: str) -> list:
    """The sources of every term the lag model of channel ``ch`` chose (reported as effects
    or listed in ``not_reported``), the heat input named ``heat``."""
    import re

    out = set(lag_sources(doc, ch))
    for line in doc.get("not_reported", []):
        label, _, basis_ = line.partition(": ")
        if label != ch:
            continue
        m = re.match(r"(?:lag\()?\(?([^,()]+)", basis_)
        src = m.group(1).strip()
        out.add("heat" if src.startswith("S_rpm") else src)
    return sorted(out)


def report(res: dict) -> None:
    """The tables of the report (stdout)."""
    from helpers.fl_runs import WINDOWS

    c = compare(res)
    print("window ch | 15 s: sources (dominant tau s) | 60 s: sources | J | MAE 15/60 um | bound "
          "15/60 | lambda_rel 15/60 | 1se sets")
    for name in WINDOWS:
        a, b = res[f"{name}_1"], res[f"{name}_4"]
        for ch in a["channels"]:
            ca, cb = a["channels"][ch], b["channels"][ch]

            def fmt(x):
                return " ".join(f"{s}@{x['tau_s'][s]:.0f}" + (f"^{x['p'][s]:g}" if s in x["p"]
                                                               else "") for s in x["sources"])
            sa, sb = set(ca["sources"]), set(cb["sources"])
            j = len(sa & sb) / len(sa | sb) if sa | sb else 1.0
            print(f"{name} {ch} | {fmt(ca)} | {fmt(cb)} | {j:.2f} | {ca['mae_um']:.2f}/"
                  f"{cb['mae_um']:.2f} | {ca['bound_um']:.2f}/{cb['bound_um']:.2f} | "
                  f"{ca['lambda_rel']:.2g}/{cb['lambda_rel']:.2g} | "
                  f"{len(ca['sources_1se'])}/{len(cb['sources_1se'])} "
                  f"{'=' if set(ca['sources_1se']) == set(cb['sources_1se']) else '!='}")
    print({k: v for k, v in c.items() if k != "rows"})
    one = compare(res, "sources_1se")
    print("one-SE lambda: equal sets", one["equal_sets"], "Jaccard", round(one["jaccard_mean"], 3))
    w15 = sum(ch["mae_1se_um"] <= ch["bound_um"] for k, v in res.items() if k.endswith("_1")
              for ch in v["channels"].values())
    print("one-SE lambda: within bound at 15 s", w15)
    sizes = [len(ch["sources"]) for v in res.values() for ch in v["channels"].values()]
    print("set sizes: mean", np.mean(sizes), "min", min(sizes), "max", max(sizes))
    lagq = [(n, ch) for n in WINDOWS for ch in res[f"{n}_1"]["channels"]]
    eq_named = sum(set(res[f"{n}_1"]["channels"][ch]["lag_sources"]) ==
                   set(res[f"{n}_4"]["channels"][ch]["lag_sources"]) for n, ch in lagq)
    docs = {k: json.loads((OUT / f"loop_{k}.json").read_text()) for k in res}
    eq_all = sum(set(lag_terms_all(docs[f"{n}_1"], ch)) == set(lag_terms_all(docs[f"{n}_4"], ch))
                 for n, ch in lagq)
    print("forward selection: equal source sets, named effects", eq_named, "all chosen terms",
          eq_all)
    for k, v in res.items():
        print(k, "CPU glasso s", round(v["cpu_glasso_s"], 1), "bank s", round(v["cpu_bank_s"], 2),
              "columns", v["n_columns"], "max sweeps",
              max(ch["max_sweeps"] for ch in v["channels"].values()), "not converged",
              sum(ch["not_converged"] for ch in v["channels"].values()), "at grid end",
              sum(ch["at_grid_end"] for ch in v["channels"].values()))


def main():
    """``glasso.py [--unweighted] [--step 1|4] [--compare]``: compute (one sampling or both),
    or compare what the files hold."""
    weighted = "--unweighted" not in sys.argv
    tag = "" if weighted else "_unweighted"
    if "--compare" in sys.argv:
        sys.path.insert(0, str(HERE.parents[2] / "tests"))
        from helpers.fl_runs import WINDOWS
        res = {f"{n}_{s}": json.loads((OUT / f"glasso_{n}_{s}{tag}.json").read_text())
               for n in WINDOWS for s in (1, 4)}
        report(res)
        return
    steps = (int(sys.argv[sys.argv.index("--step") + 1]),) if "--step" in sys.argv else (1, 4)
    run_all(weighted, steps)


if __name__ == "__main__":
    main()
