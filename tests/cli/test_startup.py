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
