"""LinuxCNC joint compensation files, checked against what LinuxCNC's own code does with
them (src/emc/motion/usrmotintf.cc usrmotLoadComp: type 0 ``trim = nominal - column``,
type 1 ``trim = column``; control.c: ``motor_pos_cmd = pos_cmd + trim`` interpolated
linearly, the forward column while moving up, the reverse one while moving down), re-written
here from the source, not from volerr; and the refusal of tables that make a machine worse."""

import json

import numpy as np
import pytest

import volerr
from volerr.cli import main
from volerr.fiveaxis.example import write_example
from volerr.tables import controller_tables as ctl
from volerr.tables.functions import ErrorFunctions
from volerr.tables.table import ErrorTable, write_error_dir

X = np.linspace(-250, 250, 51)


def _e(x):
    """The planted positioning error of X (mm): actual position minus nominal."""
    return 4e-3 * np.sin(np.asarray(x) / 70.0) + 2e-3 * np.asarray(x) / 250


def _rv(x):
    """The planted ISO 230-2 reversal B of X (mm): + approach minus - approach."""
    return -6e-3 + 1e-3 * np.cos(np.asarray(x) / 50.0)


@pytest.fixture(scope="module")
def errdir(tmp_path_factory):
    d = tmp_path_factory.mktemp("err")
    write_error_dir(d, {"X": ErrorTable("X", X, {"EXX": _e(X)}, reversal=_rv(X))}, None)
    return d


def _export(errdir, out, *extra):
    return main(["controller", "export", "DMU50", "--errors", str(errdir), "--format",
                 "linuxcnc", "--out", str(out), *extra])


def _lines(path):
    rows = [ln.split() for ln in path.read_text().splitlines() if ln.strip()]
    assert all(len(r) == 3 for r in rows)
    return np.array([[float(c) for c in r] for r in rows])


def _linuxcnc_actual(rows, comp_type, pos_cmd, direction):
    """Where the joint ends when LinuxCNC commands ``pos_cmd`` moving in ``direction``: the
    motion module's trim (usrmotLoadComp, compute_screw_comp) added to the command, then the
    machine's own error at the motor position (forward approach: E + B/2)."""
    nom = rows[:, 0]
    col = rows[:, 1] if direction > 0 else rows[:, 2]
    trim = nom - col if comp_type == 0 else col
    motor = pos_cmd + np.interp(pos_cmd, nom, trim)
    return motor + _e(motor) + direction * _rv(motor) / 2


@pytest.mark.parametrize("comp_type", [0, 1])
def test_tables_correct_the_joint_as_linuxcnc_applies_them(errdir, tmp_path, comp_type):
    out = tmp_path / "lcnc"
    assert _export(errdir, out, "--comp-file-type", str(comp_type)) == 0
    ini = (out / "compensation.ini").read_text()
    assert "[JOINT_0]" in ini and "COMP_FILE = X.comp" in ini and \
        f"COMP_FILE_TYPE = {comp_type}" in ini
    rows = _lines(out / "X.comp")
    assert len(rows) <= 256 and np.all(np.diff(rows[:, 0]) > 0)
    cmd = np.linspace(-240, 240, 97)
    for d in (1, -1):
        uncompensated = cmd + _e(cmd) + d * _rv(cmd) / 2 - cmd
        left = _linuxcnc_actual(rows, comp_type, cmd, d) - cmd
        assert np.abs(uncompensated).max() > 5e-3
        # what is left: the second-order term E'(x) * E and the table's interpolation
        assert np.abs(left).max() < 2e-4, (d, np.abs(left).max())


def test_type_0_and_type_1_carry_the_same_trims(errdir, tmp_path):
    for t in (0, 1):
        assert _export(errdir, tmp_path / f"t{t}", "--comp-file-type", str(t)) == 0
    r0, r1 = _lines(tmp_path / "t0" / "X.comp"), _lines(tmp_path / "t1" / "X.comp")
    assert np.array_equal(r0[:, 0], r1[:, 0])
    assert np.allclose(r0[:, [0]] - r0[:, 1:], r1[:, 1:], atol=1e-9)


def test_import_gives_the_error_and_reversal_back(errdir, tmp_path):
    assert _export(errdir, tmp_path / "lcnc") == 0
    assert main(["controller", "import", "DMU50", str(tmp_path / "lcnc" / "compensation.ini"),
                 "--format", "linuxcnc", "--out", str(tmp_path / "back")]) == 0
    m = volerr.load("DMU50")
    back = ErrorFunctions.from_dir(tmp_path / "back", m)
    t = back.tables["X"]
    inside = np.clip(t.positions, -250, 250)
    assert np.abs(t.values["EXX"] - _e(inside)).max() <= 0.5e-6 + 1e-12
    assert np.abs(t.reversal - _rv(inside)).max() <= 1e-6 + 1e-12


