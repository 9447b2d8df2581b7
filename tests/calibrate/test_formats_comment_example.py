"""formats.md ("Comment lines") shows the ``#`` lines ``volerr calibrate --errors-out`` writes
above ``constants.csv``; they are the lines the command writes for the shipped sphere example
(``volerr calibrate DMU50 sphere_example_DMU50.csv --errors-out DIR``).  The page showed
"-18.1 +- 0.22 um", the command writes "-18.1 +- 0.41 um" (journey pass, 2026-12-07)."""

from __future__ import annotations

from pathlib import Path

from volerr.cli import main
from volerr.example_files import shipped_path

PAGE = Path(__file__).resolve().parents[2] / "docs" / "formats.md"


def test_the_page_shows_the_lines_calibrate_writes(tmp_path):
    out = tmp_path / "ce"
    assert main(["calibrate", "DMU50", str(shipped_path("sphere_example_DMU50.csv")),
                 "--errors-out", str(out)]) == 0
    lines = (out / "constants.csv").read_text(encoding="utf-8").splitlines()[:3]
    page = PAGE.read_text(encoding="utf-8")
    block = "\n".join("    " + ln for ln in lines)
    assert block in page, block
