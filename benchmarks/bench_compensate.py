"""Benchmark: compensation of a long five-axis program (DMU50), vectorised over all blocks vs
the same solve called block by block (the baseline a per-line script would be).

Run: python benchmarks/bench_compensate.py [N_BLOCKS]
"""

import sys
import tempfile
import time
from pathlib import Path

import numpy as np

import volerr
from volerr.tables import table as tables
from volerr.fiveaxis.compensate import ErrorModel, compensate_program, solve
from volerr.tables.table import ErrorTable, write_constants, write_error_table


def main(n: int = 20000) -> None:
    m = volerr.load("DMU50")
    rng = np.random.default_rng(0)
    with tempfile.TemporaryDirectory() as tmp:
        d = Path(tmp)
        for a in m.axes:
            lo, hi = (0.0, 360.0) if a == "C" else m.travel[a]
            x = np.linspace(lo, hi, 31)
            vals = {p: rng.normal(0, 30e-6 if p[1] in "ABC" else 10e-3)
                    * np.sin(np.linspace(0, 3, 31) + rng.uniform(0, 3))
                    for p in m.layout.axes[a].component_errors}
            write_error_table(d / f"{a}.csv", ErrorTable(a, x, vals))
        write_constants(d / "constants.csv", {"EC0Y": 20e-6, "EX0C": 0.01, "EA0B": 15e-6})
        funcs = tables.ErrorFunctions.from_dir(d, m)
        lines = ["G90 G1 X0 Y0 Z100 B10 C0"]
        for _ in range(n):
            lines.append("X%.3f Y%.3f Z%.3f B%.3f C%.3f" % (
                rng.uniform(-240, 240), rng.uniform(-220, 220), rng.uniform(10, 390),
                rng.uniform(1, 179), rng.uniform(0, 359)))
        text = "\n".join(lines) + "\n"
        t0 = time.perf_counter()
        res = compensate_program(m, funcs, text)
        t_prog = time.perf_counter() - t0
        s = res.summary()
        q = np.array([[float(v) for v in [r.nominal[a] for a in m.axes]] for r in res.reports])
        em = ErrorModel(m, funcs)
        t0 = time.perf_counter()
        solve(em, q)
        t_vec = time.perf_counter() - t0
        k = min(500, len(q))
        t0 = time.perf_counter()
        for row in q[:k]:
            solve(em, row[None, :])
        t_loop = (time.perf_counter() - t0) * len(q) / k
        print(f"DMU50, {n} motion blocks, full strategy")
        print(f"  whole program (parse, solve, round, write): {t_prog:.2f} s "
              f"({1e6 * t_prog / n:.0f} us per block)")
        print(f"  solve vectorised: {t_vec:.3f} s; block by block (extrapolated from {k}): "
              f"{t_loop:.1f} s; ratio {t_loop / t_vec:.0f}x")
        print(f"  predicted error max {s['max_before_um']:.2f} -> {s['max_after_um']:.4f} um, "
              f"iterations max {s['max_iterations']}")


if __name__ == "__main__":
    main(int(sys.argv[1]) if len(sys.argv) > 1 else 20000)
