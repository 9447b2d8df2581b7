"""A European comma decimal (``X300,5``) is refused naming the comma, also in a Fanuc-style
program where the decimal-less rule would otherwise name ``X300`` (acceptance run
benchmarks/acceptance/nc_programs2)."""

import pytest

import volerr
from volerr.nc import dialect, gcode


def test_comma_decimal_is_named():
    with pytest.raises(volerr.errors.InputError, match=r"line 2: X300,5\.\.\.: a comma is no "
                                                       r"decimal point"):
        gcode.blocks(gcode.parse("G21 G90\nG0 X300,5 Y400. Z150.\n"), ("X", "Y", "Z"))


def test_decimal_less_rule_leaves_a_comma_decimal_to_the_tokenizer():
    dialect.refuse_decimal_less(["%\n", "O4005\n", "G0 X300,5 Y400. Z150.\n"])
