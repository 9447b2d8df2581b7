"""CPU (``time.process_time``, s) of one FL_THERMAL window of the drift loop in-process (one
BLAS thread, as tests/helpers/fl_runs.py runs it), JSON and predictions CSV written into a
temporary folder.

    python benchmarks/speed_drift/fl_window_cpu.py [WINDOW]     (default 40-60)

Run from the repository root; a tree: PYTHONPATH at a folder holding ``volerr`` -> that
tree's runtime/.
"""
import contextlib
import io
import sys
import tempfile
import time

import threadpoolctl

sys.path.insert(0, "tests")
threadpoolctl.threadpool_limits(1)
from helpers import fl_runs  # noqa: E402

from volerr.cli import main  # noqa: E402

name = sys.argv[1] if len(sys.argv) > 1 else "40-60"
with tempfile.TemporaryDirectory() as d:
    c0 = time.process_time()
    with contextlib.chdir(d), contextlib.redirect_stdout(io.StringIO()):
        main(["loop", "DMU50", f"drift:{fl_runs.data()}", "--holdout-time",
              fl_runs.WINDOWS[name][0], "--json", "w.json", "--predictions-out", "p.csv"])
    print(f"window {name} cpu {time.process_time() - c0:.2f} s")
