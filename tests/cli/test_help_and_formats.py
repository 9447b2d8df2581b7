"""Help texts a user without the source can read, and the file formats shipped with volerr."""

from __future__ import annotations

import argparse
import re
from pathlib import Path

import pytest

from volerr.cli import COMMANDS, build_parser, main

ROOT = Path(__file__).resolve().parents[2]


def _subparsers():
    parser = build_parser()
    sub = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
    out = {}
    for name, p in sub.choices.items():
        out[name] = p
        for a in p._actions:  # controller export / import
            if isinstance(a, argparse._SubParsersAction):
                out.update({f"{name} {k}": v for k, v in a.choices.items()})
    return out


PARSERS = _subparsers()


def test_every_command_module_is_registered():
    assert {c.replace("_", "-") for c in COMMANDS} <= set(PARSERS)


@pytest.mark.parametrize("name", sorted(PARSERS))
def test_help_is_plain_text_with_defaults_and_points_to_the_formats(name):
    p = PARSERS[name]
    text = p.format_help()
    assert "``" not in text and not re.search(r":(mod|func|class|meth):`", text), text
    assert "INTERFACE.md" not in text
    assert "volerr formats" in text
    help_of = {}
    for a in p._actions:
        if a.option_strings and a.help is not argparse.SUPPRESS:
            help_of[a.dest] = a
    for dest, a in help_of.items():
        if a.default in (None, False, argparse.SUPPRESS, []) or dest == "help":
            continue
        # the option's own lines in the help must state its default
        shown = p._get_formatter()._get_help_string(a) % {"default": a.default}
        assert "default" in shown.lower(), f"{name} {a.option_strings[0]}: no default shown"
        if isinstance(a.default, (int, float, str)) and not isinstance(a.default, bool):
            value = f"{a.default:g}" if isinstance(a.default, float) else str(a.default)
            assert value in shown, f"{name} {a.option_strings[0]}: {shown}"


def test_vector_options_accept_both_syntaxes(capsys):
    from volerr.cli._common import parse_vector

    assert parse_vector(["1", "2", "3"], "--p") == parse_vector(["1,2,3"], "--p") \
        == parse_vector(["1,", "2", "3"], "--p") == (1.0, 2.0, 3.0)
    for bad in (["1", "2"], ["1,2,3,4"], ["1", "inf", "2"], ["1e300", "0", "0"], ["a", "b", "c"]):
        code = main(["map", "MB1", "--errors", "nowhere", "--probe", *bad])
        err = capsys.readouterr().err
        assert code == 2 and len(err.strip().splitlines()) == 1 and "--probe" in err


def test_formats_document_is_shipped_and_identical_to_docs():
    from volerr.cli.formats import text

    assert text() == (ROOT / "docs" / "formats.md").read_text(encoding="utf-8")


@pytest.mark.parametrize("name", ["tables", "tracker", "sphere", "deviations", "loop-json",
                                  "layout", "gcode", "controller", "uncertainty", "iso230-2",
                                  "outputs"])
def test_formats_command_prints_each_section(name, capsys):
    assert main(["formats", name]) == 0
    out = capsys.readouterr().out
    assert out.startswith("## ") and len(out.splitlines()) > 8
    assert main(["formats"]) == 0
    assert name in capsys.readouterr().out


def test_formats_lists_every_recognised_covariate_column():
    """The deviations section names every covariate column the loop's candidate search knows."""
    from volerr.cli.formats import sections
    from volerr.loop import candidates

    text = sections()["deviations"][1]
    for col in (*candidates._TIME, *candidates._GROUP,
                *(c for trio in candidates._PROBE_DIRS for c in trio), "T_C", "dir_<A>"):
        assert f"`{col}`" in text, col


def test_unknown_format_section_is_one_line(capsys):
    assert main(["formats", "nope"]) == 2
    assert "sections:" in capsys.readouterr().err


def test_readme_has_no_missing_file_and_python_version():
    readme = (ROOT / "README.md").read_text()
    assert "INTERFACE.md" not in readme
    assert "3.11" in readme and "venv" in readme
    assert "volerr-demo/" in (ROOT / ".gitignore").read_text()


def test_layouts_long_shows_travel_points_and_parameters(capsys):
    assert main(["layouts", "--long"]) == 0
    out = capsys.readouterr().out
    dmu = out[out.index("DMU50"):].split("\n\n")[0]
    assert "travel -250 .. 250 mm" in dmu and "through (0, 0, d) mm" in dmu
    assert "d = 154.996 mm" in dmu and "X = X_t - 250 mm" in dmu


def test_readme_python_example_runs(tmp_path, monkeypatch, capsys):
    """The README's Python example (load a model, read an error folder, evaluate 10 points and
    their random error) runs as printed; its numbers agree with the model called by hand."""
    import numpy as np

    readme = (ROOT / "README.md").read_text()
    code = re.search(r"```python\n(.*?)```", readme, re.S).group(1)
    assert "ErrorFunctions.from_dir" in code and "random_error" in code
    monkeypatch.chdir(tmp_path)
    ns = {}
    exec(compile(code, "README.md", "exec"), ns)
    out = capsys.readouterr().out
    assert len(out.strip().splitlines()) == 10
    m, q = ns["m"], ns["q"]
    assert q.shape == (10, 3) and ns["e"].shape == (10, 3) and np.all(ns["r"] > 0)
    # the first component of the first point, from the errors evaluated independently
    import volerr
    from volerr.tables import read_error_dir

    tables, _ = read_error_dir(tmp_path / "errors_MH2", m.axes)
    exx = np.interp(q[:, 0], tables["X"].positions, tables["X"].values["EXX"])
    assert np.allclose(ns["funcs"](q)["EXX"], exx)
    assert ns["e"].shape == volerr.load("MH2").volumetric_error(q, ns["funcs"](q)).shape
