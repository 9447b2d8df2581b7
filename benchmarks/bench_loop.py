"""Benchmark of ``volerr loop``: fit plus diagnosis of 10^4 measured points.

MB1 (21 functions: 18 component errors + 3 squareness), five probe offsets, two set-ups,
every covariate column present so that all 8 candidate families are searched (thermal, drift,
reversal, coupling, periodic, higher_order, probe_direction, setup), one undeclared effect.
Target: under 30 s on a 2-core machine.  Baseline in the same process: one plain numpy
least-squares solve of the declared design of the same points (what a single fit costs).

    python benchmarks/bench_loop.py [n_points]
"""

import sys
import time

import numpy as np

import volerr
from volerr.loop.fit import data_ranges, declared_design
from volerr.loop.run import columns_to_data, run_loop
from volerr.loop.simulate import demo_probes, simulate


def main(n: int = 10_000) -> None:
    model = volerr.load("MB1")
    camp = simulate("MB1", n_points=n, seed=7, probes=demo_probes(model), rounds=2,
                    effects=[{"kind": "periodic", "component": "EYY", "period_mm": 30.0,
                              "um": 1.5}])
    # baseline: one least-squares solve of the declared model (degree 4) on the same points
    t0 = time.perf_counter()
    data = columns_to_data(camp.columns(), model)
    d = declared_design(model, data, 4, data_ranges(model, data))
    A = d.A.reshape(-1, d.A.shape[-1])
    np.linalg.lstsq(A, data.deviation.ravel(), rcond=None)
    base = time.perf_counter() - t0

    t0 = time.perf_counter()
    rep = run_loop("MB1", camp, progress=False)
    total = time.perf_counter() - t0
    print(f"points: {n}; functions: {len(model.parameters)}; candidate families: "
          f"{len(rep['candidate_families'])} ({', '.join(rep['candidate_families'])}); "
          f"candidates tested: {rep['candidates_tested']}")
    print(f"loop (fit + diagnosis + augment + report numbers): {total:.2f} s  (target < 30 s)")
    print(f"baseline (one declared least-squares solve): {base:.2f} s; ratio {total / base:.1f}")
    print(rep.summary())


if __name__ == "__main__":
    main(int(sys.argv[1]) if len(sys.argv) > 1 else 10_000)
