"""A command line without surprises (issue 23): one spelling per option, help on every option
with its default shown once, --version, "did you mean", ';' read by every CSV reader, no silent
folder creation, no replaced file without --force, stale staging folders of dead runs removed,
implausible numbers in a program refused."""

from __future__ import annotations

import argparse
import os
import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from volerr.cli import build_parser, main
from volerr.fileio import Outputs, staging_prefix, write_text
from volerr.errors import InputError


def run(capsys, *argv):
    code = main([str(a) for a in argv])
    out, err = capsys.readouterr()
    return code, out, err


def one_line_error(code, err):
    assert code == 2, err
    assert "Traceback" not in err
    assert len(err.strip().splitlines()) == 1, err


def files_in(d) -> set:
    return {str(p.relative_to(d)) for p in d.rglob("*")}


def _parsers(parser, name="volerr"):
    yield name, parser
    for a in parser._actions:
        if isinstance(a, argparse._SubParsersAction):
            for n, child in a.choices.items():
                yield from _parsers(child, f"{name} {n}")


# ---------------------------------------------------------------------------------------------
def test_every_option_of_every_command_has_help_and_its_default_once():
    checked = 0
    for name, p in _parsers(build_parser()):
        fmt = p._get_formatter()
        visible = {a.dest for a in p._actions if a.help is not argparse.SUPPRESS}
        for a in p._actions:
            if isinstance(a, (argparse._SubParsersAction, argparse._HelpAction)):
                continue
            if a.help is argparse.SUPPRESS:   # a hidden old spelling of a visible option
                assert a.dest in visible, f"{name} {a.option_strings}: hidden, no alias of"
                continue
            text = fmt._expand_help(a) if a.help else ""
            assert text.strip(), f"{name} {a.option_strings or a.dest}: no help"
            assert len(re.findall(r"default", text, re.I)) <= 1, f"{name}: {text}"
            assert not re.search(r"default:\s*\)", text), f"{name}: empty default: {text}"
            if a.option_strings and a.default not in (None, False, [], argparse.SUPPRESS):
                # the default is shown (by the formatter or in the text), exactly once
                assert "default" in text.lower(), f"{name} {a.option_strings}: {text}"
            checked += 1
    assert checked > 150


def test_the_same_thing_has_one_option_name_everywhere():
    """--errors-out for an error folder written, --json/--plot/--html never required."""
    for name, p in _parsers(build_parser()):
        for a in p._actions:
            if "--json" in a.option_strings or "--html" in a.option_strings:
                assert not a.required, f"{name}: {a.option_strings} required"
            if a.dest == "errors_out":
                assert "--errors-out" in a.option_strings and a.metavar == "DIR", name
    # the old spellings still work as aliases
    sub = {n: p for n, p in _parsers(build_parser())}
    for cmd, old in (("volerr iso230-2", "--table-out"), ("volerr squareness", "--out"),
                     ("volerr controller import", "--out")):
        act = sub[cmd]._option_string_actions[old]
        assert act.dest == "errors_out", (cmd, old)
    assert sub["volerr tcpmap"]._option_string_actions["--out"].dest == "plot"


def test_version_and_did_you_mean(capsys):
    from volerr import __version__

    with pytest.raises(SystemExit) as exc:
        build_parser().parse_args(["--version"])
    assert exc.value.code == 0
    assert capsys.readouterr().out.strip() == f"volerr {__version__}"
    code, _, err = run(capsys, "mapp")
    one_line_error(code, err)
    assert "did you mean 'map'" in err
    code, _, err = run(capsys, "map", "MB1", "--errros", "x")
    one_line_error(code, err)
    assert "--errros" in err and "did you mean --errors" in err
    code, _, err = run(capsys, "iso230-2", "r.csv", "--tolerence", "A=1")
    one_line_error(code, err)
    assert "did you mean --tolerance" in err
    code, _, err = run(capsys, "controller", "exprt")
    one_line_error(code, err)
    assert "did you mean 'export'" in err


# ---------------------------------------------------------------------------------------------
def _semicolons(src, dst):
    dst.write_text(Path(src).read_text().replace(",", ";"))


def test_semicolon_separated_files_read_like_commas(inputs, tmp_path):
    from volerr.cmm.examples import write_example_errors
    from volerr.identify.inputs import read_rounds
    from volerr.probe.calibration import read_sphere_csv
    from volerr.tables import ErrorFunctions
    from volerr.uncertainty.tasks import read_task

    comma, semi = tmp_path / "c", tmp_path / "s"
    write_example_errors(comma, "MB1")
    semi.mkdir()
    for f in comma.iterdir():
        _semicolons(f, semi / f.name)
    assert ";" in (semi / "X.csv").read_text().splitlines()[0]
    q = np.array([[100.0, 200.0, 300.0], [450.0, 50.0, 12.0]])
    a, b = ErrorFunctions.from_dir(comma, "MB1"), ErrorFunctions.from_dir(semi, "MB1")
    for k, v in a(q).items():
        assert np.array_equal(v, b(q)[k]), k
    for k, v in a.sigmas(q).items():
        assert np.array_equal(v, b.sigmas(q)[k]), k
    # tracker data, probing data and a task: the same numbers either way
    _semicolons(inputs["tracker"], tmp_path / "t.csv")
    r1 = read_rounds([inputs["tracker"]], "csv", None, None)
    r2 = read_rounds([tmp_path / "t.csv"], "csv", None, None)
    assert np.array_equal(r1[0].points, r2[0].points)
    _semicolons(inputs["sphere"], tmp_path / "sph.csv")
    s1, s2 = read_sphere_csv(inputs["sphere"]), read_sphere_csv(tmp_path / "sph.csv")
    assert np.array_equal(s1.points, s2.points)
    _semicolons(inputs["task"], tmp_path / "task.csv")
    import volerr
    axes = volerr.load("MB1").axes
    t1, t2 = read_task(inputs["task"], axes), read_task(tmp_path / "task.csv", axes)
    for a in axes:
        assert np.array_equal(t1.positions[a], t2.positions[a])


