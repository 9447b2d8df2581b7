"""The example files shipped with the formats (volerr/data) read and identify the values
planted in them (tables written by volerr.calibrate.examples; checked against the planted
numbers, not against a run of the code)."""

import contextlib
import io
import json
from importlib import resources

from volerr.calibrate.examples import BALLBAR_TRUTH, SPHERE_TRUTH


def _data(name):
    return str(resources.files("volerr") / "data" / name)


def _run(*args):
    """``volerr ARGS`` through ``volerr.cli.main`` in this process: (exit code, stderr)."""
    from volerr.cli import main

    err = io.StringIO()
    with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(err):
        code = main(list(args))
    return code, err.getvalue()


def test_shipped_sphere_example_gives_the_planted_location_errors(tmp_path):
    out = tmp_path / "r.json"
    code, err = _run("calibrate", "DMU50", _data("sphere_example_DMU50.csv"), "--json", str(out))
    assert code == 0, err
    doc = json.loads(out.read_text())
    assert len(doc["parameters"]) >= 4
    for name, v in doc["parameters"].items():
        assert abs(v["value"] - SPHERE_TRUTH[name]) < 3 * v["std"], (name, v)


def test_shipped_ballbar_example_gives_the_planted_squareness(tmp_path):
    out = tmp_path / "b.json"
    code, err = _run("ballbar", "evaluate", _data("ballbar_example_XY.csv"), "--json", str(out))
    assert code == 0, err
    diag = {d["parameter"]: d for d in json.loads(out.read_text())["diagnosis"]}
    e = diag["EC0Y"]
    assert abs(e["value"] - BALLBAR_TRUTH["EC0Y"]) < 3 * e["std"], e
    m = diag["EXX@slope-EYY@slope"]
    planted = 1e-3 * (BALLBAR_TRUTH["EXX"] - BALLBAR_TRUTH["EYY"])
    assert abs(m["value"] - planted) < 3 * m["std"], m
