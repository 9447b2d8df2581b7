"""NC-program compensation: executed on an independent exact model the compensated program lands
within 0.1 um; zero errors give the same bytes; G-code handling; CLI bad input; controller
tables; plots."""

import contextlib
import io
import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from helpers import in_process
from helpers.error_dirs import write_errors
from helpers.fiveaxis_chain import tool2work

import volerr
from volerr.nc import gcode
from volerr.tables import table as tables
from volerr.tables.functions import ErrorFunctions
from volerr.fiveaxis.program import compensate_program
from volerr.tables.table import ErrorTable, write_error_table

FAMILIES = ("DMU50", "TT_AC", "HH_BC", "TH_BC")


def cli(*args, cwd=None):
    """``volerr ARGS`` as ``python -m volerr`` runs it: (exit code, stdout, stderr), through
    ``volerr.cli.main`` in this process (``helpers.in_process``: the exit code and the lines on
    stderr are ``main``'s; a warning a process would print is appended to stderr, so the
    one-line checks still count it), without starting an interpreter (issue 42 item 7)."""
    r = in_process.volerr(*args, cwd=cwd)
    return r.returncode, r.stdout, r.stderr


def main_(*args):
    """``volerr ARGS`` through ``volerr.cli.main`` in this process: (exit code, stdout, stderr),
    for the commands expected to succeed."""
    from volerr.cli import main

    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        code = main([str(a) for a in args])
    return code, out.getvalue(), err.getvalue()


def random_program(m, rng, n, crlf=False):
    """Absolute moves with modal omissions, comments, then a G91 section."""
    lines = ["%", "O0042 (TEST PROGRAM)", "N10 G90 G21 G17 G0 (start)"]
    first = []
    for a in m.axes:
        lo, hi = m.travel[a]
        first.append(f"{a}{0.5 * (lo + hi) if a not in m.rotary_axes else max(lo, 0.0) + 10:.3f}")
    lines.append("G0 " + " ".join(first))
    for k in range(n):
        words = []
        for a in m.axes:
            if rng.random() < 0.6:
                lo, hi = m.travel[a]
                if a in m.rotary_axes:
                    lo, hi = max(lo, -170.0), min(hi, 170.0)
                    lo = max(lo, 1.0) if m.name == "DMU50" and a == "B" else lo
                words.append(f"{a}{rng.uniform(lo + 1, hi - 1):.3f}")
        if not words:
            words = ["F800"]
        tail = " ; cut" if k % 7 == 0 else (" (note)" if k % 5 == 0 else "")
        lines.append(f"N{100 + 10 * k} G1 " + " ".join(words) + tail)
        if k % 9 == 0:
            lines.append("")
    lines += ["G91 X1.5 Z-2.0", "Y0.5", "G90", "M30", "%"]
    end = "\r\n" if crlf else "\n"
    return end.join(lines) + end


def execute(m, funcs, text, tool=(0, 0, 0)):
    """'Run' a program: axis positions of each motion block -> actual tool tip and tool axis on
    the independent exact chain of test_fiveaxis with the errors of ``funcs`` there."""
    blocks = gcode.blocks(gcode.parse(text), m.axes)
    q = np.array([[b.target[a] for a in m.axes] for b in blocks])
    e = funcs(_lookup(m, funcs, q)) if funcs is not None else {}
    out = []
    for r, row in enumerate(q):
        er = {k: float(v[r]) for k, v in e.items()}
        t = tool2work(m.name, dict(zip(m.axes, row)), er)
        out.append(np.r_[(t @ np.r_[tool, 1])[:3], t[:3, 2]])
    return [b.line.number for b in blocks], q, np.array(out)


def _lookup(m, funcs, q):
    from volerr.fiveaxis.compensate import ErrorModel

    return ErrorModel(m, funcs).lookup(q)


def nominal(m, text, tool=(0, 0, 0)):
    blocks = gcode.blocks(gcode.parse(text), m.axes)
    q = np.array([[b.target[a] for a in m.axes] for b in blocks])
    return m.forward(q, tool)


