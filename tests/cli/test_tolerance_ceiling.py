"""Tolerances and MPE beyond any machine, and a minus sign in an MPE (hostile-input acceptance,
RULE.md in benchmarks/acceptance/hostile_inputs): ``--tolerance A=12 mm`` and ``E=25000``
(um) were accepted and judged against; ``--mpe E0=-2+L/300`` was refused naming the format,
not the sign.  Each is refused with one line naming the likely unit or the sign; tolerances
up to the ceiling pass."""

import pytest

from volerr.conformance import parse_tolerances
from volerr.errors import InputError
from volerr.uncertainty.iso10360 import parse_spec
from volerr.units import TOLERANCE_CEILING_UM, check_tolerance_um

NAMES = ("A", "E", "M", "R", "B")


@pytest.mark.parametrize("text, likely", [("A=12 mm", "write A=12 um"),
                                          ("E=25000", "write E=25 um"),
                                          ("R=2e6 nm", "above any machine's tolerance")])
def test_tolerance_above_any_machine_refused(text, likely):
    with pytest.raises(InputError) as e:
        parse_tolerances(text, NAMES)
    assert likely in str(e.value) and "\n" not in str(e.value)


def test_tolerances_up_to_the_ceiling_pass():
    assert TOLERANCE_CEILING_UM == 1000.0
    assert parse_tolerances("A=1000,E=0.2 mm,M=20 um", NAMES) == {"A": 1000.0, "E": 200.0,
                                                                   "M": 20.0}
    assert check_tolerance_um(1000.0, "x") == 1000.0


def test_mpe_in_mm_for_um_refused():
    with pytest.raises(InputError, match="likely meant in um: write 2 um"):
        parse_spec("E0=2 mm+L/300", "--mpe")


@pytest.mark.parametrize("text", ["E0=-2+L/300", "E0=2+L/-300", "E0=2+L/300,PFTU=-1"])
def test_mpe_minus_sign_named(text):
    with pytest.raises(InputError, match="must be positive \\(a minus sign\\)"):
        parse_spec(text, "--mpe")
