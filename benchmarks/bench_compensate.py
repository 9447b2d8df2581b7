"""Benchmark: `volerr compensate DMU50` on a long five-axis program, streamed in chunks.

Reports, for N blocks: the whole command (parse, interpret, solve, round, predict, write) in a
subprocess with its peak RSS (resource.getrusage), the vectorised solve alone on the same
positions (ratio whole / solve: what the text handling costs on top of the numerics) and the
solve block by block (the baseline a per-line script would be).  Peak RSS is also measured for
N/10 blocks: streaming keeps it independent of the program length.

Run: python benchmarks/bench_compensate.py [N_BLOCKS]   (default 200000)
"""

import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

import volerr
from volerr.fiveaxis.compensate import ErrorModel, solve
from volerr.tables import table as tables
from volerr.tables.table import ErrorTable, write_constants, write_error_table

RUN = """
import resource, sys, time
from volerr.cli import main
t0 = time.perf_counter(); c0 = time.process_time()
rc = main(["compensate", "DMU50", sys.argv[1], "--errors", sys.argv[2], "--out", sys.argv[3]])
print(time.perf_counter() - t0, time.process_time() - c0,
      resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0)
"""


def write_program(path: Path, n: int, rng) -> np.ndarray:
    q = np.column_stack([rng.uniform(-240, 240, n), rng.uniform(-220, 220, n),
                         rng.uniform(10, 390, n), rng.uniform(1, 179, n), rng.uniform(0, 359, n)])
    with open(path, "w", encoding="latin-1", newline="") as fh:
        fh.write("G90 G1 X0 Y0 Z100 B10 C0\n")
        for i in range(0, n, 100000):
            fh.write("".join("X%.3f Y%.3f Z%.3f B%.3f C%.3f\n" % tuple(r) for r in q[i:i + 100000]))
    return np.round(q, 3)


def command(prog, errors, out):
    r = subprocess.run([sys.executable, "-c", RUN, str(prog), str(errors), str(out)],
                       capture_output=True, text=True, check=True)
    wall, cpu, rss = map(float, r.stdout.split()[-3:])
    return wall, cpu, rss


def main(n: int = 200000) -> None:
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
        big, small = d / "big.nc", d / "small.nc"
        q = write_program(big, n, rng)
        write_program(small, max(n // 10, 1), rng)
        em = ErrorModel(m, funcs)
        k = min(300, n)
        runs = []
        for _ in range(2):   # interleaved, min of the runs
            runs.append((command(big, d, d / "out.nc"), command(small, d, d / "out_s.nc")))
            t0 = time.perf_counter()
            for i in range(0, n, 20000):
                solve(em, q[i:i + 20000])
            t_vec = time.perf_counter() - t0
            runs[-1] += (t_vec,)
        wall = min(r[0][0] for r in runs)
        cpu = min(r[0][1] for r in runs)
        rss, rss_s = min(r[0][2] for r in runs), min(r[1][2] for r in runs)
        t_vec = min(r[2] for r in runs)
        t0 = time.perf_counter()
        for row in q[:k]:
            solve(em, row[None, :])
        t_loop = (time.perf_counter() - t0) * n / k
        print(f"DMU50, {n} motion blocks, full strategy (min of {len(runs)} interleaved runs)")
        print(f"  volerr compensate: {wall:.1f} s wall, {cpu:.1f} s CPU "
              f"({n / wall:.0f} blocks/s); peak RSS {rss:.0f} MB ({rss_s:.0f} MB at {n // 10} "
              "blocks)")
        print(f"  solve alone (chunks of 20000): {t_vec:.2f} s; whole command / solve "
              f"{wall / t_vec:.1f}x; block by block (extrapolated from {k}): {t_loop:.0f} s, "
              f"{t_loop / wall:.0f}x the whole command")


if __name__ == "__main__":
    main(int(sys.argv[1]) if len(sys.argv) > 1 else 200000)
