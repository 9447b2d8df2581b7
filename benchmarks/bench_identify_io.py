"""Benchmark: reading a laser-tracker CSV of 10^5 positions x 3 points (3 x 10^5 rows).

``read_tracker_csv`` parses a well-formed file column-wise (numpy converts the numbers, checks
run on whole columns); the baseline, run in the same process on the same rows, is the
row-by-row reader (a check and its message per line) that still reports a faulty file.
Both include the grouping into rounds; CSV tokenising (``read_csv_rows``) is timed apart.
The total is ``read_tracker_csv``, which tokenises a plain file with ``numpy.loadtxt``.
Run: ``python benchmarks/bench_identify_io.py [n_positions]``.
"""

import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from volerr.identify import tracker_io as tio


def main(n=100_000):
    rng = np.random.default_rng(0)
    with tempfile.TemporaryDirectory() as d:
        path = Path(d) / "track.csv"
        pos = np.linspace(0, 500, n)
        lines = ["round,point,position,x,y,z"]
        for p in pos:
            for lab, base in zip("KPQ", ([60, 10, -150], [-40, 50, -100], [10, -60, -200])):
                x, y, z = np.add(base, [p, 0, 0]) + rng.normal(size=3) * 1e-3
                lines.append(f"1,{lab},{p:.6f},{x:.6f},{y:.6f},{z:.6f}")
        path.write_text("\n".join(lines) + "\n")
        t_tok = {"tokenise": np.inf, "fast": np.inf, "row": np.inf, "total": np.inf}
        for _ in range(3):  # interleaved, best of 3, CPU time
            t = time.process_time()
            rows = tio._open_rows(path)
            t_tok["tokenise"] = min(t_tok["tokenise"], time.process_time() - t)
            idx = tio._header_index(path, rows[0][1])
            t = time.process_time()
            fast = tio._read_regular(path, rows[1:], idx)
            t_tok["fast"] = min(t_tok["fast"], time.process_time() - t)
            t = time.process_time()
            slow = tio._read_by_row(path, rows[1:], idx)
            t_tok["row"] = min(t_tok["row"], time.process_time() - t)
            t = time.process_time()
            now = tio.read_tracker_csv(path)
            t_tok["total"] = min(t_tok["total"], time.process_time() - t)
        assert np.array_equal(fast[0].points, slow[0].points)
        assert np.array_equal(now[0].points, slow[0].points) and now[0].labels == slow[0].labels
        assert np.array_equal(fast[0].positions, slow[0].positions)
        print(f"tracker CSV, {n:,} positions x 3 points (best of 3, CPU s)")
        print(f"  tokenise (csv module)   {t_tok['tokenise']:7.3f}")
        print(f"  column-wise parse       {t_tok['fast']:7.3f}   row-by-row / column-wise = "
              f"{t_tok['row'] / t_tok['fast']:5.1f}x")
        print(f"  row-by-row (baseline)   {t_tok['row']:7.3f}")
        prev = t_tok["tokenise"] + t_tok["fast"]
        print(f"  csv module + column-wise (previous path) {prev:7.3f}")
        print(f"  read_tracker_csv total (numpy.loadtxt path) {t_tok['total']:7.3f}   "
              f"previous / now = {prev / t_tok['total']:4.1f}x")


if __name__ == "__main__":
    if {"-h", "--help"} & set(sys.argv[1:]):     # the usage is the docstring
        sys.exit(print(__doc__))
    main(int(sys.argv[1]) if len(sys.argv) > 1 else 100_000)