# ------------------------------------------------------------------ the acceptance properties
@pytest.mark.parametrize("name", FAMILIES)
def test_compensated_program_lands_within_0p1_um(tmp_path, name):
    m = volerr.load(name)
    err = write_errors(tmp_path / "err", m, seed=hash(name) % 1000)
    prog = tmp_path / "part.nc"
    prog.write_bytes(random_program(m, np.random.default_rng(7), 60, crlf=True).encode())
    out = tmp_path / "part_comp.nc"
    rc, so, se = main_("compensate", name, "--errors", err, prog, "--out", out,
                     "--report", tmp_path / "rep.csv", "--json", tmp_path / "s.json")
    assert rc == 0, se
    funcs = ErrorFunctions.from_dir(err, m)
    text_in = prog.read_bytes().decode("latin-1")
    text_out = out.read_bytes().decode("latin-1")
    want = nominal(m, text_in)
    _, _, before = execute(m, funcs, text_in)
    lines, _, after = execute(m, funcs, text_out)
    e_before = np.linalg.norm(before[:, :3] - want[:, :3], axis=1) * 1e3
    e_after = np.linalg.norm(after[:, :3] - want[:, :3], axis=1) * 1e3
    assert e_before.max() > 5.0            # the test errors matter
    assert e_after.max() < 0.1, (lines[int(np.argmax(e_after))], e_after.max())
    # the report predicts the executed errors
    rep = np.genfromtxt(tmp_path / "rep.csv", delimiter=",", names=True, dtype=None,
                        encoding=None)
    assert np.allclose(rep["e_before_um"], e_before, atol=1e-6)
    assert np.allclose(rep["e_after_um"], e_after, atol=1e-3)
    # every byte that is not an axis number is kept: same line count and endings
    assert text_out.count("\r\n") == text_in.count("\r\n")
    strip = lambda s: [gcode.rewrite_line(ln, {}, {}) for ln in gcode.parse(s)]  # noqa: E731
    assert len(strip(text_out)) == len(strip(text_in))


@pytest.mark.parametrize("name", ["DMU50", "TT_AC", "HH_BC", "TH_BC", "MB1", "MB2", "FH1",
                                  "FH2", "FB1", "FB2", "MH1", "MH2", "CX", "CY"])
def test_linear_jacobian_depends_on_the_rotary_positions_only(name):
    """The solve evaluates d(tip)/d(linear axes) once and keeps it while only the linear axes
    move (the nominal chain is affine in them): the generated Jacobian of every shipped layout
    gives bitwise the same values at other linear positions."""
    from volerr.machine.kinematics import linear_axes, linear_jacobian

    m = volerr.load(name)
    rng = np.random.default_rng(4)
    lo = np.array([m.travel[a][0] for a in m.axes])
    hi = np.array([m.travel[a][1] for a in m.axes])
    q = lo + rng.random((50, len(m.axes))) * (hi - lo)
    moved = q.copy()
    for a in linear_axes(m):
        i = m.axes.index(a)
        moved[:, i] = lo[i] + rng.random(50) * (hi[i] - lo[i])
    assert not np.array_equal(moved, q)
    for tool in ((0.0, 0.0, 0.0), (12.0, -7.0, 95.0)):
        assert np.array_equal(linear_jacobian(m, moved, tool), linear_jacobian(m, q, tool))


def test_orientation_compensation_corrects_the_tool_axis(tmp_path):
    m = volerr.load("DMU50")
    err = write_errors(tmp_path / "err", m, seed=3)
    funcs = ErrorFunctions.from_dir(err, m)
    text = random_program(m, np.random.default_rng(11), 40)
    res = compensate_program(m, funcs, text, orientation=True)
    want = nominal(m, text)
    _, _, after = execute(m, funcs, res.text)
    _, _, before = execute(m, funcs, text)
    assert np.linalg.norm(after[:, :3] - want[:, :3], axis=1).max() < 1e-4
    ok = np.array([r.status == "compensated" for r in res.reports])
    ang_before = np.linalg.norm(before[:, 3:] - want[:, 3:], axis=1)
    ang_after = np.linalg.norm(after[:, 3:] - want[:, 3:], axis=1)
    assert ang_before[ok].min() > 5e-6
    # rotary words are written with 1e-4 deg (1.7 urad) resolution
    assert ang_after[ok].max() < 2e-6


def test_zero_errors_give_byte_identical_program(tmp_path):
    text = ("%\r\nO1 (T)\r\n\r\nN1 G90 G1 X10.12345 Y-2 Z+3. B0 C45 F500 ; go\r\n"
            "n2 x11\r\n(comment only)\r\nG91 Z-1 ;incr\r\nG90 B30.0 C-300.5\r\nM30\r\n%\r\n")
    prog = tmp_path / "p.nc"
    prog.write_bytes(text.encode("latin-1") + "(\xe9t\xe9)\r\n".encode("latin-1"))
    empty = tmp_path / "errs"
    empty.mkdir()
    # an O number with decimal-less numbers (Y-2, C45): the reading stated
    rc, so, se = main_("compensate", "DMU50", "--errors", empty, prog, "--out", tmp_path / "o.nc",
                       "--decimal-less", "mm")
    assert rc == 0, se
    assert (tmp_path / "o.nc").read_bytes() == prog.read_bytes()
    # tables full of zeros too
    m = volerr.load("DMU50")
    write_errors(tmp_path / "zeros", m, scale_um=0.0, scale_urad=0.0)
    rc, so, se = main_("compensate", "DMU50", "--errors", tmp_path / "zeros", prog, "--out",
                     tmp_path / "o2.nc", "--extrapolate", "--decimal-less", "mm")
    assert rc == 0, se
    assert (tmp_path / "o2.nc").read_bytes() == prog.read_bytes()


