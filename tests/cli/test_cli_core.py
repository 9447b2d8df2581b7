"""Command line basics: layouts, derive, load, and bad input (exit 2, one line, no traceback)."""

import subprocess
import sys

import pytest

import volerr


def run(*args, cwd=None):
    return subprocess.run([sys.executable, "-m", "volerr", *args], capture_output=True,
                          text=True, cwd=cwd)


def assert_clean_failure(proc, fragment=""):
    assert proc.returncode == 2, proc.stderr
    lines = [ln for ln in proc.stderr.splitlines() if ln.strip()]
    assert len(lines) == 1, proc.stderr
    assert "Traceback" not in proc.stderr
    assert fragment.lower() in lines[0].lower()


def test_layouts_lists_the_ten_cmms():
    names = run("layouts").stdout.split()
    for n in ["MB1", "MB2", "FB1", "FB2", "MH1", "MH2", "FH1", "FH2", "CX", "CY"]:
        assert n in names
    assert names == volerr.layouts()


def test_layouts_long_one_complete_block_each():
    blocks = run("layouts", "--long").stdout.strip().split("\n\n")
    assert [b.split()[0] for b in blocks] == volerr.layouts()
    for b, name in zip(blocks, volerr.layouts()):
        lay = volerr.load(name).layout
        for a in lay.axis_names:  # every axis with its travel
            assert f"  {a}: " in b and " travel " in b.split(f"  {a}: ")[1].splitlines()[0]
        assert b.rstrip().endswith(".")  # the whole description, not its first sentence


def test_unknown_layout():
    assert_clean_failure(run("derive", "MB9", "--out", "x"), "unknown layout")
    with pytest.raises(volerr.InputError):
        volerr.load("MB9")


BAD_LAYOUTS = {
    "unknown axis": ('name = "T"\n[axes.Q]\nkind = "linear"\ndirection = [1,0,0]\n'
                     'travel = [0, 1]\n[chain]\ntool = ["Q"]\n', "unknown axis"),
    "cycle": ('name = "T"\n[axes.X]\nkind = "linear"\ndirection = [1,0,0]\ntravel = [0, 1]\n'
              '[chain]\ntool = ["X", "X"]\n', "twice"),
    "missing transform": ('name = "T"\n[axes.X]\nkind = "linear"\ndirection = [1,0,0]\n'
                          'travel = [0, 1]\n[chain]\ntool = ["X", "spindle"]\n', "missing"),
    "not toml": ("name = [", "TOML"),
    "zero direction": ('name = "T"\n[axes.X]\nkind = "linear"\ndirection = [0,0,0]\n'
                       'travel = [0, 1]\n[chain]\ntool = ["X"]\n', "zero"),
    "bad squareness": ('name = "T"\n[axes.X]\nkind = "linear"\ndirection = [1,0,0]\n'
                       'travel = [0, 1]\n[chain]\ntool = ["X"]\n[squareness]\nEC0Y = "Z"\n',
                       "squareness"),
    "undeclared name in a frame": ('name = "T"\n[axes.X]\nkind = "linear"\ndirection = [1,0,0]\n'
                                   'travel = [0, 1]\n[frames.ram]\ntranslation = [0, 0, "q"]\n'
                                   '[chain]\ntool = ["X", "ram"]\n', "unknown name 'q'"),
    "bad expression in a frame": ('name = "T"\n[axes.X]\nkind = "linear"\ndirection = [1,0,0]\n'
                                  'travel = [0, 1]\n[frames.ram]\ntranslation = [0, 0, "2*("]\n'
                                  '[chain]\ntool = ["X", "ram"]\n', "not a valid expression"),
}


@pytest.mark.parametrize("case", sorted(BAD_LAYOUTS))
def test_malformed_layout_files(tmp_path, case):
    text, fragment = BAD_LAYOUTS[case]
    path = tmp_path / "bad.toml"
    path.write_text(text)
    out = tmp_path / "out"
    assert_clean_failure(run("derive", str(path), "--out", str(out)), fragment)
    assert path.read_text() == text and not out.exists()


