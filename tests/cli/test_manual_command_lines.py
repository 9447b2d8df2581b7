"""Every full command line the manual shows parses with volerr's own parser: the indented
command lines of README.md and docs/*.md, and the command line (with options) heading a row of
docs/benchmarks.md (which says a reader can rerun it).  The benchmarks page showed ``volerr map MH2 --grid 100
--out map.csv`` (no ``--errors``: exit 2) and ``volerr plan MB1 --instrument ballbar`` (no
``--readings``, ``--out``: exit 2) (journey pass, 2026-12-07)."""

from __future__ import annotations

import re
import shlex
from pathlib import Path

import pytest

from volerr.cli import build_parser

ROOT = Path(__file__).resolve().parents[2]
PAGES = [ROOT / "README.md", *sorted((ROOT / "docs").glob("*.md"))]


def _indented_lines():
    for page in PAGES:
        for line in page.read_text(encoding="utf-8").splitlines():
            for part in re.split(r"\s*&&\s*", line.strip()):
                if line.startswith("    ") and part.startswith("volerr "):
                    yield page.name, part


def _benchmark_rows():
    for line in (ROOT / "docs" / "benchmarks.md").read_text(encoding="utf-8").splitlines():
        m = re.match(r"\| `(volerr [^`]+)`", line)
        if m and " --" in m.group(1):     # a command line, not a row's name ("volerr loop")
            yield "benchmarks.md", m.group(1)


CASES = sorted(set(_indented_lines()) | set(_benchmark_rows()))


def test_the_manual_shows_command_lines():
    assert len(CASES) >= 10


@pytest.mark.parametrize("page,line", CASES)
def test_command_line_parses(page, line):
    argv = shlex.split(line)[1:]
    try:
        build_parser().parse_args(argv)
    except SystemExit as exc:
        pytest.fail(f"{page}: `{line}` does not parse (exit {exc.code})")
