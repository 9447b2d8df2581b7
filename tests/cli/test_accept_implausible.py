"""``--accept-implausible`` on every command that reads or writes error tables (issue 43).

The technician's mistake of the issue: a column headed ``_mm`` over values in um (DMU50's
EXX_um of the shipped five-axis example re-headed EXX_mm: 9.2 um read as 9.2 mm; an MB1 X.csv
with EYX up to 1.5 um headed EYX_mm).  Every command that reads such a directory refuses it
with one stderr line that names the file, the column and the option, exits 2 and writes
nothing; with ``--accept-implausible`` it runs (exit 0, its output written).  The writers
(``calibrate --errors-out``, ``loop --errors-out``, ``controller import --out``) refuse values
beyond the limits the same way and name the folder the user gave, not a staging folder.

The limits are the stated rule (translational 500 um + 500 ppm of the largest linear travel:
DMU50 500 mm -> 750 um, MB1 900 mm -> 950 um), so 9200 um and 1500 um are beyond them and the
example's own values (at most 9.2 um) are far inside.
"""

from __future__ import annotations

import shutil

import numpy as np
import pytest

from volerr.cli import main

pytestmark = pytest.mark.xdist_group("accept_implausible")

OPTION = "--accept-implausible"


@pytest.fixture(scope="module")
def world(tmp_path_factory):
    """DMU50: the shipped example re-headed; MB1: a small directory with EYX_mm over um."""
    from volerr.fiveaxis.example import write_example

    root = tmp_path_factory.mktemp("implausible")
    ex = write_example(root / "dmu")
    bad5 = root / "dmu_bad"
    shutil.copytree(ex["errors"], bad5)
    text = (bad5 / "X.csv").read_text()
    assert text.startswith("X,EXX_um,")
    (bad5 / "X.csv").write_text(text.replace("X,EXX_um,", "X,EXX_mm,", 1))
    bad3 = root / "mb1_bad"
    bad3.mkdir()
    x, y = np.linspace(0.0, 900.0, 10), np.linspace(0.0, 575.0, 6)
    rows = ["X,EXX_um,EYX_mm,EXX_std_um"] + [
        f"{a:g},{3.0 * np.sin(a / 300.0):.6g},{1.5 * a / 900.0:.6g},0.5" for a in x]
    (bad3 / "X.csv").write_text("\n".join(rows) + "\n")
    rows = ["Y,EYY_um,EXY_um"] + [f"{a:g},{2.0 * a / 575.0:.6g},{-1.0 * a / 575.0:.6g}"
                                  for a in y]
    (bad3 / "Y.csv").write_text("\n".join(rows) + "\n")
    task = root / "task.csv"
    task.write_text("X,Y,Z\n100,100,100\n700,400,300\n")
    return {"root": root, "prog": ex["program"], "dmu": bad5, "mb1": bad3, "task": task}


def _both(capsys, args, outputs, needles):
    """``args`` refused (exit 2, one line naming every needle and the option, no output),
    then accepted with the option (exit 0, the first output written)."""
    code = main([str(a) for a in args])
    err = capsys.readouterr().err
    assert code == 2, err
    assert err.count("\n") == 1 and "Traceback" not in err, err
    assert OPTION in err, err
    for n in needles:
        assert n in err, (n, err)
    assert ".volerr-staging" not in err, err
    assert not any(o.exists() for o in outputs), outputs
    code = main([str(a) for a in args] + [OPTION])
    err = capsys.readouterr().err
    assert code == 0, err
    assert outputs[0].exists()


def test_compensate(world, capsys):
    out = world["root"] / "comp.nc"
    _both(capsys, ["compensate", "DMU50", world["prog"], "--errors", world["dmu"], "--out", out],
          [out], ["X.csv", "EXX_mm"])