def test_words_added_only_where_a_modal_axis_needs_a_correction(tmp_path):
    m = volerr.load("DMU50")
    text = "G90 G1 X10 Y0 Z100 B0 C0\nY10\nY20 (y)\n"
    # EXX depends on X only: once X is corrected, Y moves need no X word
    x = np.linspace(-250, 250, 11)
    write_error_table(tmp_path / "X.csv", ErrorTable("X", x, {"EXX": 1e-5 * x}))
    funcs = ErrorFunctions.from_dir(tmp_path, m)
    out = compensate_program(m, funcs, text).text.splitlines()
    assert out[0].startswith("G90 G1 X9.9999 Y0 Z100 B0 C0")
    assert out[1:] == ["Y10", "Y20 (y)"]
    # EXY depends on Y: the Y moves need an X word
    d2 = tmp_path / "y"
    d2.mkdir()
    y = np.linspace(-225, 225, 11)
    write_error_table(d2 / "Y.csv", ErrorTable("Y", y, {"EXY": 1e-5 * y}))
    funcs = ErrorFunctions.from_dir(d2, m)
    out = compensate_program(m, funcs, text).text.splitlines()
    assert out[0] == "G90 G1 X10 Y0 Z100 B0 C0"
    assert out[1] == "Y10 X9.9999"
    assert out[2] == "Y20 X9.9998 (y)"


def test_incremental_mode_is_compensated_without_drift(tmp_path):
    m = volerr.load("DMU50")
    y = np.linspace(-225, 225, 11)
    write_error_table(tmp_path / "Y.csv", ErrorTable("Y", y, {"EXY": 1e-5 * y,
                                                             "EZY": 2e-6 * y}))
    funcs = ErrorFunctions.from_dir(tmp_path, m)
    text = "G90 G1 X10 Y0 Z100 B0 C0\nG91\n" + "Y7.3\n" * 20 + "X1 Y-3\nG90\n"
    res = compensate_program(m, funcs, text)
    want = nominal(m, text)
    _, _, after = execute(m, funcs, res.text)
    assert np.abs(after[:, :3] - want[:, :3]).max() < 1e-4
    assert "G91" in res.text and res.text.count("\n") == text.count("\n")


def test_thesis_strategy_leaves_what_it_neglects(tmp_path):
    m = volerr.load("DMU50")
    err = write_errors(tmp_path / "err", m, seed=5)
    funcs = ErrorFunctions.from_dir(err, m)
    text = random_program(m, np.random.default_rng(2), 30)
    full = compensate_program(m, funcs, text).summary()
    thesis = compensate_program(m, funcs, text, strategy="thesis").summary()
    assert full["max_after_um"] < 0.1
    assert thesis["max_after_um"] > 10 * full["max_after_um"]
    assert thesis["rms_after_um"] < thesis["rms_before_um"]
    # with the angular errors of the linear axes and all rotary errors zero, and constant
    # translational errors, the thesis strategy is exact too
    only = {"EXX", "EYY", "EZZ"}
    d2 = tmp_path / "lin"
    d2.mkdir()
    for a, p in zip("XYZ", ("EXX", "EYY", "EZZ")):
        lo, hi = m.travel[a]
        write_error_table(d2 / f"{a}.csv", ErrorTable(a, [lo, hi], {p: [0.01, 0.01]}))
    f2 = ErrorFunctions.from_dir(d2, m)
    assert compensate_program(m, f2, text, strategy="thesis").summary()["max_after_um"] < 0.06
    assert only


# ------------------------------------------------------------------ G-code tokenizer
_word = st.builds(lambda l, v: f"{l}{v}", st.sampled_from("GMNFSTXYZBCxyz"),
                  st.sampled_from(["0", "1", "-2.5", "+3.", "10.125", ".5", "007"]))
_piece = st.one_of(_word, st.sampled_from([" ", "  ", "\t", "(c)", "( x y )"]))
_line = st.builds(lambda ps, c: "".join(ps) + c, st.lists(_piece, max_size=6),
                  st.sampled_from(["", " ; tail", ";x"]))


@settings(max_examples=200, deadline=None)
@given(st.lists(_line, max_size=8), st.sampled_from(["\n", "\r\n", "\r"]),
       st.booleans())
def test_tokenizer_keeps_every_byte(lines, end, trailing):
    text = end.join(lines) + (end if trailing else "")
    parsed = gcode.parse(text)
    assert "".join(ln.text for ln in parsed) == text
    assert "".join(gcode.rewrite_line(ln, {}, {}) for ln in parsed) == text
    for ln in parsed:
        assert "".join(t.text for t in ln.tokens) == ln.body


