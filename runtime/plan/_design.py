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
for a candidate while that lowers the criterion; (4) the readings per set-up by the
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
#: most passes of the exchange
EXCHANGE_PASSES = 8
#: iterations of the multiplicative algorithm
ALLOCATION_STEPS = 200


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


def gains(Minv: np.ndarray, W: np.ndarray, U: np.ndarray, kind: str, scale: float = 1.0
          ) -> np.ndarray:
    """Decrease of the criterion (C,) when ``scale * U_c U_c^T`` is added to ``M``."""
    U = U * np.sqrt(scale)
    B = np.matmul(Minv, U)                                      # M^-1 U  (C, q, r)
    Ut = np.transpose(U, (0, 2, 1))
    C = np.eye(U.shape[2]) + np.matmul(Ut, B)
    if kind == "D":
        return np.linalg.slogdet(C)[1]
    D = np.matmul(np.transpose(B, (0, 2, 1)), np.matmul(W, B))   # U^T M^-1 W M^-1 U
    return np.trace(np.linalg.solve(C, D), axis1=1, axis2=2)


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
        best = int(np.argmax(g))
        chosen.append(best)
        free[best] = False
        M = M + cand.info[best]
        i = cand.inst[best]
        if sum(1 for c in chosen if cand.inst[c] == i) >= caps[i]:
            free[cand.inst == i] = False
    return chosen


def exchange(cand: Candidates, W, P0, kind: str, chosen: list, locked=()) -> list:
    """Fedorov exchange on the equal-readings criterion: swap a chosen set-up (not
    ``locked``) for a free candidate of the same instrument while that lowers it."""
    chosen = list(chosen)
    q = W.shape[0]
    ridge = RIDGE * max(float(np.mean(np.trace(cand.info, axis1=1, axis2=2))) / q, 1e-300)
    for _ in range(EXCHANGE_PASSES):
        M = P0 + ridge * np.eye(q) + cand.info[chosen].sum(axis=0)
        now = criterion(M, W, kind)
        best = (0.0, None, None)
        for pos, s in enumerate(chosen):
            if s in locked:
                continue
            Mm = M - cand.info[s]
            g = gains(np.linalg.pinv(Mm, hermitian=True), W, cand.factor, kind)
            base = criterion(Mm, W, kind)
            new = base - g
            new[chosen] = np.inf
            new[cand.inst != cand.inst[s]] = np.inf
            c = int(np.argmin(new))
            if now - new[c] > best[0] + 1e-9 * abs(now):
                best = (now - new[c], pos, c)
        if best[1] is None:
            break
        chosen[best[1]] = best[2]
    return chosen


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
        j = int(np.argmax(np.where(m > lo, m - target, -np.inf)))
        m[j] -= 1
    while m.sum() < readings and (m < hi).any():
        m[int(np.argmax(np.where(m < hi, target - m, -np.inf)))] += 1
    return m


def minutes(cand: Candidates, chosen: list, m) -> float:
    """Set-up changes plus readings (minutes)."""
    return float(sum(cand.setup_min[s] + m[k] * cand.read_min[s]
                     for k, s in enumerate(chosen)))


def plan_value(cand, W, P0, kind, chosen, m) -> float:
    M = P0 + np.tensordot(np.asarray(m, float), cand.info[chosen], axes=1)
    return criterion(M, W, kind)
