"""Start-up of ``python -m volerr``: the parsers of every command are built without importing
any capability (issue 42 item 7).  ``volerr --help``, ``volerr CMD --help`` and the usage
errors need argparse only; numpy, scipy, SQLAlchemy, matplotlib, jinja2 and sympy are imported
when a command runs."""

import subprocess
import sys

import volerr
from volerr import choices

#: third-party packages no ``--help`` may import (each costs 0.05 .. 0.25 s CPU at start-up)
HEAVY = ("numpy", "scipy", "sqlalchemy", "matplotlib", "jinja2", "sympy", "pandas", "tqdm")

PROBE = """
import contextlib, io, sys
import volerr.cli as cli
for argv in (["--help"], ["history", "add", "--help"], ["calibrat"], ["map", "--jsn", "x"]):
    with contextlib.redirect_stdout(io.StringIO()), contextlib.redirect_stderr(io.StringIO()):
        cli.main(argv)
heavy = sorted({m.split(".")[0] for m in sys.modules} & set(sys.argv[1:]))
capabilities = sorted(m for m in sys.modules if m.startswith("volerr.")
                      and m.split(".")[1] not in ("cli", "choices", "errors", "fileio",
                                                  "progress", "units", "machine"))
print(" ".join(heavy + capabilities))
"""


def test_help_and_usage_errors_import_no_capability():
    proc = subprocess.run([sys.executable, "-c", PROBE, *HEAVY], capture_output=True, text=True)
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout.split() == [], f"imported at --help: {proc.stdout}"


def test_the_light_word_lists_are_the_capabilities_own():
    # one statement of each list: the capability names the very object the parser offers
    from volerr.cmm import diagonals
    from volerr.instruments import simulated_files
    from volerr.tables import functions
    from volerr.uncertainty import report

    assert functions.METHODS is choices.INTERPOLATION
    assert diagonals.KINDS is choices.DIAGONAL_KINDS
    assert report.BIAS_MODES is choices.BIAS_MODES
    assert simulated_files.INSTRUMENTS is choices.SIMULATED_INSTRUMENTS
    assert simulated_files.DEFAULT_PLANTED is choices.SIMULATED_PLANTED


def test_model_and_load_still_named_by_the_package():
    # Model and load are imported when first named, as the capabilities are
    from volerr.machine import model

    assert volerr.Model is model.Model and volerr.load is model.load
    from volerr.machine import Model, load

    assert Model is model.Model and load is model.load
    assert "Model" in dir(volerr)


ONE_COMMAND = """
import contextlib, io, sys
import volerr.cli as cli
with contextlib.redirect_stdout(io.StringIO()):
    code = cli.main(["history", "add", "--help"])
print(code, " ".join(sorted(m for m in sys.modules if m.startswith("volerr.cli."))))
"""


def test_a_command_builds_only_its_own_parser():
    proc = subprocess.run([sys.executable, "-c", ONE_COMMAND], capture_output=True, text=True)
    assert proc.returncode == 0, proc.stderr
    code, *modules = proc.stdout.split()
    assert code == "0"
    assert set(modules) <= {"volerr.cli._common", "volerr.cli._memory", "volerr.cli.history"}
    assert "volerr.cli.history" in modules


def _commands(parser) -> dict:
    import argparse

    sub = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
    return sub.choices


def test_the_parser_of_one_command_is_the_one_of_the_whole_parser():
    from volerr.cli import build_parser

    whole = _commands(build_parser())
    assert len(whole) >= 20
    for name, parser in whole.items():
        alone = _commands(build_parser(name))
        assert list(alone) == [name]
        assert alone[name].format_help() == parser.format_help(), name
    # not a command as typed (the module's name, an unknown word): every command
    assert len(_commands(build_parser("probe_cal"))) == len(whole)
    assert len(_commands(build_parser("mapp"))) == len(whole)