@pytest.mark.parametrize("text,msg", [
    ("G2 X10 Y10 B10 I5 J0\n", "rotary axis B in an arc"),
    ("G43.5 H1 X1 Y1 Z1 I0 J0 K1\n", "TCPM program needs the tool length"),
    ("G20\nG1 X1\n", "inch"),
    ("G1 A10\n", "axis A is not an axis"),
    ("G1 X#1\n", "cannot interpret"),
    ("G1 X1 (open\n", "unclosed comment"),
    ("G81 Z-5 R1\n", "canned cycle"),
    ("G43.4 H1\n", "TCPM"),
    ("/G1 X1\n", "block delete"),
    ("G1 X1 X2\n", "programmed twice"),
    ("G92 X0\n", "coordinate shift"),
])
def test_unsupported_constructs_are_refused(text, msg):
    with pytest.raises(volerr.errors.InputError, match=msg):
        gcode.blocks(gcode.parse(text), ("X", "Y", "Z", "B", "C"))


def test_unknown_axes_are_reported_not_guessed(tmp_path):
    m = volerr.load("DMU50")
    err = write_errors(tmp_path / "err", m)
    funcs = ErrorFunctions.from_dir(err, m)
    text = "G1 X10 Y10\nZ50 B10 C0\nX20\nG28 Z0\nX30\nZ60\n"
    res = compensate_program(m, funcs, text)
    status = [r.status for r in res.reports]
    assert status[0].startswith("not compensated")
    assert status[1] == "compensated" and status[2] == "compensated"
    assert status[3].startswith("not compensated: position of axis Z")   # after G28
    assert status[4] == "compensated"
    lines = res.text.splitlines()
    assert lines[0] == "G1 X10 Y10" and lines[3] == "G28 Z0" and lines[4] == "X30"
    res2 = compensate_program(m, funcs, text, initial={"Z": 50, "B": 10, "C": 0})
    assert res2.reports[0].status == "compensated"


def test_rotary_axes_never_programmed_are_taken_at_zero(tmp_path):
    """A three-axis program on a five-axis machine: B and C stay at 0 and every block is
    compensated; executed on the independent chain it lands within 0.1 um."""
    m = volerr.load("DMU50")
    err = write_errors(tmp_path / "err", m, seed=3)
    funcs = ErrorFunctions.from_dir(err, m)
    text = "G90 G1 X10 Y-20 Z30\nX40\nY15 Z110\n"
    res = compensate_program(m, funcs, text)
    assert res.assumed_zero == ("B", "C")
    assert [r.status for r in res.reports] == ["compensated"] * 3
    full = lambda t: "".join(f"{ln} B0 C0\n" for ln in t.splitlines())  # noqa: E731
    want = nominal(m, full(text))
    _, _, before = execute(m, funcs, full(text))
    _, _, after = execute(m, funcs, full(res.text))
    assert np.linalg.norm(before[:, :3] - want[:, :3], axis=1).max() > 5e-3
    assert np.linalg.norm(after[:, :3] - want[:, :3], axis=1).max() < 1e-4
    # a B word anywhere means B is programmed: before it, its position stays unknown
    res2 = compensate_program(m, funcs, "G1 X10 Y0 Z0\nB10 C0\n")
    assert res2.assumed_zero == () and res2.reports[0].status.startswith("not compensated")


# ------------------------------------------------------------------ command line
def test_cli_bad_input_exit_2_one_line(tmp_path):
    m = volerr.load("DMU50")
    err = write_errors(tmp_path / "err", m)
    prog = tmp_path / "p.nc"
    prog.write_text("G90 G1 X10 Y10 Z100 B10 C10\n")
    before = prog.read_bytes()
    cases = [
        ("compensate", "NOPE", "--errors", err, prog, "--out", tmp_path / "o.nc"),
        ("compensate", "DMU50", "--errors", err, prog, "--out", prog),
        ("compensate", "DMU50", "--errors", tmp_path / "missing", prog, "--out", tmp_path / "o"),
        ("compensate", "DMU50", "--errors", err, tmp_path / "nope.nc", "--out", tmp_path / "o"),
        ("compensate", "MB1", "--errors", tmp_path / "e0", prog, "--out", tmp_path / "o",
         "--orientation"),
        ("compensate", "DMU50", "--errors", err, prog, "--out", tmp_path / "o", "--initial",
         "Q=1"),
        ("compensate", "DMU50", "--errors", err, prog, "--out", tmp_path / "o", "--tol-um",
         "nan"),
        ("tcpmap", "MB1", "--errors", err, "--point", "0", "0", "0", "--out", tmp_path / "m.png"),
        ("controller", "export", "DMU50", "--errors", tmp_path / "missing", "--format", "isg",
         "--out", tmp_path / "x.csv"),
    ]
    (tmp_path / "e0").mkdir()
    for args in cases:
        rc, so, se = cli(*args)
        assert rc == 2, (args, se)
        assert len(se.strip().splitlines()) == 1 and "Traceback" not in se, se
    assert prog.read_bytes() == before


