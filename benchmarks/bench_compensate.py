"""Benchmark: `volerr compensate DMU50` on a long five-axis program, streamed in chunks, for
each shape of program post-processors write.

Shapes (the same positions in every one): ``bare`` (``X.. Y.. Z.. B.. C..``), ``g1`` (``G1`` on
every line), ``post`` (``N.. G01 X.. Y.. Z.. B.. C.. F1500. S12000 M8 (cut) ; fin`` with CRLF),
``lower`` (``g1 x 1.0 y 2.0 ...``: lower case, blanks between letter and number), ``tools``
(``G0``/``G1`` alternating, ``T`` and ``M`` words, comments between the words), and TCPM
tool-vector programs as post-processors write them (the tool tip and the unit tool vector of
the same positions, tool length 120 mm; the program starts ``G90 G21 G17``, ``T1 M6`` and the
TCPM block, no rotary word before it): ``vector`` (Fanuc ``G43.5``: ``G1 X.. Y.. Z.. I.. J..
K.. F2000``, no comment), ``vector_n`` (``N.. G01 X.. Y.. Z.. I.. J.. K.. F2000.`` with CRLF),
``vector_cut`` (``N.. G01 ... F1500. (cut)`` with CRLF: a comment on every line) and
``traori`` (Siemens ``TRAORI``: ``N.. G01 X.. Y.. Z.. A3=.. B3=.. C3=.. F2000``).  The aim for
the TCPM shapes (issues 31 item 5, 36 item 6): under 10 s per 10^6 blocks on the 2-core CI
machine, in every shape.

Reports, for N blocks of each shape: the whole command (parse, interpret, solve, round,
predict, write) in a subprocess, wall and CPU time and peak RSS (resource.getrusage), and the
ratio to the bare shape; interleaved, min of the runs.  At N/10 blocks the whole-chunk text
path is checked byte for byte against every line interpreted and written one by one
(``program.WHOLE_CHUNK = False``, the reference) and timed against it (``--baseline-full``: also
at N; it takes ~100 s per 10^6 blocks).  Also: the vectorised solve alone on the same
positions and the solve block by block (a per-line script).

With ``--base REV`` the whole command of commit REV (exported with ``git archive``, run
through ``PYTHONPATH``) runs on the N-block program of every shape too, interleaved, output
compared byte for byte; the table gives before (REV), after (this tree) and their ratio.

Run: python benchmarks/bench_compensate.py [N_BLOCKS] [--runs R] [--shapes bare,post,...]
     [--baseline-full] [--base REV]     (default 1000000 blocks, 2 runs, every shape)
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
from volerr.tables.functions import ErrorFunctions
from volerr.tables.table import ErrorTable, write_constants, write_error_table

RUN = """
import resource, sys, time
from volerr.cli import main
from volerr.fiveaxis import program
program.WHOLE_CHUNK = sys.argv[4] == "1"
t0 = time.perf_counter(); c0 = time.process_time()
# the tool length only for the TCPM shapes: on axis-position programs --tool-length moves the
# evaluated point to the tool tip (a different, not a slower, compensation than a base before it)
head = open(sys.argv[1], encoding="latin-1").read(300)
tool = ["--tool-length", "120"] if ("G43.5" in head or "TRAORI" in head) else []
rc = main(["compensate", "DMU50", sys.argv[1], "--errors", sys.argv[2], "--out", sys.argv[3],
           *tool])
print(time.perf_counter() - t0, time.process_time() - c0,
      resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0)
