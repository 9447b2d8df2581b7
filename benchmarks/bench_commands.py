"""Benchmark: whole commands a user waits for, this tree against a baseline commit.

* ``volerr map MH2 --errors DIR --grid 100 --out map.csv``: 10^6 points with the random component, errors
  from ``volerr.cmm.examples.write_example_errors``;
* ``volerr identify MB1 track.csv --axis X --out X.csv``: a tracker CSV of 10^5 positions x 3
  points (3 x 10^5 rows).

Each command runs in a fresh process (``python -m volerr ...``), this tree and the baseline in
turn (A B A B ...), and the figures are the child's own accounting: CPU (user + sys), wall and
peak RSS; reported as min and median of the runs with the ratio baseline / this tree.  The
outputs of both are compared (the map CSV byte for byte, the identified table to 1e-9 um).

Run: python benchmarks/bench_commands.py [--base REV] [--runs R]   (default b32e5c7, 5 runs)
"""

import argparse
import resource
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from _baseline import BASE, env_for, export, which_volerr


def write_track(path: Path, n: int = 100_000) -> None:
    rng = np.random.default_rng(0)
    pos = np.linspace(0, 500, n)
    base = np.array([[60, 10, -150], [-40, 50, -100], [10, -60, -200]], float)
    pts = base[None] + np.stack([pos, 0 * pos, 0 * pos], 1)[:, None] \
        + rng.normal(size=(n, 3, 3)) * 1e-3
    rows = np.column_stack([np.repeat(pos, 3), pts.reshape(-1, 3)])
    labels = np.tile(np.array(["K", "P", "Q"]), n)
    with open(path, "w") as fh:
        fh.write("round,point,position,x,y,z\n")
        fh.write("".join("1,%s,%.6f,%.6f,%.6f,%.6f\n" % (lab, *r) for lab, r in zip(labels, rows)))


def run(args, pythonpath=None):
    """(CPU s, wall s, peak RSS MB) of one child process."""
    r0 = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    p = subprocess.run([sys.executable, "-c", "import resource, sys\n"
                        "from volerr.cli import main\n"
                        "rc = main(sys.argv[1:])\n"
                        "print(resource.getrusage(resource.RUSAGE_SELF).ru_maxrss)\n"
                        "sys.exit(rc)", *args],
                       capture_output=True, text=True, env=env_for(pythonpath))
    wall = time.perf_counter() - t0
    r1 = resource.getrusage(resource.RUSAGE_CHILDREN)
    if p.returncode:
        raise SystemExit(f"{' '.join(args)} failed: {p.stderr.strip()}")
    cpu = (r1.ru_utime - r0.ru_utime) + (r1.ru_stime - r0.ru_stime)
    return cpu, wall, int(p.stdout.split()[-1]) / 1024.0


def main(base: str = BASE, runs: int = 5) -> None:
    with tempfile.TemporaryDirectory() as tmp:
        d = Path(tmp)
        pkg = export(base, d / "base")
        assert which_volerr(pkg).startswith(str(pkg)), "baseline import not taken"
        from volerr.cmm.examples import write_example_errors
        write_example_errors(d / "err", "MH2")
        write_track(d / "track.csv")
        jobs = {
            "map MH2 --grid 100 --out (10^6 points)":
                lambda tag: ["map", "MH2", "--errors", str(d / "err"), "--grid", "100",
                             "--out", str(d / f"map_{tag}.csv")],
            "identify MB1, 10^5 positions x 3 points":
                lambda tag: ["identify", "MB1", str(d / "track.csv"), "--axis", "X",
                             "--out", str(d / f"id_{tag}" / "X.csv")],
        }
        print(f"this tree vs {base}: {runs} runs each, interleaved; CPU = user + sys of the "
              f"child; min / median")
        for title, make in jobs.items():
            res = {"new": [], "base": []}
            for i in range(runs):
                for tag, path in (("new", None), ("base", pkg)):
                    args = make(f"{tag}{i}")
                    res[tag].append(run(args, path))
            new, old = np.array(res["new"]), np.array(res["base"])
            med = {k: [statistics.median(v[:, j]) for j in range(3)] for k, v in
                   (("new", new), ("base", old))}
            print(f"  {title}")
            for k, v in (("this tree", new), (base, old)):
                key = "new" if k == "this tree" else "base"
                print(f"    {k:>10}: CPU {v[:, 0].min():.2f} / {med[key][0]:.2f} s, wall "
                      f"{v[:, 1].min():.2f} / {med[key][1]:.2f} s, peak RSS {med[key][2]:.0f} MB")
            print(f"    ratio {base} / this tree (medians): CPU {med['base'][0] / med['new'][0]:.2f} x,"
                  f" wall {med['base'][1] / med['new'][1]:.2f} x")
        same = (d / "map_new0.csv").read_bytes() == (d / "map_base0.csv").read_bytes()
        a = np.loadtxt(d / "id_new0" / "X.csv", delimiter=",", skiprows=1)
        b = np.loadtxt(d / "id_base0" / "X.csv", delimiter=",", skiprows=1)
        print(f"  map CSV byte-identical: {same}; identified table max difference "
              f"{np.max(np.abs(a - b)):.1e} (um / urad)")
        assert same and np.max(np.abs(a - b)) < 1e-9


if __name__ == "__main__":
    ap = argparse.ArgumentParser()
    ap.add_argument("--base", default=BASE)
    ap.add_argument("--runs", type=int, default=5)
    a = ap.parse_args()
    main(a.base, a.runs)
