"""Issue 32, item 2: what is written is what was determined.  On every shipped layout family
(column, fixed bridge, fixed horizontal arm, moving bridge, moving horizontal arm CMMs: three
ballbar circles; head-head, table-head, table-table five-axis machines: sphere probing), the
error directory ``calibrate`` writes holds 0 for every name the report calls undetermined,
except the ``written_as`` name of a determined combination, which holds the combination's
value and says so in a ``#`` comment line that every reader of error directories skips.

Before: ``calibrate DMU50 sphere_example_DMU50.csv --errors-out d`` reported EY0B and EY0C not
determined and wrote EY0B = -18.10 um (their sum) without a word."""

import contextlib
import io

import numpy as np
import pytest
from helpers import in_process

from volerr.calibrate import calibrate, terms
from volerr.calibrate.examples import write_ballbar_example
from volerr.cli import main
from volerr.estimate.design import series_basis
from volerr.machine.model import load
from volerr.tables.table import read_error_dir

pytestmark = pytest.mark.xdist_group("test_calibrate_written")

CMM = ["CX", "FB1", "FH1", "MB1", "MH1"]
FIVE_AXIS = ["HH_BC", "TH_BC", "TT_AC"]


def _check_written(cal, directory):
    """Every undetermined name 0 in ``directory``, every combination under its written_as."""
    model = load(cal.model.name)
    tables, (consts, _, _) = read_error_dir(directory, model.axes)
    doc = cal.data
    combos = {c["written_as"]: c for c in doc["combinations"]}
    for name in doc["unidentifiable"]:
        if name.startswith("RV_"):
            continue                        # reversals are not written into error tables
        p, _, term = name.partition("@")
        if model.parameter_axis.get(p) is None:
            value = consts.get(p, 0.0) * (1e6 if p[1] in "ABC" else 1e3)
        else:
            axis = model.parameter_axis[p]
            if axis not in tables or p not in tables[axis].values:
                value = 0.0
            else:
                t = tables[axis]
                P = series_basis(model, axis, t.positions, cal.ranges, cal.degree)
                coef = np.linalg.lstsq(P, t.values[p], rcond=None)[0]
                k = terms.term_degree(term)
                value = terms.report((p, k), coef[k], 0.0, model, cal.ranges)["value"]
        if name in combos:
            c = combos[name]
            assert abs(value - c["value"]) <= 1e-6 * max(1.0, abs(c["value"])), (name, value, c)
        else:
            assert abs(value) <= 1e-6, (name, value)
    text = "\n".join(f.read_text() for f in sorted(directory.iterdir()))
    for c in doc["combinations"]:
        assert f"# {c['written_as']} holds the combination {c['expression']}" in text, text[:800]


@pytest.mark.parametrize("layout", CMM)
def test_cmm_ballbar_defaults(layout, tmp_path):
    ex = write_ballbar_example(tmp_path / "bb", layout)
    cal = calibrate(layout, [str(f) for f in ex["files"]], plan=False, progress=False)
    assert cal.data["combinations"], cal.data["unidentifiable"]   # bar length unknown
    _check_written(cal, cal.write_error_tables(tmp_path / "d"))


def test_cmm_ballbar_everything(tmp_path):
    """``--parameters all``: many combinations and undetermined terms at once."""
    ex = write_ballbar_example(tmp_path / "bb", "MB1")
    cal = calibrate("MB1", [str(f) for f in ex["files"]], parameters="all", plan=False,
                    progress=False)
    assert len(cal.data["combinations"]) >= 3 and len(cal.data["unidentifiable"]) >= 10
    _check_written(cal, cal.write_error_tables(tmp_path / "d"))
    # the map and the ISO 10360 numbers say what they hold
    assert cal.data["volumetric_map"]["combinations"] == [
        c["expression"] for c in cal.data["combinations"]]
    assert cal.data["iso10360"]["combinations"] == cal.data["volumetric_map"]["combinations"]