def test_cli_refuses_bad_arcs_and_positions_outside_the_tables(tmp_path):
    err = tmp_path / "err"
    err.mkdir()
    write_error_table(err / "X.csv", ErrorTable("X", [0, 100], {"EXX": [0.0, 0.001]}))
    prog = tmp_path / "p.nc"
    for text, msg in [("G1 X10 Y0 Z10 B0 C0\nG2 X20 Y10 R5\n", "line 2: the end point is "
                                                                  "not on the arc's circle"),
                      ("G1 X150 Y0 Z10 B0 C0\n", "outside the measured range"),
                      ("G1 X10 Y0 Z900 B0 C0\n", "outside the travel"),
                      ("G1 X10 Y0 Z10 B0 C0 A5\n", "axis A")]:
        prog.write_text(text)
        rc, so, se = cli("compensate", "DMU50", "--errors", err, prog, "--out", tmp_path / "o")
        assert rc == 2 and msg in se, se
        assert not (tmp_path / "o").exists()
    prog.write_text("G1 X150 Y0 Z10 B0 C0\n")
    rc, so, se = cli("compensate", "DMU50", "--errors", err, prog, "--out", tmp_path / "o",
                     "--extrapolate")
    assert rc == 0, se
    assert "X149.9985" in (tmp_path / "o").read_text()


def test_cli_outputs_report_json_and_plot(tmp_path):
    import json

    m = volerr.load("DMU50")
    err = write_errors(tmp_path / "err", m)
    prog = tmp_path / "p.nc"
    prog.write_text(random_program(m, np.random.default_rng(1), 12))
    rc, so, se = main_("compensate", "DMU50", "--errors", err, prog, "--out", tmp_path / "o.nc",
                     "--json", tmp_path / "s.json", "--plot", tmp_path / "p.png",
                     "--orientation")
    assert rc == 0, se
    s = json.loads((tmp_path / "s.json").read_text())
    assert s["max_after_um"] < 0.1 < s["max_before_um"]
    assert (tmp_path / "p.png").read_bytes()[:4] == b"\x89PNG"
    rc, so, se = main_("tcpmap", "DMU50", "--errors", err, "--point", "20", "10", "50",
                     "--out", tmp_path / "m.png", "--csv", tmp_path / "m.csv", "--steps", "9")
    assert rc == 0, se
    grid = np.genfromtxt(tmp_path / "m.csv", delimiter=",", names=True)
    assert len(grid) == 81
    # the grid's axis positions put the tool tip on the point
    q = np.column_stack([grid["X_mm"], grid["Y_mm"], grid["Z_mm"], grid["B_deg"], grid["C_deg"]])
    assert np.allclose(m.forward(q)[:, :3], [20, 10, 50], atol=1e-9)
    funcs = ErrorFunctions.from_dir(err, m)
    ok = np.isfinite(grid["e_um"])
    e = m.exact_error(q[ok], funcs(_lookup(m, funcs, q[ok])))
    assert np.allclose(np.linalg.norm(e, axis=1) * 1e3, grid["e_um"][ok], rtol=1e-5)


# ------------------------------------------------------------------ controller tables
@pytest.mark.parametrize("fmt", ["isg", "etalon"])
def test_controller_export_import_round_trip(tmp_path, fmt):
    m = volerr.load("DMU50")
    err = write_errors(tmp_path / "err", m)
    f = tmp_path / f"dmu.{fmt}"
    rc, so, se = main_("controller", "export", "DMU50", "--errors", err, "--format", fmt,
                       "--out", f)
    assert rc == 0, se
    rc, so, se = main_("controller", "import", "DMU50", f, "--out", tmp_path / "back")
    assert rc == 0, se
    t0, (c0, _, _) = tables.read_error_dir(err, m.axes)
    t1, (c1, _, _) = tables.read_error_dir(tmp_path / "back", m.axes)
    assert set(t0) == set(t1) and set(c0) == set(c1)
    for a in t0:
        assert np.allclose(t0[a].positions, t1[a].positions)
        for p in t0[a].values:
            assert np.allclose(t0[a].values[p], t1[a].values[p], rtol=1e-10, atol=1e-15)
    for p in c0:
        assert c1[p] == pytest.approx(c0[p], rel=1e-10)
    text = f.read_text()
    assert ("C0Y" in text and "EC0Y" not in text)  # position errors without the E


