"""Choosing set-ups and spreading the readings: sequential (greedy) optimal design with
low-rank updates, then Fedorov's exchange, on the normal equations of the candidate set-ups
(Fedorov 1972, *Theory of Optimal Experiments*, ch. 3; Atkinson, Donev & Tobias 2007,
*Optimum Experimental Designs, with SAS*, ch. 12: sequential construction and exchange).

Every set-up ``s`` brings, per reading, ``I_s`` (q, q): its Schur information divided by its
template's readings (:mod:`volerr.plan._information`), so ``m`` readings of it bring about
``m I_s``.  The information of a plan is ``M = P0 + sum_s m_s I_s`` (``P0``: the priors of the
campaign-wide nuisances).  Criteria (columns scaled to unit information first):

* I-optimal (default): ``trace(W M^-1)``, the mean squared predicted uncertainty of the
  volumetric error over the map grid;
* D-optimal: ``-log det M`` over the columns.

Steps: (1) greedy: add, one at a time, the set-up that lowers the criterion most (equal
readings per set-up; a tiny ridge ``RIDGE`` makes the start defined), each candidate scored
through the Woodbury identity from its low-rank factor ``I_s = U U^T``; (2) the number of
set-ups ``K`` along the greedy path: the smallest whose criterion, with the readings spread
over its set-ups, is within ``GOOD_ENOUGH`` of the best (a set-up change costs more than
readings), within the time budget; (3) Fedorov exchange at that ``K``: swap a chosen set-up
for a candidate while that lowers the criterion, from the greedy start and a few random
ones (``--seed``), the best end point kept; (4) the readings per set-up by the
multiplicative algorithm for the approximate design (weights ``w_s <- w_s (d_s / mean d)^0.5``
with ``d_s = trace(M^-1 W M^-1 I_s)``, Silvey, Titterington & Torsney 1978), rounded to whole
readings, each set-up at least its minimum.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

#: ridge of the greedy start, relative to the mean information of a set-up
RIDGE = 1e-8
#: a number of set-ups whose criterion is within this factor of the best is enough
GOOD_ENOUGH = 1.05
#: most passes of the exchange, and its time budget per start (s)
EXCHANGE_PASSES = 20
EXCHANGE_SECONDS = 10.0
#: random starts of the exchange besides the greedy one
RESTARTS = 4
#: largest columns x factor rank of a problem restarted (the exchange's cost grows as its cube)
RESTART_SIZE = 600
#: iterations of the multiplicative algorithm
ALLOCATION_STEPS = 60
#: gains within this fraction of the best are one gain (a tie): the candidate listed first
#: wins.  Mirror-image set-ups bring the same information; computed through a nearly
#: singular start their gains differ in the last bits, which differ between BLAS kernels
TIE_REL = 1e-6


def argbest(values, tol: float | None = None) -> int:
    """Index of the largest value; values within ``tol`` of it (default ``TIE_REL`` of its
    size) are one value, and the lowest index (the candidates' order) wins: the plan does not
    depend on rounding."""
    v = np.asarray(values, float)
    top = float(np.max(v))
    if not np.isfinite(top):
        return int(np.argmax(v))
    tol = TIE_REL * abs(top) if tol is None else tol
    return int(np.flatnonzero(v >= top - tol)[0])


@dataclass
class Candidates:
    """The pool: ``info`` (C, q, q) per-reading information (scaled columns), ``factor`` (C, q,
    r) low-rank factors, ``inst`` (C,) instrument index, ``min_readings``, ``max_readings``,
    ``template`` (C,),
    ``setup_min`` (C,) minutes of a set-up change, ``read_min`` (C,) minutes per reading."""

    info: np.ndarray
    factor: np.ndarray
    inst: np.ndarray
    min_readings: np.ndarray
    max_readings: np.ndarray
    template: np.ndarray
    setup_min: np.ndarray
    read_min: np.ndarray


def factors(info: np.ndarray) -> np.ndarray:
    """Low-rank factors ``U`` (C, q, r) with ``info[c] = U U^T`` (r: the largest rank)."""
    w, V = np.linalg.eigh(info)
    top = np.maximum(w[:, -1:], 1e-300)
    ok = w > 1e-10 * top
    r = max(int(ok.sum(axis=1).max()), 1)
    w, V, ok = w[:, -r:], V[:, :, -r:], ok[:, -r:]
    return V * np.sqrt(np.where(ok, w, 0.0))[:, None, :]


def criterion(M: np.ndarray, W: np.ndarray, kind: str) -> float:
    """I: trace(W M^-1); D: -log det M (inf when singular)."""
    try:
        if kind == "D":
            sign, logdet = np.linalg.slogdet(M)
            return -logdet if sign > 0 else np.inf
        return float(np.trace(np.linalg.solve(M, W)))
    except np.linalg.LinAlgError:
        return np.inf


def gains(Minv: np.ndarray, W: np.ndarray, U: np.ndarray, kind: str, sign=None
          ) -> np.ndarray:
    """Decrease of the criterion (C,) when ``U_c S U_c^T`` is added to ``M`` (``S`` the
    diagonal ``sign``, +1 by default: an added set-up; -1 columns remove one), through the
    Woodbury identity: ``(M + U S U^T)^-1 = M^-1 - B (S + U^T B)^-1 B^T``, ``B = M^-1 U``.
    A change that leaves ``M`` not positive definite gives -inf."""
    r = U.shape[2]
    S = np.diag(np.ones(r) if sign is None else np.asarray(sign, float))
    B = np.matmul(Minv, U)                                      # M^-1 U  (C, q, r)
    K = S + np.matmul(np.transpose(U, (0, 2, 1)), B)            # S^-1 = S
    sgn, logdet = np.linalg.slogdet(np.matmul(S, K))            # det(I + S U^T M^-1 U)
    if kind == "D":
        return np.where(sgn > 0, logdet, -np.inf)
    D = np.matmul(np.transpose(B, (0, 2, 1)), np.matmul(W, B))   # U^T M^-1 W M^-1 U
    out = np.trace(np.linalg.solve(K, D), axis1=1, axis2=2)
    return np.where(sgn > 0, out, -np.inf)


def greedy(cand: Candidates, W, P0, kind: str, k_max: int, caps: dict) -> list:
    """Set-ups in the order the greedy adds them, at most ``caps[i]`` of instrument ``i``."""
    q = W.shape[0]
    ridge = RIDGE * max(float(np.mean(np.trace(cand.info, axis1=1, axis2=2))) / q, 1e-300)
    M = P0 + ridge * np.eye(q)
    chosen = []
    free = np.ones(len(cand.info), bool)
    while len(chosen) < k_max and free.any():
        g = gains(np.linalg.inv(M), W, cand.factor, kind)
        g[~free] = -np.inf
        best = argbest(g)
        chosen.append(best)
        free[best] = False
        M = M + cand.info[best]
        i = cand.inst[best]
        if sum(1 for c in chosen if cand.inst[c] == i) >= caps[i]:
            free[cand.inst == i] = False
    return chosen


def exchange(cand: Candidates, W, P0, kind: str, chosen: list, locked=()) -> list:
    """Fedorov exchange on the equal-readings criterion: swap a chosen set-up (not
    ``locked``) for a free candidate of the same instrument while that lowers it; each swap
    scored as one rank update of the current information (:func:`gains` with the removed
    set-up's factor signed -1: no near-singular intermediate)."""
    import time

    chosen = list(chosen)
    q = W.shape[0]
    ridge = RIDGE * max(float(np.mean(np.trace(cand.info, axis1=1, axis2=2))) / q, 1e-300)
    r = cand.factor.shape[2]
    sign = np.concatenate([np.ones(r), -np.ones(r)])
    stop = time.perf_counter() + EXCHANGE_SECONDS
    for _ in range(EXCHANGE_PASSES):
        if time.perf_counter() > stop:
            break
        M = P0 + ridge * np.eye(q) + cand.info[chosen].sum(axis=0)
        Minv = np.linalg.inv(M)
        best = (1e-9 * abs(criterion(M, W, kind)), None, None)
        for pos, s in enumerate(chosen):
            if s in locked:
                continue
            free = np.flatnonzero(cand.inst == cand.inst[s])
            free = free[~np.isin(free, chosen)]
            if not len(free):
                continue
            F = cand.factor[free]
            V = np.concatenate([F, np.broadcast_to(cand.factor[s], F.shape)], axis=2)
            g = gains(Minv, W, V, kind, sign)
            c = argbest(g)
            if g[c] > best[0] * (1 + TIE_REL):
                best = (g[c], pos, int(free[c]))
        if best[1] is None:
            break
        chosen[best[1]] = best[2]
    return chosen


def best_exchange(cand: Candidates, W, P0, kind: str, start: list, restarts: int = RESTARTS,
                  seed: int = 0) -> list:
    """:func:`exchange` from the greedy ``start`` and from ``restarts`` random starts with as
    many set-ups of each instrument (seeded by ``seed``): the best end point (a single-swap
    exchange stops at a local optimum)."""
    rng = np.random.default_rng(seed)
    q = W.shape[0]
    if q * cand.factor.shape[2] > RESTART_SIZE:      # large problems: the greedy start only
        restarts = 0
    ridge = RIDGE * max(float(np.mean(np.trace(cand.info, axis1=1, axis2=2))) / q, 1e-300)
    starts = [list(start)]
    for _ in range(restarts):
        trial = []
        for i in dict.fromkeys(cand.inst[start].tolist()):
            pool = np.flatnonzero(cand.inst == i)
            k = int(np.sum(cand.inst[start] == i))
            trial += rng.choice(pool, size=k, replace=False).tolist()
        starts.append(trial)
    ends = [exchange(cand, W, P0, kind, s) for s in starts]
    value = [criterion(P0 + ridge * np.eye(q) + cand.info[e].sum(axis=0), W, kind)
             for e in ends]
    return ends[argbest(-np.asarray(value))]


def allocate(cand: Candidates, W, P0, kind: str, chosen: list, readings: int) -> np.ndarray:
    """Whole readings per chosen set-up (sum ``readings``, each within its minimum and
    maximum) by the multiplicative algorithm."""
    info = cand.info[chosen]
    lo = cand.min_readings[chosen]
    hi = cand.max_readings[chosen]
    w = np.full(len(chosen), 1.0 / len(chosen))
    for _ in range(ALLOCATION_STEPS):
        M = P0 + readings * np.tensordot(w, info, axes=1)
        try:
            Minv = np.linalg.inv(M)
        except np.linalg.LinAlgError:
            break
        A = Minv if kind == "D" else Minv @ W @ Minv
        d = np.tensordot(info, A, axes=([1, 2], [1, 0]))
        w = w * np.sqrt(np.maximum(d, 1e-300) / max(float(w @ d), 1e-300))
        w = np.clip(w / w.sum(), lo / readings, hi / readings)
    return _whole(w * readings, lo, hi, readings)


def _whole(target, lo, hi, readings: int) -> np.ndarray:
    """Whole numbers near ``target`` within [lo, hi] summing to ``readings`` (when the bounds
    allow)."""
    m = np.clip(np.floor(target).astype(int), lo, hi)
    while m.sum() > readings and (m > lo).any():
        j = argbest(np.where(m > lo, m - target, -np.inf), tol=1e-9)
        m[j] -= 1
    while m.sum() < readings and (m < hi).any():
        m[argbest(np.where(m < hi, target - m, -np.inf), tol=1e-9)] += 1
    return m


def minutes(cand: Candidates, chosen: list, m) -> float:
    """Set-up changes plus readings (minutes)."""
    return float(sum(cand.setup_min[s] + m[k] * cand.read_min[s]
                     for k, s in enumerate(chosen)))


def plan_value(cand, W, P0, kind, chosen, m) -> float:
    M = P0 + np.tensordot(np.asarray(m, float), cand.info[chosen], axes=1)
    return criterion(M, W, kind)