def test_tcpmap(world, capsys):
    out, png = world["root"] / "tcp.csv", world["root"] / "tcp.png"
    _both(capsys, ["tcpmap", "DMU50", "--errors", world["dmu"], "--point", "0", "0", "50",
                   "--steps", "5", "--csv", out, "--plot", png], [out, png],
          ["X.csv", "EXX_mm"])


def test_controller_export(world, capsys):
    out = world["root"] / "isg.csv"
    _both(capsys, ["controller", "export", "DMU50", "--errors", world["dmu"], "--format", "isg",
                   "--out", out, "--force"], [out], ["X.csv", "EXX_mm"])


def test_controller_export_axis_tables(world, capsys):
    out = world["root"] / "lec.txt"
    _both(capsys, ["controller", "export", "DMU50", "--errors", world["dmu"], "--format",
                   "sinumerik-lec", "--out", out, "--force"], [out], ["X.csv", "EXX_mm"])


def test_controller_import_writes_no_implausible_table(world, capsys):
    """The controller file holds 9.2 mm (exported with the option); importing it into an
    error directory is refused by the writer, naming the folder given."""
    isg = world["root"] / "isg_for_import.csv"
    assert main(["controller", "export", "DMU50", "--errors", str(world["dmu"]), "--format",
                 "isg", "--out", str(isg), "--force", OPTION]) == 0
    capsys.readouterr()
    out = world["root"] / "imported"
    _both(capsys, ["controller", "import", "DMU50", isg, "--out", out], [out],
          [str(out), "EXX"])


def test_squareness(world, capsys):
    out = world["root"] / "sq"
    _both(capsys, ["squareness", "MB1", world["mb1"], "--out", out], [out],
          ["X.csv", "EYX_mm"])


def test_uncertainty(world, capsys):
    js = world["root"] / "u.json"
    _both(capsys, ["uncertainty", "MB1", "--task", world["task"], "--evaluate", "distance",
                   "--errors", world["mb1"], "--samples", "200", "--quiet", "--json", js],
          [js], ["X.csv", "EYX_mm"])


def test_iso10360(world, capsys):
    js = world["root"] / "iso.json"
    _both(capsys, ["iso10360", "MB1", "--errors", world["mb1"], "--json", js], [js],
          ["X.csv", "EYX_mm"])


def test_ballbar_simulate(world, capsys):
    out = world["root"] / "bb.csv"
    _both(capsys, ["ballbar", "simulate", "MB1", "--errors", world["mb1"], "--plane", "XY",
                   "--radius", "100", "--centre", "450", "290", "200", "--points", "36",
                   "--out", out], [out], ["X.csv", "EYX_mm"])


def test_simulate_instrument(world, capsys):
    out = world["root"] / "sim_bb.csv"
    _both(capsys, ["simulate", "MB1", "--instrument", "ballbar", "--errors", world["mb1"],
                   "--out", out], [out], ["X.csv", "EYX_mm"])


@pytest.fixture(scope="module")
def large(world):
    """Deviations of an MB1 with errors of a few hundred um (inside the deviations reader's
    limit): fitted with degree 2 and --accept-residual (the random functions are not
    polynomials), the identified EA0Z is some 4000 urad, beyond MB1's 1000 urad."""
    d = world["root"] / "large.csv"
    assert main(["simulate", "MB1", "--magnitude-um", "400", "--points", "60", "--probe", "0",
                 "0", "0", "--out", str(d)]) == 0
    return d


def test_calibrate_errors_out(world, large, capsys):
    capsys.readouterr()
    out = world["root"] / "cal_errors"
    _both(capsys, ["calibrate", "MB1", large, "--degree", "2", "--accept-residual",
                   "--errors-out", out], [out], [f"{out}/constants.csv", "urad"])


def test_loop_errors_out(world, large, capsys):
    capsys.readouterr()
    out = world["root"] / "loop_errors"
    _both(capsys, ["loop", "MB1", large, "--degree", "2", "--accept-residual", "--families",
                   "step", "--errors-out", out], [out], [f"{out}/", "urad"])
