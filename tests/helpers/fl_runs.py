"""``volerr loop`` on the FL_THERMAL spindle test, run once per process for every test file
that asks for the same run (issue 42 item 7: the suite's time).

tests/loop/test_drift_sampling.py (every window at 15 s and 60 s),
test_drift_generalisation.py (the five 20 % windows at 15 s) and test_drift_fl_thermal.py
(the publication window at 15 s) ran the same loop on the same bytes with the same options,
each in its own fixture (and the last two each in a ``python -m volerr`` process).  Here the
command runs in-process (tests/helpers/in_process.py: ``volerr.cli.main``, what ``python -m
volerr`` calls, with one BLAS thread as those processes had), its ``--json`` and
``--predictions-out`` files read back, and the result kept (``functools.lru_cache``; the
tests share the objects and must not change them).  Every test of these files is in one
xdist group (``GROUP``), so that one worker computes each run once and the pooled coverage
test of test_drift_generalisation.py sees every window (about 40 s of CPU in one worker).

Measured when this module was written, every window: at 15 s the JSON, the predictions file
and the console text of the in-process run are byte-identical to those of the process the
tests started; at 15 s and 60 s the JSON holds what ``loop_drift(...).data`` held (what
test_drift_sampling.py read, in-process with the default BLAS threads): the same keys,
strings, integers, families and terms, the floats within 1e-10 relative (9.4e-11 at most:
the threaded BLAS's summation order), the file names in ``runs`` aside.
"""

from __future__ import annotations

import atexit
import csv
import json
import shutil
import tempfile
from dataclasses import dataclass
from functools import lru_cache
from importlib import resources
from pathlib import Path

#: the xdist group of every test that reads these runs
GROUP = "fl_thermal"

#: window -> (``--holdout-time``, the file cut before this time in s, or None): five 20 %
#: windows held out of the whole file (training on both sides) and the publication split
#: (the file before 133 380 s, 100 035 s on held out)
WINDOWS = {"0-20": ("0s:33345s", None), "20-40": ("33345s:66690s", None),
           "40-60": ("66690s:100035s", None), "60-80": ("100035s:133380s", None),
           "80-100": ("133380s:", None), "pub": ("100035s:", 133380.0)}


def data() -> Path:
    """The shipped data file (15 s)."""
    return Path(str(resources.files("volerr") / "data" / "fl_thermal_spindle.csv"))


def file_text(step: int, cut) -> str:
    """The data file with every ``step``-th reading, the readings at ``cut`` s and later left
    out (``cut`` None: none); its header lines kept (step 1, no cut: the file itself)."""
    lines = data().read_text().splitlines()
    head = [ln for ln in lines if ln.startswith("#")]
    body = [ln for ln in lines if not ln.startswith("#")]
    rows = body[1:][::step]
    if cut is not None:
        rows = [r for r in rows if float(r.split(",", 1)[0]) < cut]
    return "\n".join(head + [body[0]] + rows) + "\n"


@dataclass(frozen=True)
class Run:
    """One ``volerr loop`` run: its exit code, console text, JSON (parsed), predictions
    (``csv.DictReader`` rows), and the folder holding its input ``input`` and its outputs
    ``w.json`` and ``p.csv`` (kept until the process ends)."""

    returncode: int
    stdout: str
    stderr: str
    doc: dict
    rows: list
    folder: Path
    input: Path


_ROOT: list = []


def _root() -> Path:
    if not _ROOT:
        _ROOT.append(Path(tempfile.mkdtemp(prefix="volerr-fl-runs-")))
        atexit.register(shutil.rmtree, _ROOT[0], True)
    return _ROOT[0]


@lru_cache(maxsize=None)
def loop_run(step: int, name: str) -> Run:
    """``volerr loop DMU50 drift:FILE --holdout-time W --json w.json --predictions-out
    p.csv`` on window ``name`` of :data:`WINDOWS`, FILE every ``step``-th reading (step 1 of
    an uncut window: the shipped file itself), run once per process."""
    from helpers.in_process import volerr as volerr_cmd

    window, cut = WINDOWS[name]
    folder = _root() / f"{name}_{step}"
    folder.mkdir()
    if step == 1 and cut is None:
        path = data()
    else:
        path = folder / f"fl_{step}.csv"
        path.write_text(file_text(step, cut))
    r = volerr_cmd(*["loop", "DMU50", f"drift:{path}", "--holdout-time", window,
                     "--json", "w.json", "--predictions-out", "p.csv"], cwd=folder)
    doc, rows = {}, []
    if r.returncode == 0:
        doc = json.loads((folder / "w.json").read_text())
        with open(folder / "p.csv", newline="") as fh:
            rows = list(csv.DictReader(fh))
    return Run(r.returncode, r.stdout, r.stderr, doc, rows, folder, path)
