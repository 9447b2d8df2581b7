"""Heidenhain plain language: a block with M92 is in coordinates relative to a position the
machine builder defines (not the machine datum, not the program's numbers): refused naming the
line; M91 (machine datum) passes by the work-offset rule (acceptance run
benchmarks/acceptance/nc_programs2)."""

import pytest

import volerr
from volerr.nc.heidenhain import parse_line


def test_m92_block_is_refused():
    with pytest.raises(volerr.errors.InputError, match="line 4: M92"):
        parse_line(4, "4 L Z+0 R0 FMAX M92", "\n")


def test_m91_block_passes_with_its_words():
    line = parse_line(4, "4 L Z+550 R0 FMAX M91", "\n")
    assert [(a, v) for a, v, _ in line.items()] == [("Z", 550.0), ("M", 91.0)]