# ---------------------------------------------------------------------------------------------
def test_a_mistyped_output_folder_is_refused_not_created(inputs, tmp_path, capsys):
    code, _, err = run(capsys, "map", "MB1", "--errors", inputs["errors"],
                       "--plot", tmp_path / "typo" / "m.png")
    one_line_error(code, err)
    assert "does not exist" in err and "typo" in err
    code, _, err = run(capsys, "squareness", "MB1", inputs["errors"],
                       "--errors-out", tmp_path / "missing" / "sq")
    one_line_error(code, err)
    assert files_in(tmp_path) == set()
    # an output folder itself is created when its parent exists
    code, _, err = run(capsys, "squareness", "MB1", inputs["errors"],
                       "--errors-out", tmp_path / "sq")
    assert code == 0, err
    assert (tmp_path / "sq" / "constants.csv").is_file()


def test_a_folder_output_never_replaces_a_file_without_force(inputs, tmp_path, capsys):
    out = tmp_path / "sq"
    out.mkdir()
    (out / "X.csv").write_text("the user's own table\n")
    code, _, err = run(capsys, "squareness", "MB1", inputs["errors"], "--errors-out", out)
    one_line_error(code, err)
    assert "X.csv" in err and "--force" in err
    assert files_in(out) == {"X.csv"} and (out / "X.csv").read_text() == "the user's own table\n"
    # the old spelling, with --force: replaced
    code, _, err = run(capsys, "squareness", "MB1", inputs["errors"], "--out", out, "--force")
    assert code == 0, err
    assert (out / "X.csv").read_text().startswith("X,")
    # controller import into a folder that holds a table
    from volerr.tables.controller import write_isg
    from volerr.tables.table import read_error_dir

    tables, (consts, _, _) = read_error_dir(inputs["errors"], ("X", "Y", "Z"))
    isg = tmp_path / "m.isg.csv"
    write_text(isg, write_isg("MB1", tables, consts))
    code, _, err = run(capsys, "controller", "import", "MB1", isg, "--out", out)
    one_line_error(code, err)
    assert "exists already" in err
    # a folder whose file names are known only at the end (the demo): refused at commit,
    # nothing moved, the staging removed
    (tmp_path / "d").mkdir()
    (tmp_path / "d" / "map_MB1.csv").write_text("mine")
    plan = Outputs().folder("--out", tmp_path / "d")
    with pytest.raises(InputError, match="map_MB1.csv"):
        with plan:
            write_text(plan.path("--out") / "map_MB1.csv", "demo")
            write_text(plan.path("--out") / "index.html", "demo")
    assert files_in(tmp_path / "d") == {"map_MB1.csv"}
    assert (tmp_path / "d" / "map_MB1.csv").read_text() == "mine"


def test_stale_staging_folders_of_dead_runs_are_removed(inputs, tmp_path, capsys):
    dead = subprocess.Popen([sys.executable, "-c", "pass"])
    dead.wait()
    me = staging_prefix()
    stale = tmp_path / (me.replace(f"-{os.getpid()}@", f"-{dead.pid}@") + "abc123de")
    alive = tmp_path / (me + "zz99yy88")          # this process: alive, kept
    other = tmp_path / ".volerr-staging-x7kq2m1a"  # no owner in the name: kept
    for d in (stale, alive, other):
        (d / ".volerr-folder-0").mkdir(parents=True)
        (d / ".volerr-folder-0" / "X.csv").write_text("partial")
    code, _, err = run(capsys, "map", "MB1", "--errors", inputs["errors"],
                       "--json", tmp_path / "m.json")
    assert code == 0, err
    assert not stale.exists() and alive.exists() and other.exists()
    assert (tmp_path / "m.json").is_file()


def test_implausible_numbers_in_a_program_are_refused(inputs, tmp_path, capsys):
    from volerr.cmm.examples import write_example_errors

    write_example_errors(tmp_path / "e", "MB1")
    for line, word in (("G1 X1e300", "X1e300"), ("G1 X2.5E-3 Y3", "X2.5E-3")):
        prog = tmp_path / "p.nc"
        prog.write_text(f"G1 X10 Y10 Z10\n{line}\n")
        code, _, err = run(capsys, "compensate", "MB1", "--errors", tmp_path / "e", prog,
                           "--out", tmp_path / "o.nc")
        one_line_error(code, err)
        assert word in err and "line 2" in err
    prog.write_text("G1 X10 Y10 Z10\nG1 X100000000000\n")
    code, _, err = run(capsys, "compensate", "MB1", "--errors", tmp_path / "e", prog,
                       "--out", tmp_path / "o.nc", "--ignore-travel", "--extrapolate")
    one_line_error(code, err)
    assert "implausibly large" in err
    assert not (tmp_path / "o.nc").exists()
    # an E word of its own (a blank before it) is no number of the X word
    prog.write_text("G1 X10 Y10 Z10 (1e5 in a comment)\nG1 X20 E5\n")
    code, _, err = run(capsys, "compensate", "MB1", "--errors", tmp_path / "e", prog,
                       "--out", tmp_path / "o.nc")
    assert code == 0, err
