"""issue 42 item 4: a command is argparse + one API call, so the API refuses the same bad
input with the same one-line message the command prints (``volerr CMD: error: MESSAGE``)."""

import pytest

from helpers.refusals import api_error, command_error


@pytest.mark.parametrize("magnify", ["-1", "0"])
def test_map_magnify_refused_alike(magnify, capsys):
    from volerr.cmm.api import error_map

    said = command_error(["map", "MB1", "--errors", "nowhere", "--magnify", magnify], capsys)
    assert "--magnify" in said and "positive" in said
    assert api_error(lambda: error_map("MB1", "nowhere", magnify=float(magnify))) == said


def test_derive_without_a_layout_refused_alike(capsys):
    from volerr.machine.derivation import derive_request

    said = command_error(["derive"], capsys)
    assert "--all" in said
    assert api_error(lambda: derive_request([])) == said


def test_derive_in_package_with_out_refused_alike(capsys, tmp_path):
    from volerr.machine.derivation import derive_request

    said = command_error(["derive", "MB1", "--in-package", "--out", str(tmp_path)], capsys)
    assert "--in-package" in said and "--out" in said
    assert api_error(lambda: derive_request(["MB1"], out=tmp_path, in_package=True)) == said


def test_unknown_format_section_refused_alike(capsys):
    from volerr.formats_doc import section

    said = command_error(["formats", "no-such-section"], capsys)
    assert "no-such-section" in said and "tables" in said
    assert api_error(lambda: section("no-such-section")) == said


def test_at_parsed_and_refused_by_the_units_helper():
    from volerr.units import parse_at

    assert parse_at(["B=30", " C =-90.5"]) == {"B": 30.0, "C": -90.5}
    assert parse_at(None) == {}
    assert "AXIS=VALUE" in api_error(lambda: parse_at(["B30"]))
    assert "'x' is not a number" in api_error(lambda: parse_at(["B=x"]))


def test_at_refused_by_diagonals_as_by_the_helper(capsys):
    from volerr.units import parse_at

    said = command_error(["diagonals", "MB1", "--errors", "nowhere", "--at", "B30"], capsys)
    assert api_error(lambda: parse_at(["B30"])) == said
