"""Fanuc decimal-less numbers: ``X300`` is 300 mm or 0.300 mm by parameter 3401#0 DPI, which a
program does not say.  A Fanuc-style program (a program-number line ``O1234``) with a nonzero
axis or arc number without a decimal point is refused naming the line and the word, unless
``--decimal-less mm`` states the reading; zero (``Z0``), words in comments, ``N F S T H D M G
P`` words and programs without an O number are read as before (acceptance run
benchmarks/acceptance/nc_programs2)."""

import pytest
from helpers.error_dirs import write_errors

import volerr
from volerr.fiveaxis.program import compensate_program
from volerr.nc import dialect
from volerr.tables.functions import ErrorFunctions

FANUC = "%\nO4001 (POST)\nN10 G21 G90 G0 X300. Y400. Z0\nN20 G1 Z100. F500\nN30 X350\nM30\n%\n"


@pytest.fixture(scope="module")
def fb2(tmp_path_factory):
    m = volerr.load("FB2")
    return m, ErrorFunctions.from_dir(write_errors(tmp_path_factory.mktemp("e") / "err", m), m)


def test_fanuc_style_decimal_less_word_is_refused_naming_line_and_word(fb2):
    with pytest.raises(volerr.errors.InputError, match=r"line 5: X350 has no decimal point"):
        compensate_program(*fb2, FANUC)


def test_stated_reading_compensates_it_as_mm(fb2):
    out = compensate_program(*fb2, FANUC, decimal_less="mm").text.splitlines()
    assert out[4].startswith("N30 X350.0") or out[4].startswith("N30 X349.9"), out[4]


@pytest.mark.parametrize("text", [
    "%\nO4001\nG0 X300. Y400. Z0 (X350 in a comment) ; Y20\nG4 P500\nT6 M6 H6 D6 F500 S8000\n",
    "%\nG0 X300 Y400 Z150\nX350\n",         # no O number: LinuxCNC / Siemens read mm
])
def test_what_is_not_ambiguous_passes(text):
    lines = text.splitlines(keepends=True)
    if dialect.fanuc_style(lines):
        dialect.refuse_decimal_less(lines)


def test_refusal_line_number_counts_from_the_chunk_start():
    with pytest.raises(volerr.errors.InputError, match=r"line 12: Y-2 has no decimal point"):
        dialect.refuse_decimal_less(["G0 X1.\n", "(c)\n", "G1 Y-2\n"], first=10)


@pytest.mark.parametrize("ending", ["\n", "\r\n", "\r"])
def test_refusal_line_number_for_every_line_ending(ending, fb2):
    # a program with CR endings (old controllers' editors) named line 1 before
    text = FANUC.replace("\n", ending)
    with pytest.raises(volerr.errors.InputError, match=r"line 5: X350 has no decimal point"):
        compensate_program(*fb2, text)
