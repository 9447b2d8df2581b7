"""A length tolerance below any machine's in ``check --tolerance`` and ``history show
--tolerance`` (hostile-input acceptance, benchmarks/acceptance/hostile_inputs): ``EX0C=0.001
um`` and ``map=0.02 um`` were accepted (``iso230-2`` and ``iso10360`` already refused them);
now the same floor (:func:`volerr.units.check_tolerance_um`, 0.1 um) refuses them naming mm.
Angles and plausible lengths pass."""

from types import SimpleNamespace

import pytest

from volerr.check import _tolerance
from volerr.errors import InputError
from volerr.history.run import parse_tolerances

REF = SimpleNamespace(names=("EX0C", "EA0B"), units=("um", "urad"))


@pytest.mark.parametrize("text", ["EX0C=0.001 um", "map=0.02 um", "EX0C=50 nm"])
def test_check_length_below_any_machine(text):
    with pytest.raises(InputError, match="below any machine's tolerance"):
        _tolerance.parse(text, REF)


def test_check_plausible_limits_pass():
    assert _tolerance.parse("EX0C=20 um,EA0B=0.5 urad,map=30 um", REF) == {
        "EX0C": 20.0, "EA0B": 0.5, "map": 30.0}


def test_history_length_below_any_machine():
    with pytest.raises(InputError, match="likely meant in mm: write EX0C=0.001 mm"):
        parse_tolerances("EX0C=0.001 um")
    assert parse_tolerances("EX0C=20 um,EA0B=5 urad") == {"EX0C": (20.0, "um"),
                                                          "EA0B": (5.0, "urad")}
