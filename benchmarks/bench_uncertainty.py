"""Task-specific Monte Carlo: 10^4 machines x 10^3 probing points (10^7 point evaluations +
10^4 sphere fits) on MB1.

Machines: constrained Monte Carlo from "E0=2+L/300" (all 21 parameters random, rejection on the
simulated ISO 10360-2 test) + 0.3 um probing noise.  Reports the single-process time, a
baseline in the same process (the same samples one by one: one Model.volumetric_error call and
one sphere fit per sample), the LocalCluster (2 workers) time, and the per-sample cost for
planning 10^6 samples on a cluster.  Run: python benchmarks/bench_uncertainty.py
"""

from __future__ import annotations

import os
import time

import numpy as np

import volerr
from volerr.uncertainty import ensemble, montecarlo as mc, tasks


def sphere_task(n=1000):
    rng = np.random.default_rng(0)
    d = rng.normal(size=(n, 3))
    d[:, 2] = np.abs(d[:, 2])
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    p = np.array([450.0, 287.5, 150.0]) + 25.0 * d
    return tasks.Task({"X": p[:, 0], "Y": p[:, 1], "Z": p[:, 2]}, np.zeros((n, 3)), d)


def main():
    model = volerr.load("MB1")
    task = sphere_task()
    ens = ensemble.Ensemble.build(spec=ensemble.parse_spec("E0=2+L/300"), noise_um=0.3, seed=1)
    t0 = time.perf_counter()
    prob = mc.prepare(model, "MB1", task, "sphere", ens, seed=1)
    t_prep = time.perf_counter() - t0
    N = 10_000
    t0 = time.perf_counter()
    v1, info = mc.run(prob, N, mc.Runner(chunks=1))
    t_single = time.perf_counter() - t0
    # baseline: the same kind of work sample by sample (draw once, evaluate per sample)
    nb = 100
    d = prob.sources[0].draw(np.random.default_rng(0), nb, model)
    t0 = time.perf_counter()
    for s in range(nb):
        errs = {k: np.broadcast_to(v[s], (task.n_points,)) for k, v in d.errors.items()}
        e = model.volumetric_error(task.positions, errs)
        tasks.evaluate("sphere", prob.nominal - e)
    t_base = (time.perf_counter() - t0) / nb
    print(f"conditions: {os.cpu_count()} cores shared with other jobs, load "
          f"{os.getloadavg()[0]:.1f}")
    print(f"prepare (pilot of 400 candidates): {t_prep:.2f} s")
    print(f"single process, {N} samples x {task.n_points} points: {t_single:.2f} s "
          f"({t_single / N * 1e3:.3f} ms/sample; candidates {info['candidates']}, "
          f"acceptance {info['kept'] / info['candidates']:.2f})")
    print(f"baseline one sample at a time (evaluation only, no rejection test): "
          f"{t_base * 1e3:.3f} ms/sample -> vectorised engine {t_base / (t_single / N):.1f} x faster")
    try:
        from dask.distributed import Client  # noqa: F401
    except ImportError:
        print("dask not installed: LocalCluster skipped")
        return
    with mc.Runner("dask", chunks=8, workers=2) as runner:
        mc.run(prob, 1000, runner)  # warm up (workers load the model)
        t0 = time.perf_counter()
        vd, _ = mc.run(prob, N, runner)
        t_dask = time.perf_counter() - t0
    print(f"LocalCluster 2 workers: {t_dask:.2f} s -> speed-up {t_single / t_dask:.2f} x; "
          f"identical values: {np.array_equal(v1, vd)}")
    per = t_single / N
    print(f"planning: 10^6 samples ~ {per * 1e6 / 60:.1f} min on one core; "
          f"on W cluster cores ~ {per * 1e6:.0f} s / W")


if __name__ == "__main__":
    main()