@pytest.mark.parametrize("content,msg", [
    ("Z X EXX\n0 0 0.1\n0 10 0.2\n", "more than one argument"),
    ("X EXY\n0 0.1\n10 0.2\n", "error of axis Y"),
    ("X EXX\n0 0.1\n10 nan\n", "NaN"),
    ("X EXX EYX\n0 0.1\n", "values for"),
    ("[EXX]\nGridpoints = {\n0 0.1\n", "not closed"),
    ("[C0Y]\nVALUE = abc\n", "not a number"),
    ("[EXA]\nGridpoints = {\n0 0.1\n10 0.2\n}\n", "axis A is not an axis"),
    ("[Q0Y]\nVALUE = 1\n", "not an ISO"),
])
def test_controller_import_refuses_malformed_files(tmp_path, content, msg):
    f = tmp_path / "in.txt"
    f.write_text(content)
    rc, so, se = cli("controller", "import", "DMU50", f, "--out", tmp_path / "o")
    assert rc == 2 and msg in se, se
    assert len(se.strip().splitlines()) == 1
    assert not (tmp_path / "o").exists()


def test_controller_reads_the_documented_isg_example(tmp_path):
    """The ISG documentation's example layout: blanks, // comments, # block breaks."""
    f = tmp_path / "x.csv"
    f.write_text("// position errors\nA0Z B0Z\n0.0001 -0.0002\n#\n// X\n"
                 "X EXX EYX EZX EAX EBX ECX\n0.0 0.02 0.01 0.07 0.00 0.0042 0.003\n"
                 "10.0 0.00 -0.1 0.01 0.00 0.0011 0.002\n")
    m = volerr.load("DMU50")
    from volerr.tables.controller import read_controller_file

    t, c = read_controller_file(f, m)
    assert c == {"EA0Z": 0.0001, "EB0Z": -0.0002}
    assert t["X"].values["EYX"].tolist() == [0.01, -0.1]
    assert math.isclose(t["X"].values["EBX"][0], 0.0042)


def test_added_words_follow_the_program_style(tmp_path):
    m = volerr.load("DMU50")
    y = np.linspace(-225, 225, 11)
    write_error_table(tmp_path / "Y.csv", ErrorTable("Y", y, {"EXY": 1e-5 * y}))
    funcs = ErrorFunctions.from_dir(tmp_path, m)
    out = compensate_program(m, funcs, "G90G1X10Y0Z100B0C0\ny10\n").text
    assert out == "G90G1X10Y0Z100B0C0\ny10x9.9999\n"


def test_builtin_example_hemisphere(tmp_path):
    """The demo example: thesis-size errors, a five-axis finishing program made with the
    nominal inverse (tool axis normal to a hemisphere); compensated within 0.1 um."""
    from volerr.fiveaxis.example import write_example

    paths = write_example(tmp_path / "ex")
    m = volerr.load("DMU50")
    funcs = ErrorFunctions.from_dir(paths["errors"], m)
    text = paths["program"].read_bytes().decode("latin-1")
    want = nominal(m, text)
    blocks = gcode.blocks(gcode.parse(text), m.axes)
    q = np.array([[b.target[a] for a in m.axes] for b in blocks])
    # the program really is the hemisphere: tool axis along the normal at every block
    nrm = (want[:, :3] - [30.0, 20.0, 20.0]) / 40.0
    body = slice(0, -1)  # the last block is the retract
    assert np.allclose(np.linalg.norm(nrm[body], axis=1), 1.0, atol=1e-5)
    assert np.allclose(want[body, 3:], nrm[body], atol=1e-5)
    assert np.ptp(q[:, 3]) > 40 and np.ptp(q[:, 4]) > 300
    res = compensate_program(m, funcs, text)
    _, _, after = execute(m, funcs, res.text)
    _, _, before = execute(m, funcs, text)
    assert np.linalg.norm(before[:, :3] - want[:, :3], axis=1).max() > 10e-3
    assert np.linalg.norm(after[:, :3] - want[:, :3], axis=1).max() < 1e-4


@pytest.mark.parametrize("name", ["TT_AC", "HH_BC", "TH_BC"])
def test_orientation_compensation_other_families(tmp_path, name):
    m = volerr.load(name)
    err = write_errors(tmp_path / "err", m, seed=8)
    funcs = ErrorFunctions.from_dir(err, m)
    text = random_program(m, np.random.default_rng(5), 25)
    res = compensate_program(m, funcs, text, orientation=True)
    want = nominal(m, text)
    _, _, after = execute(m, funcs, res.text)
    assert np.linalg.norm(after[:, :3] - want[:, :3], axis=1).max() < 1e-4
    ok = np.array([r.status == "compensated" for r in res.reports])
    assert ok.sum() >= len(ok) - 2
    assert np.linalg.norm(after[ok, 3:] - want[ok, 3:], axis=1).max() < 2e-6


