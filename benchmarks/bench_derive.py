"""Benchmark: `volerr derive --all --out DIR` (14 layouts + the three-point and probe modules),
this tree against a baseline commit run the same way, interleaved, min of the runs.

The baseline's source is exported with ``git archive`` into a temporary package tree and run
with ``PYTHONPATH`` pointing at it (same interpreter and sympy).  Reports CPU (user + sys of
the child) and wall time, and checks that both produce the same files, equal except for the
source-hash lines of the headers (the derivation sources differ, the generated code must not).

The CPU time is what counts on this shared 2-core machine (another process may hold a core):
the derivation is single-threaded, so wall time follows CPU time only on an idle machine.

Run: python benchmarks/bench_derive.py [--base REV] [--runs R]   (default b32e5c7, 3 runs)
"""

import argparse
import re
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from _baseline import BASE, ROOT, env_for, export, which_volerr

HASH = re.compile(r"^(derivation|input) sha256 .*$", re.M)


def run(out: Path, pythonpath=None):
    env = env_for(pythonpath)
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    subprocess.run([sys.executable, "-m", "volerr", "derive", "--all", "--out", str(out)],
                   check=True, capture_output=True, env=env, cwd=tempfile.gettempdir())
    wall = time.perf_counter() - t0
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    return wall, cpu


def texts(d: Path) -> dict:
    return {p.name: HASH.sub("", p.read_text()) for p in sorted(d.glob("*.py"))}


def main(base: str = BASE, runs: int = 3) -> None:
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        pkg = export(base, tmp / "base")
        assert which_volerr(pkg).startswith(str(pkg)), "baseline package not imported"
        assert which_volerr().startswith(str(ROOT)), "this tree's package not imported"
        res = {"base": [], "this": []}
        for r in range(runs):
            res["base"].append(run(tmp / f"b{r}", pkg))
            res["this"].append(run(tmp / f"t{r}"))
            print(f"  run {r + 1}: baseline {res['base'][-1][1]:.1f} s CPU, this tree "
                  f"{res['this'][-1][1]:.1f} s CPU", flush=True)
        same = texts(tmp / "b0") == texts(tmp / "t0")
        bw, bc = (min(x[i] for x in res["base"]) for i in range(2))
        tw, tc = (min(x[i] for x in res["this"]) for i in range(2))
        print(f"volerr derive --all, min of {runs} interleaved runs")
        print(f"  baseline {base}: {bc:.1f} s CPU, {bw:.1f} s wall")
        print(f"  this tree: {tc:.1f} s CPU, {tw:.1f} s wall; ratio {bc / tc:.2f}x CPU, "
              f"{bw / tw:.2f}x wall")
        print(f"  generated files equal apart from the source hashes: {same}")


if __name__ == "__main__":
    ap = argparse.ArgumentParser()
    ap.add_argument("--base", default=BASE)
    ap.add_argument("--runs", type=int, default=3)
    a = ap.parse_args()
    main(a.base, a.runs)
