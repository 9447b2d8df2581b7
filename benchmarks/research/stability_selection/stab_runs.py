"""Stability selection (RULE.md) on the FL_THERMAL windows: the loop once per window and
sampling, and the runtime's own lag selection on every leave-one-blocked-fold-out subsample.

Per window and sampling: ``volerr loop`` in-process (tests/helpers/fl_runs.py, the runs the
tests read), with ``volerr.loop.drift.fit._channel`` wrapped only to keep what it is called
with (the channel, the basis columns, Z, the candidates); then per subsample k (fold k not
training, the others renumbered) :func:`select_on`: ``select.select_terms`` as
``fit._channel`` calls it.  Writes out/<window>_<step>.json: the loop's JSON and, per
channel, the own sources of the terms each subsample selected; CPU (process time) of the
loop and of the subsample selections.

usage: python stab_runs.py [WINDOW ...]   (default: the six windows; both samplings)
"""

from __future__ import annotations

import itertools
import json
import os
import sys
import time

import numpy as np
from threadpoolctl import threadpool_limits

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(os.path.dirname(HERE)))
sys.path.insert(0, os.path.join(ROOT, "tests"))
OUT = os.path.join(HERE, "out")

from helpers.fl_runs import WINDOWS, loop_run  # noqa: E402
from volerr.loop.drift import basis, fit  # noqa: E402
from volerr.loop.drift import select as sel  # noqa: E402
from volerr.loop.drift.engine import Engine  # noqa: E402

STEPS = (1, 4)
#: "lofo" (RULE.md: leave one blocked fold out, K subsamples) or "cpairs" (a sensitivity
#: measured after RULE.md's figures: every split of the K folds into two complementary
#: halves, Shah & Samworth 2013; K = 6: 10 pairs, 20 subsamples of 3 folds)
SCHEME = os.environ.get("STAB_SCHEME", "lofo")


def out_name(name: str, step: int, scheme: str = SCHEME) -> str:
    """out/<window>_<step>[_<scheme>].json: the file of one window and sampling."""
    return os.path.join(OUT, f"{name}_{step}{'' if scheme == 'lofo' else '_' + scheme}.json")


def source_key(cols, a: int) -> str:
    """A basis column's source (RULE.md): the heat input at any exponent and lag is one
    source, ``basis.SPEED``; a sensor its name."""
    c = cols[a]
    return basis.SPEED if c.source == "heat" else c.source


def subsample_folds(fold: np.ndarray, k: int) -> np.ndarray:
    """Fold k not training (-1), the other folds renumbered 0..K-2 in order."""
    f = fold.copy()
    f[fold == k] = -1
    f[fold > k] -= 1
    return f


def half_folds(fold: np.ndarray, half) -> np.ndarray:
    """Only the folds ``half`` training, renumbered 0.. in order; the others -1."""
    f = np.full_like(fold, -1)
    for i, k in enumerate(sorted(half)):
        f[fold == k] = i
    return f


def subsample_list(fold: np.ndarray) -> list:
    """The subsamples' fold arrays of ``SCHEME``."""
    K = int(fold.max()) + 1
    if SCHEME == "lofo":
        return [subsample_folds(fold, k) for k in range(K)]
    halves = [h for h in itertools.combinations(range(K), K // 2) if 0 in h]
    return [half_folds(fold, x) for h in halves
            for x in (h, tuple(k for k in range(K) if k not in h))]


def select_on(ch, cols, Z, cands, fold, cache) -> list:
    """The terms ``select.select_terms`` takes on the training readings ``fold >= 0``, as
    ``fit._channel`` calls it (the heat input first, then the sensors)."""
    eng = Engine(Z, ch.y, fold, basis.whole_runs(ch.rule), ch.s.run, ch.n_runs, cache,
                 ch.s.zero(ch.y))
    heat_c, sensor_c = cands
    terms = []
    if len(heat_c):
        terms = sel.select_terms(eng, cols, ch.n_runs, cands=heat_c, max_terms=fit.HEAT_TERMS)
    if len(sensor_c):
        terms = terms + sel.select_terms(eng, cols, ch.n_runs, cands=sensor_c, start=terms)
    return terms


def run_window(name: str, step: int) -> dict:
    seen = []
    original = fit._channel

    def keep(ch, cols, Z, cands, cache):
        seen.append((ch, cols, Z, cands))
        return original(ch, cols, Z, cands, cache)

    fit._channel = keep
    try:
        t0 = time.process_time()
        run = loop_run(step, name)
        cpu_loop = time.process_time() - t0
    finally:
        fit._channel = original
    assert run.returncode == 0, run.stderr
    out = {"window": name, "step": step, "cpu_loop_s": cpu_loop, "doc": run.doc,
           "channels": {}}
    K = len(subsample_list(seen[0][0].fold))
    caches = [{} for _ in range(K)]
    t0 = time.process_time()
    with threadpool_limits(limits=1, user_api="blas"):
        for ch, cols, Z, cands in seen:
            label = next(k for k, v in ch.s.channels.items() if v is ch.y)
            subs = []
            for k, f in enumerate(subsample_list(ch.fold)):
                terms = select_on(ch, cols, Z, cands, f, caches[k])
                subs.append([source_key(cols, t["pair"][0]) for t in terms])
            out["channels"][label] = {"K": K, "fold_rule": ch.rule, "subsamples": subs}
    out["cpu_subsamples_s"] = time.process_time() - t0
    return out


def main(names):
    os.makedirs(OUT, exist_ok=True)
    for name in names:
        for step in STEPS:
            res = run_window(name, step)
            with open(out_name(name, step), "w") as fh:
                json.dump(res, fh, indent=1, default=float)
            print(f"{name} step {step}: loop {res['cpu_loop_s']:.1f} s CPU, "
                  f"{len(res['channels'])} channels x K subsamples "
                  f"{res['cpu_subsamples_s']:.1f} s CPU", flush=True)


if __name__ == "__main__":
    main(sys.argv[1:] or list(WINDOWS))
