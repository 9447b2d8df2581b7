"""Every ``--tolerance`` is read by one parser (:func:`volerr.units.parse_assignments`):
``volerr iso230-2`` and ``volerr history show`` take the same forms -- pairs separated by
``,`` ``;`` or ``|``, ``NAME=VALUE UNIT`` with the unit after a blank or directly (``5um``),
any unit of the quantity's kind converted.  A bare number is um in ``iso230-2`` (every ISO
230-2 quantity is a length in um) and refused in ``history show`` (parameters in different
units), each saying so in its ``--help``."""

from __future__ import annotations

import json

import pytest

from tests.cli.test_shop_defects import write_run
from volerr.cli import main
from volerr.conformance import parse_tolerances as iso230_2_tolerances
from volerr.errors import InputError
from volerr.history.run import parse_tolerances as history_tolerances

FORMS = ("A=10um|E=8um", "A=10 um; E=0.008mm", "A=10000nm,E=8 um")


@pytest.mark.parametrize("text", FORMS)
def test_same_forms_in_both(text):
    assert iso230_2_tolerances(text, "AEMRB") == pytest.approx({"A": 10.0, "E": 8.0},
                                                               rel=1e-12)
    got = history_tolerances(text)
    assert list(got) == ["A", "E"]
    assert [v for v, _ in got.values()] == pytest.approx(
        [{"um": 10.0, "nm": 10000.0}[got["A"][1]], {"um": 8.0, "mm": 0.008}[got["E"][1]]])


def test_bare_number_um_in_iso230_2_refused_in_history():
    assert iso230_2_tolerances("A=10", "AEMRB") == {"A": 10.0}
    with pytest.raises(InputError, match="needs its unit"):
        history_tolerances("A=10")


def test_iso230_2_command_takes_a_bar_separated_list(tmp_path, capsys):
    run = write_run(tmp_path / "run.csv")
    out = tmp_path / "o.json"
    assert main(["iso230-2", str(run), "--tolerance", "A=10|E=8um", "--json", str(out)]) == 0
    assert json.loads(out.read_text())["tolerance_um"] == {"A": 10.0, "E": 8.0}
    capsys.readouterr()
    for args in (["iso230-2", "--help"], ["history", "show", "--help"]):
        try:
            main(args)
        except SystemExit:
            pass
        text = " ".join(capsys.readouterr().out.split())
        assert "separated by , ; or |" in text and "bare number" in text
