"""Option values typed in the wrong unit (issue 43, "never a confident wrong answer"): the
plausibility checks of :mod:`volerr.units` behind --material-temp-C, --cte-ppm-per-K,
--part-cte, --tolerance / --mpe constants, --probe and --tool.

Expected values are derived here from the physics (68 degF = 20 degC, 11.5 ppm/K = 1.15e-5
1/K, 100 mm = 1e5 um), not read from the code.  Each refusal is one InputError line naming the
option and the likely unit; each correct value passes unchanged."""

from __future__ import annotations

import pytest

from volerr.errors import InputError
from volerr.units import (check_cte, check_offset_mm, check_temperature_C,
                          check_tolerance_um, check_tool_offset)


@pytest.mark.parametrize("value", [20.0, 23.5, -5.0, 45.0, 79.0])
def test_a_temperature_in_degC_passes(value):
    assert check_temperature_C(value, "--x") == value


def test_a_temperature_in_degF_names_fahrenheit_and_its_degC():
    with pytest.raises(InputError) as e:
        check_temperature_C(68.0, "--material-temp-C", (-10.0, 50.0))
    line = str(e.value)
    assert "\n" not in line and "--material-temp-C" in line
    assert "degF" in line and f"{(68.0 - 32.0) * 5.0 / 9.0:.1f} degC" in line


def test_a_temperature_in_kelvin_is_not_called_fahrenheit():
    with pytest.raises(InputError) as e:
        check_temperature_C(293.15, "--t")      # (293.15 - 32) * 5/9 = 145 degC: not degF
    assert "degF" not in str(e.value) and "degC" in str(e.value)


@pytest.mark.parametrize("ppm", [11.5, 0.5, 23.0, -0.3, 0.0, 0.02])
def test_a_material_expansion_coefficient_in_ppm_passes(ppm):
    assert check_cte(ppm, "--cte-ppm-per-K") == ppm


def test_a_coefficient_in_per_kelvin_typed_for_ppm_is_refused():
    with pytest.raises(InputError) as e:
        check_cte(11.5e-6, "--cte-ppm-per-K")
    line = str(e.value)
    assert "--cte-ppm-per-K" in line and "1/K" in line and "11.5 ppm/K" in line


def test_ppm_typed_where_per_kelvin_is_asked_is_refused():
    assert check_cte(11.5e-6, "--part-cte", "1/K") == 11.5e-6
    with pytest.raises(InputError) as e:
        check_cte(11.5, "--part-cte", "1/K")
    line = str(e.value)
    assert "--part-cte" in line and "ppm/K" in line and "1.15e-05 1/K" in line


def test_a_tolerance_below_any_machine_is_taken_for_mm():
    assert check_tolerance_um(2.0, "--tolerance A=2") == 2.0
    with pytest.raises(InputError) as e:
        check_tolerance_um(0.012, "--tolerance A=0.012")
    assert "0.012 mm" in str(e.value)


def test_an_offset_longer_than_the_machine_is_taken_for_um():
    assert check_offset_mm((0, 0, -100), "--probe", 1000.0) == (0.0, 0.0, -100.0)
    with pytest.raises(InputError) as e:
        check_offset_mm((0, 0, -100000), "--probe", 1000.0)   # 100 mm typed in um
    line = str(e.value)
    assert "--probe" in line and "um" in line and "100000 mm" in line


def test_a_tool_offset_pointing_into_the_spindle_is_taken_for_the_sign():
    assert check_tool_offset((0, 0, -85), "--tool", 1000.0) == (0.0, 0.0, -85.0)
    assert check_tool_offset((5, 0, 0), "--tool", 1000.0) == (5.0, 0.0, 0.0)
    with pytest.raises(InputError) as e:
        check_tool_offset((0, 0, 85), "--tool", 1000.0)
    line = str(e.value)
    assert "--tool" in line and "sign" in line and "0 0 -85" in line
