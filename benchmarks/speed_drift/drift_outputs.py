"""Write the drift loop's outputs, to prove a speedup leaves them byte-identical.

    python benchmarks/speed_drift/drift_outputs.py OUT [fl] [bench]

``fl``: ``volerr loop DMU50 drift:FILE --holdout-time W --json w.json --predictions-out
p.csv`` in-process (``volerr.cli.main``, one BLAS thread, as tests/helpers/fl_runs.py runs it)
on the six FL_THERMAL windows at 15 s of tests/helpers/fl_runs.py WINDOWS, into OUT/NAME/
(w.json, p.csv, stdout.txt).  ``bench``: ``benchmarks/bench_loop.py --drift`` (10^5
readings), its report's JSON and predictions CSV into OUT/bench.json, OUT/bench_p.csv.
Compare two trees with ``cmp`` file by file (run one tree with PYTHONPATH pointing at a
folder holding ``volerr`` -> that tree's runtime/).  Run from the repository root.
"""
import contextlib
import io
import sys
import time
from pathlib import Path

sys.path.insert(0, "tests")
out = Path(sys.argv[1])
out.mkdir(parents=True, exist_ok=True)
which = sys.argv[2:] or ["fl", "bench"]
import threadpoolctl  # noqa: E402

threadpoolctl.threadpool_limits(1)
from helpers import fl_runs  # noqa: E402

from volerr.cli import main  # noqa: E402

if "fl" in which:
    for name, (window, cut) in fl_runs.WINDOWS.items():
        f = out / name
        f.mkdir(exist_ok=True)
        path = fl_runs.data() if cut is None else f / "fl_1.csv"
        if cut is not None:
            path.write_text(fl_runs.file_text(1, cut))
        c0 = time.process_time()
        so = io.StringIO()
        with contextlib.chdir(f), contextlib.redirect_stdout(so):
            rc = main(["loop", "DMU50", f"drift:{path}", "--holdout-time", window, "--json",
                       "w.json", "--predictions-out", "p.csv"])
        (f / "stdout.txt").write_text(so.getvalue())
        print(name, rc, f"{time.process_time() - c0:.2f} s CPU", flush=True)
if "bench" in which:
    sys.path.insert(0, "benchmarks")
    import bench_loop

    from volerr.loop.drift import run as drun
    orig = drun.loop_drift

    def wrapped(*a, **k):
        rep = orig(*a, **k)
        rep.write_json(str(out / "bench.json"))
        rep.write_predictions(str(out / "bench_p.csv"))
        return rep
    drun.loop_drift = wrapped
    bench_loop.drift(100000)
