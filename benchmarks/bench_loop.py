"""Benchmark of ``volerr loop``: screening every (parameter, covariate, basis) candidate plus
selection on 10^4 measured points with 4 covariate columns (issue 9: under 30 s on a 2-core
machine), and the whole loop on 10^5 (issue 14: under 15 s, under 1 GB) and 10^6 points (time
and peak memory reported).

MB1 (21 functions), five probe offsets, two set-ups; covariates T_C, t_s, dir_X, setup (4
columns); one undeclared effect.  Baseline in the same process: one plain numpy least-squares
solve of the declared design of the same points (what a single fit costs; skipped above 2e5
points, where the dense design alone would need gigabytes).  BLAS is limited to one thread
inside the loop (threadpoolctl).  Each size runs in a child process: CPU time of the loop
(``time.process_time``: robust on a shared machine), wall time, and the child's peak RSS
(``RUSAGE_CHILDREN``), with the RSS before the loop (simulated campaign in memory).

    python benchmarks/bench_loop.py [n_points ...]      (default: 10000 100000)
    python benchmarks/bench_loop.py --json DIR [n ...]  also write each size's JSON to DIR
    python benchmarks/bench_loop.py --threads N         default BLAS threads vs one thread
    python benchmarks/bench_loop.py --lags [N]          N points (default 10^5), 10 sensors

``--lags``: the loop with the lag search (issue 30: 10^5 points, 10 logged temperatures over
10 h, drives 6 h on then off, the X scale following T_motorX through a 40 min lag; covariate
columns t_s and the ten sensors: 10 lagged, 10 plain and 45 difference covariates); under
30 s asked.  CPU and wall time, the effect found with its time constant.

``--drift [N]``: the loop on drift runs (issue 35: 10^5 readings x 24 sensors x 2 channels
under 60 s): one simulated spindle run of N readings (default 10^5) 5 s apart, a spindle
programme of random speeds and pauses, 24 sensors (first-order responses of the heat input
and of the room, 0.01 K noise), two channels (a lag of the heat, a lag of one sensor, 0.2 um
noise); the last 25 % held out.  Reading the file and the loop, CPU and wall time.

``--threads``: the loop on N points twice, with the loop's one-thread BLAS limit lifted
(default threads) and as shipped (one thread); wall and CPU time of each.  Start a busy
process first to see the effect of a shared core (OpenBLAS threads spin-wait).
"""

import resource
import sys
import time

import numpy as np

import volerr
from volerr.estimate.design import data_ranges, declared_design
from volerr.loop.run import columns_to_data, run_loop
from volerr.loop.simulate import demo_probes, simulate

KEEP = ("T_C", "t_s", "dir_X", "setup")


def one(n: int, json_dir: str | None = None) -> None:
    model = volerr.load("MB1")
    camp = simulate("MB1", n_points=n, seed=7, probes=demo_probes(model), rounds=2,
                    effects=[{"kind": "thermal", "axis": "Y", "ppm_per_K": 6.0}])
    camp.covariates = {c: v for c, v in camp.covariates.items() if c in KEEP}
    data = columns_to_data(camp.columns(), model)
    del camp
    base = None
    if n <= 200000:
        t0 = time.perf_counter()
        d = declared_design(model, data, 4, data_ranges(model, data))
        A = d.A.reshape(-1, d.A.shape[-1])
        np.linalg.lstsq(A, data.deviation.ravel(), rcond=None)
        base = time.perf_counter() - t0
        del d, A
    pre = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024
    t0, c0 = time.perf_counter(), time.process_time()
    rep = run_loop("MB1", data, progress=False)
    total, cpu = time.perf_counter() - t0, time.process_time() - c0
    print(f"points: {n}; covariate columns: {len(KEEP)}; candidates screened: "
          f"{rep['candidates_tested']} (kinds: {', '.join(rep['candidate_families'])})")
    ratio = (f"baseline (one dense declared least-squares solve): {base:.2f} s; ratio "
             f"{total / base:.1f}" if base else "baseline skipped (dense design too large)")
    print(f"loop (screening + selection + augment + before/after): CPU {cpu:.2f} s, wall "
          f"{total:.2f} s; {ratio}; peak RSS before the loop {pre:.0f} MB")
    print("  " + rep.summary())
    if json_dir:    # the loop's JSON, to compare two trees (benchmarks/json_close.py)
        print(f"  JSON: {rep.write_json(f'{json_dir}/loop_{n}.json')}")


def lags(n: int) -> None:
    model = volerr.load("MB1")
    camp = simulate("MB1", n_points=n, seed=7, probes=demo_probes(model), duration_h=10,
                    sensors=10, duty="on:6h,off:4h",
                    effects=[{"kind": "thermal_lag", "sensor": "T_motorX", "tau_min": 40,
                              "axis": "X", "ppm_per_K": 2.0}])
    camp.covariates = {c: v for c, v in camp.covariates.items()
                       if c == "t_s" or c.startswith("T_")}
    data = columns_to_data(camp.columns(), model)
    del camp
    t0, c0 = time.perf_counter(), time.process_time()
    rep = run_loop("MB1", data, progress=False)
    total, cpu = time.perf_counter() - t0, time.process_time() - c0
    print(f"points: {n}; sensors: 10; candidates screened: {rep['candidates_tested']}")
    print(f"loop with the lag search: CPU {cpu:.2f} s, wall {total:.2f} s (asked: < 30 s)")
    for e in rep.effects:
        lag = e.get("lag_s") or {}
        print(f"  {e['name']}: covariate {e['covariate']}, lag {lag.get('value')} s "
              f"+- {lag.get('std')} (planted 2400 s)")
    print("  " + rep.summary())


