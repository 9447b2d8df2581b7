"""ISO names parsed once (kinds against the ISO 230-1 grammar written out here), generated
PARAMETER_KIND, the unit factors and the one number parser/formatter."""

import pytest

import volerr
from volerr.errors import InputError
from volerr.machine import iso_names
from volerr.units import MM_PER_UM, UM_PER_MM, URAD_PER_RAD, format_number, parse_number


@pytest.mark.parametrize("name,kind,length", [
    ("EXX", "translational", True), ("EZY", "translational", True),
    ("EAX", "angular", False), ("ECZ", "angular", False),
    ("EC0Y", "squareness", False), ("EA0Z", "squareness", False),
    ("EX0C", "location", True), ("EB0C", "location", False),
    ("KT_X", "effect", False), ("RV_X", "effect", False)])
def test_iso_name_kinds(name, kind, length):
    parsed = iso_names.parse(name)
    assert parsed.kind == kind and parsed.is_length == length
    assert parsed.is_angle == (kind in ("angular", "squareness") or
                               (kind == "location" and name[1] in "ABC"))


@pytest.mark.parametrize("layout", ["MB1", "DMU50", "TT_AC"])
def test_generated_parameter_kind_matches_the_names(layout):
    m = volerr.load(layout)
    kinds = m.parameter_kind
    assert set(kinds) == set(m.parameters)
    for p, k in kinds.items():
        if len(p) == 3:
            assert k == ("translational" if p[1] in "XYZ" else "angular")
        elif p in ("EC0Y", "EB0Z", "EA0Z"):
            assert k == "squareness"
        else:
            assert k == "location" and p[2] == "0"


def test_unit_factors_and_number_text():
    assert UM_PER_MM * MM_PER_UM == 1.0 and URAD_PER_RAD == 1e6
    assert parse_number(" 2.5e-3 ") == 0.0025
    for bad, msg in (("abc", "not a number"), ("1,5", "decimal comma"), ("nan", "NaN"),
                     ("", "empty")):
        with pytest.raises(InputError, match=msg):
            parse_number(bad, "f.csv:3", "EXX_um")
    assert format_number(-0.0) == "0" and format_number(1 / 3, 4) == "0.3333"
    assert float(format_number(123.456789012345)) == pytest.approx(123.456789012345, rel=1e-11)


def test_probe_and_tool_name_the_same_offset():
    m = volerr.load("TT_AC")
    q = [[10.0, -20.0, 30.0, 15.0, 40.0]]
    a = m.forward(q, probe=(0, 0, 100.0))
    b = m.forward(q, tool=(0, 0, 100.0))
    c = m.forward(q, (0, 0, 100.0))
    assert (a == b).all() and (a == c).all()
    with pytest.raises(InputError):
        m.forward(q, probe=(0, 0, 1.0), tool=(0, 0, 1.0))