"""


SHAPES = {
    "bare": lambda k, r: "X%.3f Y%.3f Z%.3f B%.3f C%.3f\n" % r,
    "g1": lambda k, r: "G1 X%.3f Y%.3f Z%.3f B%.3f C%.3f\n" % r,
    "post": lambda k, r: ("N%d G01 X%.3f Y%.3f Z%.3f B%.3f C%.3f F1500. S12000 M8 (cut) ; fin"
                          "\r\n" % ((k,) + r)),
    "lower": lambda k, r: "g1 x %.3f y %.3f z %.3f b %.3f c %.3f\n" % r,
    "tools": lambda k, r: ("G%d X%.3f (a) Y%.3f Z%.3f B%.3f C%.3f T%d M%d ;x\n"
                           % ((k % 2,) + r + (k % 7, 8 + k % 2))),
    # TCPM: r is (tip x y z, tool vector i j k) here
    "vector": lambda k, r: "G1 X%.4f Y%.4f Z%.4f I%.6f J%.6f K%.6f F2000\n" % r,
    "vector_n": lambda k, r: "N%d G01 X%.4f Y%.4f Z%.4f I%.6f J%.6f K%.6f F2000.\r\n"
                             % ((k,) + r),
    "vector_cut": lambda k, r: "N%d G01 X%.4f Y%.4f Z%.4f I%.6f J%.6f K%.6f F1500. (cut)\r\n"
                               % ((k,) + r),
    "traori": lambda k, r: "N%d G01 X%.4f Y%.4f Z%.4f A3=%.6f B3=%.6f C3=%.6f F2000\n"
                           % ((k,) + r),
}
#: the first lines of a TCPM program: absolute, mm, tool 1, TCPM on (no rotary word before)
TCPM_HEAD = {"vector": "G90 G21 G17\nT1 M6\nG43.5 H1\n",
             "vector_n": "N1 G90 G21 G17\r\nN2 T1 M6\r\nN3 G43.5 H1\r\n",
             "vector_cut": "N1 G90 G21 G17\r\nN2 T1 M6\r\nN3 G43.5 H1\r\n",
             "traori": "N1 G90 G17\nN2 T1 M6\nN3 TRAORI\n"}


def write_program(path: Path, n: int, rng, shape: str = "bare") -> np.ndarray:
    q = np.column_stack([rng.uniform(-240, 240, n), rng.uniform(-220, 220, n),
                         rng.uniform(10, 390, n), rng.uniform(1, 179, n), rng.uniform(0, 359, n)])
    line = SHAPES[shape]
    rows = q
    if shape in TCPM_HEAD:      # the same positions as tool tip and tool vector
        q[:, 2] = rng.uniform(150, 390, n)
        q[:, 3] = rng.uniform(1, 90, n)
        rows = volerr.load("DMU50").forward(q, np.tile([0.0, 0.0, -120.0], (n, 1)))
    with open(path, "w", encoding="latin-1", newline="") as fh:
        fh.write(TCPM_HEAD.get(shape, "G90 G1 X0 Y0 Z100 B10 C0\n"))
        for i in range(0, n, 100000):
            fh.write("".join(line(i + k, tuple(r)) for k, r in enumerate(rows[i:i + 100000])))
    return np.round(q, 3)


def command(prog, errors, out, whole=True, pythonpath=None):
    r = subprocess.run([sys.executable, "-c", RUN, str(prog), str(errors), str(out),
                        "1" if whole else "0"], capture_output=True, text=True, check=True,
                       env=env_for(pythonpath))
    wall, cpu, rss = map(float, r.stdout.split()[-3:])
    return wall, cpu, rss


def main(n: int = 1000000, runs: int = 2, baseline_full: bool = False, base=None,
         shapes=tuple(SHAPES)) -> None:
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
        funcs = ErrorFunctions.from_dir(d, m)
        q = None
        for sh in shapes:
            q = write_program(d / f"big_{sh}.nc", n, np.random.default_rng(1), sh)
            write_program(d / f"small_{sh}.nc", max(n // 10, 1), np.random.default_rng(2), sh)
        em = ErrorModel(m, funcs)
        k = min(300, n)
        res = {key: [] for key in ["solve"] + [f"{sh}{x}" for sh in shapes
                                               for x in ("", "_small", "_line", "_big_line",
                                                         "_base", "_pair")]}
        pkg = export(base, d / "base") if base else None
        if pkg is not None:
            assert which_volerr(pkg).startswith(str(pkg)), "baseline import not taken"
        for _ in range(runs):   # interleaved, min of the runs
            for sh in shapes:
                res[sh].append(command(d / f"big_{sh}.nc", d, d / "out.nc"))
                res[f"{sh}_small"].append(command(d / f"small_{sh}.nc", d, d / "out_s.nc"))
                res[f"{sh}_line"].append(command(d / f"small_{sh}.nc", d, d / "ref_s.nc",
                                                 whole=False))
                assert (d / "out_s.nc").read_bytes() == (d / "ref_s.nc").read_bytes(), sh
                if baseline_full:
                    res[f"{sh}_big_line"].append(command(d / f"big_{sh}.nc", d, d / "ref.nc",
                                                         whole=False))
                    assert (d / "out.nc").read_bytes() == (d / "ref.nc").read_bytes(), sh
            for sh in shapes if pkg is not None else ():     # interleaved pairs
                res[f"{sh}_pair"].append(command(d / f"big_{sh}.nc", d, d / "out.nc"))
                res[f"{sh}_base"].append(command(d / f"big_{sh}.nc", d, d / "out_base.nc",
                                                 pythonpath=pkg))
                assert (d / "out.nc").read_bytes() == (d / "out_base.nc").read_bytes(), sh
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
                for key, v in res.items() if v and key != "solve"}
        print(f"DMU50, full strategy, min of {runs} interleaved runs "
              f"(wall s, CPU s, peak RSS MB; ratio to the bare shape)")
        ref = best.get("bare")
        for sh in shapes:
            w, c, r = best[sh]
            ratio = f", {w / ref[0]:.2f}x / {c / ref[1]:.2f}x bare" if ref else ""
            print(f"  {sh:>6} {n:>8} blocks: {w:.1f} s wall, {c:.1f} s CPU, {r:.0f} MB{ratio}")
            sw, sc, _ = best[f"{sh}_small"]
            lw, lc, lr = best[f"{sh}_line"]
            line = (f"  {sh:>6} {n // 10:>8} blocks: whole-chunk {sw:.1f} s wall; line by line "
                    f"{lw:.1f} s wall, {lc:.1f} s CPU, {lr:.0f} MB; ratio {lw / sw:.1f}x wall; "
                    "output identical")
            if f"{sh}_big_line" in best:
                bw = best[f"{sh}_big_line"][0]
                line += f"; at {n}: line by line {bw:.1f} s ({bw / w:.1f}x)"
            print(line)
        if pkg is not None:
            print(f"  {n} blocks, commit {base} (before) and this tree (after), interleaved "
                  "pairs, output identical; shape, before, after (CPU s), ratio after / before:")
            for sh in shapes:
                bc, c = best[f"{sh}_base"][1], best[f"{sh}_pair"][1]
                print(f"  {sh:>6} {bc:8.1f} {c:8.1f} {c / bc:6.2f}x")
        print(f"  solve alone (chunks of 20000): {t_vec:.2f} s; block by block (extrapolated "
              f"from {k}): {t_loop:.0f} s")


if __name__ == "__main__":
    import argparse

    ap = argparse.ArgumentParser()
    ap.add_argument("n", nargs="?", type=int, default=1000000)
    ap.add_argument("--runs", type=int, default=2)
    ap.add_argument("--baseline-full", action="store_true")
    ap.add_argument("--base", default=None, help="also run this commit's command (e.g. b32e5c7)")
    ap.add_argument("--shapes", default=",".join(SHAPES),
                    help=f"program shapes, comma separated ({', '.join(SHAPES)})")
    a = ap.parse_args()
    main(a.n, a.runs, a.baseline_full, a.base, tuple(a.shapes.split(",")))
