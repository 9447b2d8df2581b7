"""``volerr check --tolerance`` read by the one parser of every ``--tolerance``
(:func:`volerr.units.parse_assignments`) with the one name rule
(:func:`volerr.units.match_name`): pairs separated by ``,`` ``;`` or ``|``, the unit after a
blank or directly; a name as written, or in any case when that names exactly one; a name
that is two known names ignoring case, and neither exactly, refused (never a guess)."""

from __future__ import annotations

from types import SimpleNamespace

import pytest

from volerr.check._tolerance import parse
from volerr.errors import InputError

REF = SimpleNamespace(names=["EX0C", "EA0B", "EXX@slope"], units=["um", "urad", "um/mm"])


@pytest.mark.parametrize("text", ["EX0C=30 um;EA0B=40 urad", "ex0c=30um|ea0b=40 urad",
                                  "EX0C=0.03 mm, EA0B=40urad"])
def test_the_forms_of_every_tolerance(text):
    assert parse(text, REF) == pytest.approx({"EX0C": 30.0, "EA0B": 40.0}, rel=1e-12)


def test_map_in_any_case_and_a_slope_in_its_own_unit():
    assert parse("MAP=30 um|EXX@slope=2 um/mm", REF) == {"map": 30.0, "EXX@slope": 2.0}


@pytest.mark.parametrize("text, words", [
    ("EX0C=22", "--tolerance EX0C=22: the value needs its unit"),
    ("EX0C=2 um/mm", "--tolerance EX0C=2 um/mm: unit 'um/mm' unknown"),
    ("FOO=3 um", "--tolerance: 'FOO' is neither 'map' nor a parameter of the reference "
                 "(EX0C, EA0B, EXX@slope ...)"),
    ("EX0C=30 um,ex0c=3 um", "--tolerance: ex0c given twice"),
    ("EX0C=-3 um", "--tolerance: EX0C = '-3 um' must be a positive number"),
])
def test_refusals_are_one_line(text, words):
    with pytest.raises(InputError) as e:
        parse(text, REF)
    assert str(e.value).startswith(words) and "\n" not in str(e.value), str(e.value)


def test_a_name_two_known_names_ignoring_case_is_refused():
    ref = SimpleNamespace(names=["EXa", "EXA"], units=["um", "um"])
    assert parse("EXa=3 um,EXA=4 um", ref) == {"EXa": 3.0, "EXA": 4.0}
    with pytest.raises(InputError, match="'exa' is any of EXa, EXA ignoring case"):
        parse("exa=3 um", ref)
    from volerr.units import match_name

    assert match_name("a", "AEMRB", "--tolerance") == "A"
    assert match_name("Q", "AEMRB", "--tolerance") is None