def test_derive_layout_file_on_the_fly(tmp_path):
    src = (volerr.machine.layout.shipped_layout_dir() / "MB1.toml").read_text()
    path = tmp_path / "mine.toml"
    path.write_text(src.replace('name = "MB1"', 'name = "MINE"'))
    m = volerr.load(str(path))
    assert m.parameters == volerr.load("MB1").parameters
    proc = run("derive", str(path), "--out", str(tmp_path / "gen"))
    assert proc.returncode == 0 and (tmp_path / "gen" / "mine.py").exists()


def test_layout_file_with_a_fixed_frame_offset(tmp_path):
    """A fixed frame f between X and Z is a lever for the X and Y rotations only: the custom
    machine with probe p equals MB1 with probe p + f for X/Y errors, and MB1 for Z errors."""
    import numpy as np

    src = (volerr.machine.layout.shipped_layout_dir() / "MB1.toml").read_text()
    src = src.replace('name = "MB1"', 'name = "RAM"').replace(
        'tool = ["Y", "X", "Z"]', 'tool = ["Y", "X", "ram", "Z"]').replace(
        "[chain]", '[parameters]\nh = 100\n\n[frames.ram]\ntranslation = [50, -30, "2*h"]\n\n[chain]')
    path = tmp_path / "ram.toml"
    path.write_text(src)
    m, mb1 = volerr.load(str(path)), volerr.load("MB1")
    rng = np.random.default_rng(4)
    pos = rng.uniform(0, 400, (20, 3))
    f, p = np.array([50.0, -30.0, 200.0]), np.array([10.0, -20.0, -150.0])
    exy = {k: rng.normal(size=20) * (1e-3 if k[1] in "XYZ" else 1e-5)
           for k in m.parameters if k[-1] in "XY" and "0" not in k}
    exy["EC0Y"] = 1e-5
    np.testing.assert_allclose(m.volumetric_error(pos, exy, probe=p),
                               mb1.volumetric_error(pos, exy, probe=p + f), atol=1e-15)
    ez = {k: rng.normal(size=20) * 1e-5 for k in m.parameters if k[-1] == "Z" and "0" not in k}
    ez.update(EB0Z=2e-5, EA0Z=-3e-5)
    np.testing.assert_allclose(m.volumetric_error(pos, ez, probe=p),
                               mb1.volumetric_error(pos, ez, probe=p), atol=1e-15)
    np.testing.assert_allclose(m.nominal_position(pos, p), mb1.nominal_position(pos, p) + f,
                               atol=1e-9)


def test_bad_positions_and_errors_raise_input_error():
    import numpy as np

    m = volerr.load("MB1")
    with pytest.raises(volerr.InputError, match="NaN"):
        m.volumetric_error(np.array([[np.nan, 0, 0]]), {})
    with pytest.raises(volerr.InputError, match="unknown error parameter"):
        m.volumetric_error(np.zeros((1, 3)), {"EXQ": 1.0})
    with pytest.raises(volerr.InputError, match="columns"):
        m.volumetric_error(np.zeros((1, 2)), {})
    with pytest.raises(volerr.InputError, match="unknown axis"):
        m.volumetric_error({"X": 0, "Y": 0, "Z": 0, "B": 0}, {})


