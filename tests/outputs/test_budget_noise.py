"""A budget's rounding noise is printed as 0, a small real contribution as itself: the
printed ballbar budgets read "6.16e-15 µrad" for a source the quantity does not depend on."""

import pytest

from volerr.report.content import NOISE, budget_rows


def _budget(tiny: float) -> dict:
    return {"unit": "urad", "u": 2.0, "U": 4.0, "k": 2.0, "sources": [
        {"source": "noise", "u": tiny, "unit": "urad", "sensitivity": 1.0,
         "contribution": tiny},
        {"source": "reading", "u": 2.0, "unit": "urad", "sensitivity": 1.0,
         "contribution": 2.0}]}


def test_rounding_noise_printed_as_zero_a_real_source_as_itself():
    noise = budget_rows(_budget(6.16e-15))[1]
    assert noise[1] == "0" and noise[4] == "0"
    real = budget_rows(_budget(100 * NOISE * 2.0))[1]      # 2e-7 urad: small, but real
    assert float(real[4]) == pytest.approx(100 * NOISE * 2.0, rel=1e-3)


def test_a_source_in_another_unit_is_left_as_given():
    b = _budget(6.16e-15)
    b["sources"][0]["unit"] = "um"
    assert float(budget_rows(b)[1][1]) == 6.16e-15
