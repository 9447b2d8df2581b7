"""Benchmark: `volerr compensate DMU50` on a long five-axis program, streamed in chunks.

Reports, for N blocks and N/10 blocks: the whole command (parse, interpret, solve, round,
predict, write) in a subprocess, wall and CPU time and peak RSS (resource.getrusage), with the
whole-chunk text path (default) and with every line interpreted and written one by one
(``program.WHOLE_CHUNK = False``, the previous implementation's text handling; same output,
checked), interleaved, min of the runs.  The line-by-line path runs at N/10 only unless
``--baseline-full`` (it takes ~100 s per 10^6 blocks).  Also: the vectorised solve alone on
the same positions and the solve block by block (a per-line script).

With ``--base REV`` the whole command of commit REV (exported with ``git archive``, run
through ``PYTHONPATH``) runs on the N-block program too, interleaved, output compared.

Run: python benchmarks/bench_compensate.py [N_BLOCKS] [--runs R] [--baseline-full] [--base REV]
     (default 1000000 blocks, 2 runs)
"""

import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

import volerr
from _baseline import env_for, export, which_volerr
from volerr.fiveaxis.compensate import ErrorModel, solve
from volerr.tables import table as tables
from volerr.tables.table import ErrorTable, write_constants, write_error_table

RUN = """
import resource, sys, time
from volerr.cli import main
from volerr.fiveaxis import program
program.WHOLE_CHUNK = sys.argv[4] == "1"
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


def command(prog, errors, out, whole=True, pythonpath=None):
    r = subprocess.run([sys.executable, "-c", RUN, str(prog), str(errors), str(out),
                        "1" if whole else "0"], capture_output=True, text=True, check=True,
                       env=env_for(pythonpath))
    wall, cpu, rss = map(float, r.stdout.split()[-3:])
    return wall, cpu, rss


def main(n: int = 1000000, runs: int = 2, baseline_full: bool = False, base=None) -> None:
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
        res = {key: [] for key in ("big", "small", "big_line", "small_line", "solve", "base")}
        pkg = export(base, d / "base") if base else None
        if pkg is not None:
            assert which_volerr(pkg).startswith(str(pkg)), "baseline import not taken"
        for _ in range(runs):   # interleaved, min of the runs
            res["big"].append(command(big, d, d / "out.nc"))
            if pkg is not None:
                res["base"].append(command(big, d, d / "out_base.nc", pythonpath=pkg))
                assert (d / "out.nc").read_bytes() == (d / "out_base.nc").read_bytes()
            res["small"].append(command(small, d, d / "out_s.nc"))
            res["small_line"].append(command(small, d, d / "ref_s.nc", whole=False))
            assert (d / "out_s.nc").read_bytes() == (d / "ref_s.nc").read_bytes()
            if baseline_full:
                res["big_line"].append(command(big, d, d / "ref.nc", whole=False))
                assert (d / "out.nc").read_bytes() == (d / "ref.nc").read_bytes()
            t0 = time.perf_counter()
            for i in range(0, n, 20000):
                solve(em, q[i:i + 20000])
            res["solve"].append(time.perf_counter() - t0)
        t0 = time.perf_counter()
        for row in q[:k]:
            solve(em, row[None, :])
        t_loop = (time.perf_counter() - t0) * n / k
        t_vec = min(res["solve"])
        best = {key: tuple(min(r[i] for r in v) for i in range(3))
                for key, v in res.items() if v and key not in ("solve", "base")}
        print(f"DMU50, full strategy, min of {runs} interleaved runs "
              f"(wall s, CPU s, peak RSS MB)")
        for key, nb in (("big", n), ("small", n // 10)):
            w, c, r = best[key]
            line = f"  {nb:>8} blocks: whole-chunk {w:.1f} s wall, {c:.1f} s CPU, {r:.0f} MB"
            if key + "_line" in best:
                lw, lc, lr = best[key + "_line"]
                line += (f"; line by line {lw:.1f} s wall, {lc:.1f} s CPU, {lr:.0f} MB; "
                         f"ratio {lw / w:.1f}x wall, {lc / c:.1f}x CPU")
            print(line)
        w = best["big"][0]
        if res["base"]:
            bw, bc, br = (min(r[i] for r in res["base"]) for i in range(3))
            print(f"  {n:>8} blocks, commit {base}: {bw:.1f} s wall, {bc:.1f} s CPU, {br:.0f} MB; "
                  f"ratio {bw / w:.2f}x wall, {bc / best['big'][1]:.2f}x CPU; output identical")
        print(f"  solve alone (chunks of 20000): {t_vec:.2f} s; whole command / solve "
              f"{w / t_vec:.1f}x; block by block (extrapolated from {k}): {t_loop:.0f} s, "
              f"{t_loop / w:.0f}x the whole command")


if __name__ == "__main__":
    import argparse

    ap = argparse.ArgumentParser()
    ap.add_argument("n", nargs="?", type=int, default=1000000)
    ap.add_argument("--runs", type=int, default=2)
    ap.add_argument("--baseline-full", action="store_true")
    ap.add_argument("--base", default=None, help="also run this commit's command (e.g. b32e5c7)")
    a = ap.parse_args()
    main(a.n, a.runs, a.baseline_full, a.base)
