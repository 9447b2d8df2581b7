"""Set-up shared by the result-contract modules (test_result_contract, test_budget_contract:
one xdist group, ``api_examples``)."""

from __future__ import annotations

import pytest


@pytest.fixture(scope="session")
def ex(tmp_path_factory):
    """The shipped examples, a reference calibration (DMU50 sphere) and a history store: one
    folder per test process, read by both contract modules (neither writes into it: their
    outputs go to ``tmp_path``)."""
    import volerr
    from volerr.cli import main
    from volerr.example_files import write_examples

    d = tmp_path_factory.mktemp("contract")
    write_examples(d)
    assert main(["calibrate", "DMU50", str(d / "sphere_example_DMU50.csv"), "--json",
                 str(d / "cal.json")]) == 0
    volerr.history.add(str(d / "h.sqlite"), "M1", [str(d / "cal.json")])
    return d