def child(n: int, json_dir: str | None = None) -> None:
    """Run :func:`one` in a child process and report its peak RSS."""
    import subprocess

    subprocess.run([sys.executable, __file__, "--child", str(n)]
                   + (["--json", json_dir] if json_dir else []), check=True)
    peak = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss / 1024
    print(f"  peak RSS of the child process: {peak:.0f} MB")


def threads(n: int) -> None:
    import contextlib

    import threadpoolctl

    model = volerr.load("MB1")
    camp = simulate("MB1", n_points=n, seed=7, probes=demo_probes(model), rounds=2,
                    effects=[{"kind": "thermal", "axis": "Y", "ppm_per_K": 6.0}])
    camp.covariates = {c: v for c, v in camp.covariates.items() if c in KEEP}
    data = columns_to_data(camp.columns(), model)
    shipped = threadpoolctl.threadpool_limits
    for mode in ("default threads", "one thread"):
        threadpoolctl.threadpool_limits = (shipped if mode == "one thread" else
                                           lambda **k: contextlib.nullcontext())
        t0, c0 = time.perf_counter(), time.process_time()
        run_loop("MB1", data, progress=False)
        print(f"{mode}: wall {time.perf_counter() - t0:.2f} s, "
              f"CPU {time.process_time() - c0:.2f} s")
    threadpoolctl.threadpool_limits = shipped


def drift(n: int) -> None:
    import tempfile
    from pathlib import Path

    from volerr.loop.drift.run import loop_drift
    from volerr.machine.lags import lag

    rng = np.random.default_rng(5)
    t = 5.0 * np.arange(n)
    edges = np.cumsum(rng.uniform(1800, 4 * 3600, size=n // 300 + 2))
    speeds = rng.choice([0, 0, 1000, 2000, 3000, 4000, 5000], size=len(edges))
    S = speeds[np.searchsorted(edges, t)].astype(float)
    q = (S / 5000.0) ** 1.5
    room = 20 + 1.5 * np.sin(2 * np.pi * t / 86400) + 0.3 * np.sin(2 * np.pi * t / 3600)
    cols = {"t_s": t, "S_rpm": S}
    for i in range(24):
        tau = 300.0 * 1.25 ** i
        cols[f"T_{i + 1}"] = (lag(room, 600.0 + 100 * i, t) + (8 - i / 4) * lag(q, tau, t)
                              + rng.normal(0, 0.01, n))
    cols["d_a_um"] = 20 * lag(q, 2400.0, t) - 10 * lag(q, 20000.0, t) + rng.normal(0, 0.2, n)
    cols["d_b_um"] = 3.0 * lag(cols["T_5"], 1500.0, t) + rng.normal(0, 0.2, n)
    with tempfile.TemporaryDirectory() as tmp:
        path = Path(tmp) / "drift.csv"
        names = list(cols)
        M = np.column_stack([cols[k] for k in names])
        np.savetxt(path, M, delimiter=",", header=",".join(names), comments="", fmt="%.6f")
        c0, w0 = time.process_time(), time.perf_counter()
        rep = loop_drift("MB1", [path], window=f"{0.75 * t[-1]:.0f}s:")
        cpu, wall = time.process_time() - c0, time.perf_counter() - w0
    print(f"drift loop: {n} readings x 24 sensors x 2 channels: {cpu:.1f} s CPU, {wall:.1f} s "
          f"wall (asked: under 60 s)")
    for k, c in rep["channels"].items():
        terms = [t["basis"] for e in rep["effects"] if e["channel"] == k for t in e["terms"]]
        print(f"  {k}: held-out MAE {c['mae_before_um']:.2f} -> {c['mae_after_um']:.3f} um; "
              f"{'; '.join(terms)}")


if __name__ == "__main__":
    if {"-h", "--help"} & set(sys.argv[1:]):     # the usage is the docstring
        sys.exit(print(__doc__))
    if sys.argv[1:2] == ["--drift"]:
        drift(int(sys.argv[2]) if len(sys.argv) > 2 else 100000)
        sys.exit()
    if sys.argv[1:2] == ["--threads"]:
        threads(int(sys.argv[2]) if len(sys.argv) > 2 else 30000)
        sys.exit()
    if sys.argv[1:2] == ["--lags"]:
        lags(int(sys.argv[2]) if len(sys.argv) > 2 else 100000)
        sys.exit()
    if sys.argv[1:2] == ["--child"]:
        one(int(sys.argv[2]), sys.argv[4] if sys.argv[3:4] == ["--json"] else None)
        sys.exit()
    args, out = sys.argv[1:], None
    if args[:1] == ["--json"]:
        out, args = args[1], args[2:]
    for arg in (args or ["10000", "100000"]):
        child(int(arg), out)
