"""``volerr.plan.execute`` (the demo's and the tutorials' filler of a plan's files) closes the
file it reads: it left it to the garbage collector (``open(path).read()``), a ResourceWarning
per file in the plan tutorial (docs/tutorials/plot_05, run with warnings shown) and in any
test run that shows them (journey pass, 2026-12-07)."""

from __future__ import annotations

import gc
import warnings

import numpy as np

from volerr.machine.model import load
from volerr.plan import execute, plan


def test_execute_leaves_no_file_open(tmp_path):
    model = load("MB1")
    p = plan(model, ["ballbar"], 60)
    p.write(tmp_path / "p")
    files = sorted((tmp_path / "p").glob("*.csv"))
    assert files
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        for f in files:
            execute(f, model, {"EC0Y": 20e-6}, np.random.default_rng(1))
        gc.collect()
    leaks = [w for w in caught if issubclass(w.category, ResourceWarning)]
    assert not leaks, leaks[0].message