def test_api_input_forms_and_non_numbers():
    """Positions as lists, one point, names in any case give the same numbers; anything that
    is not numbers (or positions of different lengths, sigmas < 0) raises InputError."""
    import numpy as np

    m = volerr.load("MB1")
    assert volerr.load("mb1").name == "MB1"
    pos = np.array([[100.0, 200.0, 300.0], [800.0, 20.0, 10.0]])
    errs = {"EXX": [1e-3, 2e-3], "EBX": 1e-5, "EC0Y": 2e-5}
    want = m.volumetric_error(pos, errs, probe=(1.0, 2.0, -30.0))
    got = m.volumetric_error({"x": pos[:, 0].tolist(), "y": pos[:, 1], "Z": pos[:, 2]},
                             {k.lower(): v for k, v in errs.items()}, probe=[1, 2, -30])
    np.testing.assert_array_equal(got, want)
    one = m.volumetric_error(pos[1].tolist(), {"EXX": 2e-3, "EBX": 1e-5, "EC0Y": 2e-5},
                             probe=[1, 2, -30])
    np.testing.assert_allclose(one, want[1:], rtol=1e-15)
    bad = [lambda: m.volumetric_error([["a", 1, 2]], {}),
           lambda: m.volumetric_error({"X": "a", "Y": 1, "Z": 2}, {}),
           lambda: m.volumetric_error(pos, {"EXX": "abc"}),
           lambda: m.volumetric_error(pos, {}, probe=("a", 0, 0)),
           lambda: m.volumetric_error(pos, [1, 2]),
           lambda: m.volumetric_error({"X": [1, 2], "Y": [1, 2, 3], "Z": 0}, {}),
           lambda: m.volumetric_error({"X": 1, "x": 2, "Y": 0, "Z": 0}, {}),
           lambda: m.random_error(pos, {"EXX": -1e-3}),
           lambda: m.transfer({"EXX": 1e-3}, (0, 0, "a")),
           lambda: m.volumetric_error(pos, {}, direction=("a", 0, 1), probe_error=1e-3),
           lambda: m.volumetric_error(pos, {}, direction=(0, 0, 1), probe_error=[1, 2, 3]),
           lambda: m.volumetric_error(pos, {}, direction=(0, 1), probe_error=1e-3)]
    for call in bad:
        with pytest.raises(volerr.InputError):
            call()


#: ``main([NAME, "--help"])`` of every command in ONE fresh interpreter (a subprocess per
#: command cost 0.8 s each, 26 commands): exit code and stdout of each, as JSON
_EVERY_HELP = """
import contextlib, io, json, sys
from volerr.cli import main
out = {}
for name in json.loads(sys.argv[1]):
    buf = io.StringIO()
    with contextlib.redirect_stdout(buf):
        try:
            code = main([name, "--help"])
        except SystemExit as e:
            code = e.code
    out[name] = [code, buf.getvalue()]
print(json.dumps(out))
"""


def test_help_for_every_command():
    import json

    from volerr.cli import build_parser

    parser = build_parser()
    sub = next(a for a in parser._actions if a.dest == "command")
    assert {"layouts", "derive"} <= set(sub.choices)
    names = list(sub.choices)
    proc = subprocess.run([sys.executable, "-c", _EVERY_HELP, json.dumps(names)],
                          capture_output=True, text=True)
    assert proc.returncode == 0, proc.stderr
    got = json.loads(proc.stdout)
    assert list(got) == names
    for name, (code, text) in got.items():
        assert code in (0, None) and "usage" in text.lower(), (name, code, text[-500:])
    # and the entry point itself, once: python -m volerr NAME --help
    proc = run(names[-1], "--help")
    assert proc.returncode == 0 and "usage" in proc.stdout.lower()


@pytest.mark.parametrize("argv", [["layouts", "--bogus"], [], ["map"],
                                  ["identify", "MB1", "x.csv"], ["derive", "--nope"]])
def test_usage_errors_are_one_line(argv):
    assert_clean_failure(run(*argv), "error")


def test_outputs_have_the_umask_permissions(tmp_path):
    """Atomic writes go through a private temporary file; the result must not stay 0600."""
    import os
    import stat

    from volerr.fileio import write_text

    mask = os.umask(0o022)
    try:
        p = write_text(tmp_path / "a.csv", "x\n")
        assert stat.S_IMODE(p.stat().st_mode) == 0o644
    finally:
        os.umask(mask)