def test_controller_negate_round_trip(tmp_path):
    m = volerr.load("TT_AC")
    err = write_errors(tmp_path / "err", m)
    f = tmp_path / "comp.isg"
    assert main_("controller", "export", "TT_AC", "--errors", err, "--format", "isg", "--out", f,
               "--negate")[0] == 0
    t_err, _ = tables.read_error_dir(err, m.axes)
    from volerr.tables.controller import read_controller_file

    t_neg, _ = read_controller_file(f, m)
    assert np.allclose(t_neg["X"].values["EXX"], -t_err["X"].values["EXX"])
    assert main_("controller", "import", "TT_AC", f, "--negate", "--out", tmp_path / "b")[0] == 0
    t_back, _ = tables.read_error_dir(tmp_path / "b", m.axes)
    assert np.allclose(t_back["A"].values["EBA"], t_err["A"].values["EBA"], rtol=1e-10)


def test_endless_rotary_table_is_closed_over_the_turn(tmp_path):
    """A C table measured 0..340 deg (thesis: 18 positions, 20 deg steps) serves C = 350 by
    interpolating towards the value at 0 = 360 deg, never by extrapolating."""
    c = np.arange(0, 360, 20.0)
    exc = 1e-3 * np.sin(np.deg2rad(c)) + 2e-3
    write_error_table(tmp_path / "C.csv", ErrorTable("C", c, {"EXC": exc}))
    prog = tmp_path / "p.nc"
    prog.write_text("G1 X10 Y10 Z100 B0 C350\n")
    rc, so, se = cli("compensate", "DMU50", "--errors", tmp_path, prog, "--out", tmp_path / "o",
                     "--report", tmp_path / "r.csv")
    assert rc == 0, se
    assert "closed over the full turn" in se
    rep = np.genfromtxt(tmp_path / "r.csv", delimiter=",", names=True, dtype=None,
                        encoding=None)
    # at C = 350: halfway between EXC(340) and EXC(360) = EXC(0); the tool-relative error of
    # the table's C axis turns with C (see helpers.fiveaxis_chain)
    want = 0.5 * (exc[-1] + exc[0])
    cc = np.deg2rad(350.0)
    assert rep["dx_before_um"] == pytest.approx(1e3 * want * np.cos(cc), abs=1e-6)
    assert rep["dy_before_um"] == pytest.approx(1e3 * want * np.sin(cc), abs=1e-6)


def test_report_carries_the_uncertainty_of_the_remaining_error(tmp_path):
    """Only EXX has a standard deviation (0.7 um): the remaining error of every block is
    uncertain by 0.7 um along the machine X direction, whatever the rotary positions."""
    m = volerr.load("DMU50")
    x = np.linspace(-250, 250, 6)
    write_error_table(tmp_path / "X.csv", ErrorTable("X", x, {"EXX": 1e-5 * x},
                                                     std={"EXX": np.full(6, 0.7e-3)}))
    funcs = ErrorFunctions.from_dir(tmp_path, m)
    text = random_program(m, np.random.default_rng(4), 10)
    res = compensate_program(m, funcs, text)
    u = np.array([r.u_after_um for r in res.reports])
    assert np.allclose(np.linalg.norm(u, axis=1), 0.7, rtol=1e-9)
    assert res.summary()["max_u_after_um"] == pytest.approx(0.7)


def test_iso_16907_types_select_what_is_compensated(tmp_path):
    m = volerr.load("DMU50")
    rotary_only = {p for p in m.parameters if m.parameter_axis[p] in ("B", "C") or "0B" in p
                   or "0C" in p}
    err = write_errors(tmp_path / "err", m, seed=9, only=rotary_only)
    funcs = ErrorFunctions.from_dir(err, m)
    text = random_program(m, np.random.default_rng(3), 15)
    lin = compensate_program(m, funcs, text, types=["L-VOL"])
    assert lin.text == text                    # nothing of the linear axes to compensate
    s = lin.summary()
    assert s["max_after_um"] == pytest.approx(s["max_before_um"]) and s["max_before_um"] > 1
    full = compensate_program(m, funcs, text)
    assert compensate_program(m, funcs, text, types=["L-VOL", "R-VOL"]).text == full.text
    assert compensate_program(m, funcs, text, types=["R-VOL"]).text == full.text
    # every parameter has a type; the inclined B mixes positioning and tilt
    from volerr.fiveaxis.compensate import parameter_types

    t = parameter_types(m)
    assert set(t) == set(m.parameters)
    assert t["EXX"] == ("L-POS",) and t["EYX"] == ("L-STR",) and t["EBX"] == ("L-ANG",)
    assert t["EC0Y"] == ("L-SQU",) and t["EX0C"] == ("R-POR",) and t["ECC"] == ("R-POS",)
    assert t["EAC"] == ("R-ANG",) and t["EBB"] == ("R-POS", "R-ANG")
    with pytest.raises(volerr.errors.InputError, match="unknown compensation type"):
        compensate_program(m, funcs, text, types=["L-FOO"])