def test_rotary_joint_in_degrees(tmp_path):
    """The DMU50's B and C tables are in deg (the rotation about the axis' direction)."""
    m = volerr.load("DMU50")
    funcs = ErrorFunctions.from_dir(write_example(tmp_path / "ex", "DMU50")["errors"], m)
    tables = {t.input: t for t in ctl.build(funcs, "linuxcnc")}
    assert set(tables) >= {"B", "C"} and not tables["C"].modulo
    u = np.asarray(m.layout.axes["B"].direction, float)
    u /= np.linalg.norm(u)
    pos = tables["B"].positions
    q = np.zeros((len(pos), len(m.axes)))
    q[:, m.axes.index("B")] = np.clip(pos, *funcs.ranges()["B"])
    e = funcs(q)
    want = np.rad2deg(sum(u[k] * e.get(f"E{r}B", 0.0) for k, r in enumerate("ABC")))
    assert np.abs(tables["B"].values - want).max() <= 0.5e-6 + 1e-12


def test_a_table_that_makes_the_machine_worse_is_refused(tmp_path, capsys):
    """The DMU50 example's SINUMERIK CEC tables leave more than no compensation (issue 36:
    35.6 -> 36.9 um): exit 2, one line, nothing written; --force writes them and says so."""
    d = write_example(tmp_path / "ex", "DMU50")["errors"]
    out, js = tmp_path / "cec.txt", tmp_path / "cec.json"
    args = ["controller", "export", "DMU50", "--errors", str(d), "--format", "sinumerik-cec",
            "--out", str(out), "--json", str(js), "--grid", "5"]
    assert main(args) == 2
    err = capsys.readouterr().err
    assert len(err.strip().splitlines()) == 1 and "more than no compensation" in err
    assert not out.exists() and not js.exists()
    assert main(args + ["--force"]) == 0
    printed = capsys.readouterr().out
    assert "WORSE than no compensation" in printed
    s = json.loads(js.read_text())
    assert s["worse_than_none"] is True
    assert s["left_um"]["max"] > s["before_um"]["max"] or \
        s["left_um"]["rms"] > s["before_um"]["rms"]
    # a table that helps: said so, and worse_than_none false
    assert main(["controller", "export", "DMU50", "--errors", str(d), "--format",
                 "sinumerik-lec", "--out", str(tmp_path / "lec.txt"), "--json",
                 str(tmp_path / "lec.json"), "--grid", "5"]) == 0
    assert "better than no compensation" in capsys.readouterr().out
    s = json.loads((tmp_path / "lec.json").read_text())
    assert s["worse_than_none"] is False and s["left_um"]["rms"] < s["before_um"]["rms"]


@pytest.mark.parametrize("text, words", [
    ("0 0 0\n10 10.001\n", "three numbers"),
    ("0 0 0\n0 0.001 0.001\n", "must increase"),
    ("0 0 0\n", "fewer than two"),
    ("".join(f"{k} {k} {k}\n" for k in range(300)), "256"),
])
def test_bad_compensation_files_one_line_exit_2(tmp_path, capsys, text, words):
    (tmp_path / "X.comp").write_text(text)
    (tmp_path / "c.ini").write_text("[JOINT_0]\nCOMP_FILE = X.comp\nCOMP_FILE_TYPE = 0\n")
    assert main(["controller", "import", "DMU50", str(tmp_path / "c.ini"), "--format",
                 "linuxcnc", "--out", str(tmp_path / "back")]) == 2
    err = capsys.readouterr().err
    assert len(err.strip().splitlines()) == 1 and words in err, err
    assert not (tmp_path / "back").exists()


def test_bad_options_one_line_exit_2(errdir, tmp_path, capsys):
    (tmp_path / "c.ini").write_text("[JOINT_0]\nCOMP_FILE = X.comp\n")
    assert main(["controller", "import", "DMU50", str(tmp_path / "c.ini"), "--format",
                 "linuxcnc", "--out", str(tmp_path / "back")]) == 2
    assert "COMP_FILE_TYPE" in capsys.readouterr().err
    assert main(["controller", "export", "DMU50", "--errors", str(errdir), "--format",
                 "fanuc", "--out", str(tmp_path / "f.txt"), "--comp-file-type", "1"]) == 2
    err = capsys.readouterr().err
    assert len(err.strip().splitlines()) == 1 and "linuxcnc" in err
    assert _export(errdir, tmp_path / "l", "--points", "300") == 2
    assert "256" in capsys.readouterr().err
