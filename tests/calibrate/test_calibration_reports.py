"""Issue 32, item 8 (calibration and ballbar reports): a rotary ballbar sweep that diagnoses
nothing says why, on the console and in the JSON (before: an empty diagnosis, exit 0, no
word); the rotary calibration page shows no all-zero ISO 10360-2 table and no Python repr
(before: a table of zeros and the map's box as a dict).  The sweep is simulated by the
independent simulator (tests/helpers/instrument_sim.py)."""

import json
import re

import numpy as np
import pytest

from helpers import instrument_sim as S
from instruments._common import Campaign, random_setup

TRUTH = {"EX0C": 15.0, "EY0C": -10.0, "EA0C": 25.0, "EB0C": -35.0}


class _Run:
    """``volerr ARGS`` run in this process: ``returncode``, ``stdout``, ``stderr``."""

    def __init__(self, capsys, args):
        from volerr.cli import main

        self.returncode = main([str(a) for a in args])
        cap = capsys.readouterr()
        self.stdout, self.stderr = cap.out, cap.err


def test_radial_sweep_says_why(tmp_path, capsys):
    m = S.Machine("TT_AC")
    blocks = [S.concat([S.ballbar_sweep(m, "sweep_c.csv", "C", a, b, 60, (150.0, 0, 20.0),
                                        (100.0, 0, 0), "rad", u_um=0.3)
                        for a, b in ((0, 360), (360, 0))])]
    camp = Campaign(m, blocks, [S.constant(c) for c in TRUTH], TRUTH,
                    random_setup(blocks, np.random.default_rng(1)), seed=2)
    (path,) = camp.write(tmp_path)
    r = _Run(capsys, ("ballbar", "evaluate", path, "--layout", "TT_AC", "--json",
                      tmp_path / "e.json", "--html", tmp_path / "e.html"))
    assert r.returncode == 0, r.stderr
    doc = json.loads((tmp_path / "e.json").read_text())
    assert doc["diagnosis"] == []
    note = doc["diagnosis_note"]
    assert "determines none of EX0C, EY0C, EA0C, EB0C" in note and "ISO 10791-6" in note
    assert f"no diagnosis: {note}" in r.stdout
    assert "none: the sweep of C" in (tmp_path / "e.html").read_text()
    # the combination it names is the planted one (radial bar 20 mm above the pivot)
    m_ = re.search(r"EX0C \+ ([\d.]+) mm \* EB0C = ([-\d.]+) \+- ([\d.]+) um", note)
    arm, value, std = map(float, m_.groups())
    assert abs(value - (TRUTH["EX0C"] + arm * 1e-3 * TRUTH["EB0C"])) <= 3 * std, note


def test_rotary_calibration_page(tmp_path, capsys):
    from importlib.resources import files

    src = files("volerr") / "data" / "sphere_example_DMU50.csv"
    r = _Run(capsys, ("calibrate", "DMU50", src, "--html", tmp_path / "r.html", "--json",
                      tmp_path / "r.json"))
    assert r.returncode == 0, r.stderr
    text = re.sub(r"<img[^>]*>|<style>.*?</style>", "", (tmp_path / "r.html").read_text(),
                  flags=re.S)
    assert not re.search(r"[{}]|\['|\[\d", text), re.findall(r".{40}[{}\[].{40}", text)[:3]
    assert "<th>line</th>" not in text                      # no ISO 10360-2 length table
    assert "Not shown: the determined parameters do not change lengths" in text
    assert "EY0B + EY0C" in text and "written as" in text
    doc = json.loads((tmp_path / "r.json").read_text())
    assert "predicted" not in doc["iso10360"] and doc["iso10360"]["predicted_omitted"]
