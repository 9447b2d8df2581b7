"""Set-up shared by tests/check/test_check.py and test_check_fit_quality.py (one xdist group,
``check_world``): one DMU50 sphere campaign planned, filled, calibrated and its 20-minute check
planned, once per test process (both modules made exactly this, each in its own folder)."""

from __future__ import annotations

import shutil

import numpy as np
import pytest

from helpers.check_world import LAYOUT, PLANTED, SPHERE


@pytest.fixture(scope="session")
def sphere_campaign(tmp_path_factory):
    """The folder: ``ref/`` (the 80-reading plan, its sphere file filled with PLANTED, seed
    11), ``ref_empty.csv`` (that file before filling), ``cal.json`` (its calibration),
    ``plan/`` and ``plan.json`` (the check plan against it, 20 minutes).  The tests read these
    and write only files of other names."""
    from helpers import plan_fill
    from volerr.cli import main

    d = tmp_path_factory.mktemp("sphere_campaign")
    assert main(["plan", LAYOUT, "--instrument", SPHERE, "--readings", "80",
                 "--out", str(d / "ref")]) == 0
    shutil.copy(d / "ref" / "sphere.csv", d / "ref_empty.csv")
    plan_fill.fill(d / "ref" / "sphere.csv", LAYOUT, PLANTED, np.random.default_rng(11))
    assert main(["calibrate", LAYOUT, str(d / "ref" / "sphere.csv"),
                 "--json", str(d / "cal.json")]) == 0
    assert main(["check", "plan", LAYOUT, "--reference", str(d / "cal.json"),
                 "--instrument", SPHERE, "--minutes", "20", "--out", str(d / "plan"),
                 "--json", str(d / "plan.json")]) == 0
    return d
