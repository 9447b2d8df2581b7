"""Record what :mod:`volerr.loop.drift.tau_range` computes, to compare two trees' profiles.

    python benchmarks/speed_drift/tau_range_probe.py OUT [fl] [fl60] [bench]

Runs ``volerr loop DMU50 drift:FILE --holdout-time W`` in-process (one BLAS thread) on the six
FL_THERMAL windows of tests/helpers/fl_runs.py WINDOWS at 15 s (``fl``) and at 60 s (every 4th
reading, ``fl60``), and ``benchmarks/bench_loop.py --drift`` (``bench``), and pickles into
OUT/NAME.pkl, per call in order: every coordinate pass's RSS array (``tau_range._rss``),
every interval's (x, rss, threshold, [lo, hi]) (``tau_range._interval``) and every
``ranges`` result (unrounded s).  Compare with tau_range_compare.py.  Run from the repository
root (a tree: PYTHONPATH at a folder holding ``volerr`` -> that tree's runtime/).
"""
import contextlib
import io
import pickle
import sys
import tempfile
from pathlib import Path

import numpy as np
import threadpoolctl

sys.path.insert(0, "tests")
sys.path.insert(0, "benchmarks")
threadpoolctl.threadpool_limits(1)
from helpers import fl_runs  # noqa: E402

from volerr.cli import main  # noqa: E402
from volerr.loop.drift import tau_range as T  # noqa: E402

out = Path(sys.argv[1])
out.mkdir(parents=True, exist_ok=True)
rec = []
_rss, _interval, _ranges = T._rss, T._interval, T.ranges


def rss(*a):
    r = _rss(*a)
    rec.append(("pass", np.array(r, float)))
    return r


def interval(x, r, thr):
    v = _interval(x, r, thr)
    rec.append(("interval", (np.array(x), np.array(r), float(thr), list(v))))
    return v


def ranges(*a):
    v = _ranges(*a)
    rec.append(("ranges", list(v)))
    return v


T._rss, T._interval = rss, interval
from volerr.loop.drift import fit  # noqa: E402
fit.tau_range.ranges = ranges


def window(name, step):
    w, cut = fl_runs.WINDOWS[name]
    with tempfile.TemporaryDirectory() as d:
        path = fl_runs.data() if (step == 1 and cut is None) else Path(d) / "fl.csv"
        if not (step == 1 and cut is None):
            path.write_text(fl_runs.file_text(step, cut))
        with contextlib.chdir(d), contextlib.redirect_stdout(io.StringIO()):
            main(["loop", "DMU50", f"drift:{path}", "--holdout-time", w, "--json", "w.json"])


for which in sys.argv[2:]:
    if which in ("fl", "fl60"):
        for name in fl_runs.WINDOWS:
            rec.clear()
            window(name, 1 if which == "fl" else 4)
            pickle.dump(list(rec), open(out / f"{which}_{name}.pkl", "wb"))
            print(which, name, len(rec), flush=True)
    elif which == "bench":
        import bench_loop
        rec.clear()
        with contextlib.redirect_stdout(io.StringIO()):
            bench_loop.drift(100000)
        pickle.dump(list(rec), open(out / "bench.pkl", "wb"))
        print("bench", len(rec), flush=True)