#: two sphere centres (workpiece frame, mm) inside each layout's travel
CENTRES = {"HH_BC": [(900, 600, 200), (50, 30, 150)], "TH_BC": [(50, 30, 150), (-40, 60, 250)],
           "TT_AC": [(-60, 70, 90), (50, 30, 150)]}


def _sphere_file(layout, path):
    """A sphere plan over the rotary axes' travel with planted location errors (the layout's
    first-order model: what is checked here is what gets written, not the estimate)."""
    from volerr.calibrate.examples import SPHERE_TRUTH, _range
    from volerr.instruments import sphere

    model = load(layout)
    loc = [p for p in model.parameters if model.parameter_axis.get(p) is None
           and p not in model.layout.squareness]
    values = list(SPHERE_TRUTH.values())
    errors = {p: values[i % len(values)] * (1e-6 if p[1] in "ABC" else 1e-3)
              for i, p in enumerate(loc)}
    rotary = {a: np.linspace(*_range(model.travel[a]), 9) for a in model.rotary_axes}
    poses = sphere.plan(model, CENTRES[layout], rotary, (0.0, 0.0, 120.0))
    cols = sphere.simulate(model, errors, poses, (0.0, 0.0, 120.0),
                           {"1": (0.004, -0.006, 0.003), "2": (-0.005, 0.002, 0.007)}, 0.5, 3)
    sphere.write_csv(path, cols)
    return path


@pytest.mark.parametrize("layout", FIVE_AXIS)
def test_five_axis_sphere_defaults(layout, tmp_path):
    path = _sphere_file(layout, tmp_path / "s.csv")
    cal = calibrate(layout, [str(path)], plan=False, progress=False)
    _check_written(cal, cal.write_error_tables(tmp_path / "d"))


def test_dmu50_shipped_example_cli(tmp_path):
    """The issue's command on the shipped file, through the command line."""
    from importlib.resources import files

    src = files("volerr") / "data" / "sphere_example_DMU50.csv"
    r = in_process.volerr("calibrate", "DMU50", src, "--errors-out", tmp_path / "d")
    assert r.returncode == 0, r.stderr
    assert "determined only in combination: EY0B + EY0C" in r.stdout, r.stdout
    assert "written as 0" in r.stdout and "EY0C" in r.stdout
    _, (consts, _, _) = read_error_dir(tmp_path / "d", load("DMU50").axes)
    assert consts["EY0C"] == 0.0
    cal = calibrate("DMU50", [str(src)], plan=False, progress=False)
    _check_written(cal, tmp_path / "d")


def test_every_reader_accepts_the_comment_lines(tmp_path):
    """The error directory of a calibration with combinations (comment lines in X.csv, Y.csv,
    Z.csv and constants.csv) is read by map, iso10360, diagonals, squareness, controller
    export and compensate."""
    ex = write_ballbar_example(tmp_path / "bb", "MB1")
    cal = calibrate("MB1", [str(f) for f in ex["files"]], plan=False, progress=False)
    d = cal.write_error_tables(tmp_path / "d")
    assert all(f.read_text().startswith("# ") for f in d.iterdir())
    (tmp_path / "p.nc").write_text("G90 G1 X350 Y300 Z100 F1000\nG1 X400 Y320 Z120\n")
    t = tmp_path
    for args in (["map", "MB1", "--errors", d, "--out", t / "m.csv", "--extrapolate"],
                 ["iso10360", "MB1", "--errors", d, "--json", t / "i.json", "--extrapolate"],
                 ["diagonals", "MB1", "--errors", d, "--json", t / "g.json", "--extrapolate"],
                 ["squareness", "MB1", d, "--out", t / "sq"],
                 ["controller", "export", "MB1", "--errors", d, "--format", "isg", "--out",
                  t / "c.csv"],
                 ["compensate", "MB1", t / "p.nc", "--errors", d, "--out", t / "pc.nc",
                  "--extrapolate"]):
        # in this process (volerr.cli.main: the command's parser and exit code, no start-up)
        err = io.StringIO()
        with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(err):
            code = main([str(a) for a in args])
        assert code == 0, (args[0], err.getvalue())