def test_program_at_the_end_of_the_tables_is_compensated(tmp_path):
    """Tables measured over exactly the travel, a program that goes to both travel ends: the
    correction pushes the axis a few um past the table's end; the end value is used there
    (the nominal positions are inside), the executed tip lands within 0.1 um."""
    m = volerr.load("DMU50")
    err = tmp_path / "err"
    err.mkdir()
    lo, hi = m.travel["X"]
    x = np.linspace(lo, hi, 5)
    write_error_table(err / "X.csv", ErrorTable("X", x, {"EXX": -x * 1e-5, "EYX": x * 2e-5}))
    prog = tmp_path / "p.nc"
    prog.write_text(f"G0 X0 Y0 Z100 B0 C0\nG1 X{hi:g}\nG1 X{lo:g}\n")
    out = tmp_path / "o.nc"
    rc, so, se = main_("compensate", "DMU50", "--errors", err, prog, "--out", out)
    assert rc == 0, se
    blocks = gcode.blocks(gcode.parse(out.read_text()), m.axes)
    q = np.array([[b.target[a] for a in m.axes] for b in blocks])
    assert q[1, 0] > hi and q[2, 0] < lo            # the correction goes past the ends
    # the executing machine: exact chain, table values held at the ends
    xc = np.clip(q[:, 0], lo, hi)
    tip = []
    for r, row in enumerate(q):
        e = {"EXX": -xc[r] * 1e-5, "EYX": xc[r] * 2e-5}
        tip.append((tool2work("DMU50", dict(zip(m.axes, row)), e) @ [0, 0, 0, 1])[:3])
    want = nominal(m, prog.read_text())[:, :3]
    assert np.linalg.norm(np.array(tip) - want, axis=1).max() * 1e3 < 0.1
    # beyond the margin it is still refused
    prog.write_text(f"G0 X0 Y0 Z100 B0 C0\nG1 X{hi + 2:g}\n")
    rc, so, se = cli("compensate", "DMU50", "--errors", err, prog, "--out", tmp_path / "o2",
                     "--ignore-travel")
    assert rc == 2 and "outside the measured range" in se


def test_bad_program_one_stderr_line_even_with_notes_about_the_tables(tmp_path):
    """An endless C table that leaves a gap (0..330 deg) gives a note; a bad program must
    still give exactly one line on stderr (the error), for compensate and tcpmap."""
    err = tmp_path / "err"
    err.mkdir()
    c = np.arange(0.0, 331.0, 30.0)
    write_error_table(err / "C.csv", ErrorTable("C", c, {"EXC": 1e-3 * np.sin(np.radians(c))}))
    prog = tmp_path / "p.nc"
    prog.write_text("G0 X0 Y0 Z100 B0 C0\nG2 X10 Y10 R5\n")
    rc, so, se = cli("compensate", "DMU50", "--errors", err, prog, "--out", tmp_path / "o")
    assert rc == 2 and len(se.strip().splitlines()) == 1 and "line 2" in se, se
    rc, so, se = cli("tcpmap", "DMU50", "--errors", err, "--point", "0", "0", "0", "--out",
                     prog)
    assert rc == 2 and len(se.strip().splitlines()) == 1 and ".png" in se, se
    assert prog.read_text().startswith("G0")
    for args in (("compensate", "DMU50", "--errors", err, prog, "--out", tmp_path / "o",
                  "--plot", tmp_path / "q.nc"),
                 ("identify", "MB1", "--axis", "X", prog, "--out", tmp_path / "o",
                  "--plot", tmp_path / "p.svg")):
        rc, so, se = cli(*args)
        assert rc == 2 and len(se.strip().splitlines()) == 1 and ".png" in se, se
        assert not (tmp_path / "o").exists()
    prog.write_text("G0 X0 Y0 Z100 B0 C0\nG1 C345\n")
    rc, so, se = cli("compensate", "DMU50", "--errors", err, prog, "--out", tmp_path / "o")
    assert rc == 0 and "note:" in se, se


@settings(max_examples=30, deadline=None)
@given(st.integers(0, 2**32 - 1), st.sampled_from([1, 2, 3, 4]))
def test_linear_solve_by_adjugate_equals_lapack(seed, k):
    """The per-row solve of the linear-axis correction (adjugate for 3x3, LAPACK otherwise)
    against numpy.linalg.solve, on random well- and moderately-conditioned matrices; a singular
    matrix is refused like LAPACK refuses it."""
    from volerr.fiveaxis.compensate import solve_linear
    rng = np.random.default_rng(seed)
    j = rng.normal(size=(50, k, k)) + 3.0 * np.eye(k) * rng.uniform(0, 1, (50, 1, 1))
    r = rng.normal(size=(50, k))
    np.testing.assert_allclose(solve_linear(j, r), np.linalg.solve(j, r[:, :, None])[:, :, 0],
                               rtol=1e-9, atol=1e-9 * np.linalg.cond(j).max())
    j[7] = 0.0
    with pytest.raises(np.linalg.LinAlgError):
        solve_linear(j, r)
