"""Correction to 20 degC: x_20 = x - cte (T - 20) (P - P_ref)."""

from __future__ import annotations

import numpy as np
import pytest

from volerr.errors import InputError
from volerr.positioning import PositioningRun, correct_to_20C, evaluate

TARGETS = np.array([0.0, 250.0, 500.0, 750.0, 1000.0])


def warm_perfect_run(T, cte_ppm=11.5, p_ref=0.0, with_column=True):
    """A machine perfect at 20 degC, its steel scale at T: it overshoots by cte (T-20)(P-P_ref)."""
    over_mm = cte_ppm * 1e-6 * (T - 20.0) * (TARGETS - p_ref)          # exact, by hand
    dev = np.repeat(np.repeat(over_mm[:, None, None], 2, axis=1), 3, axis=2)
    dev = dev + np.array([0.3, -0.2, 0.1])[None, None, :] * 1e-3        # some scatter
    temp = np.full(dev.shape, float(T)) if with_column else None
    return PositioningRun("X", TARGETS, ("1", "2", "3"), dev, temp)


def test_warm_perfect_machine_corrects_to_zero_systematic_error():
    run = warm_perfect_run(25.0)
    # at 1000 mm and +5 K a steel scale reads 57.5 um short: the raw run shows it
    assert evaluate(run).figures_um()["E_um"] == pytest.approx(11.5 * 5 * 1.0, abs=1e-9)
    out, info = correct_to_20C(run, 11.5)
    f = evaluate(out).figures_um()
    assert f["E_um"] == pytest.approx(0.0, abs=1e-9)
    assert f["M_um"] == pytest.approx(0.0, abs=1e-9)
    assert info.correction_um == pytest.approx((-57.5, 0.0))
    assert info.temperature_C == (25.0, 25.0, 25.0)
    assert info.source == "column"


def test_per_reading_temperature_and_reference_position():
    run = warm_perfect_run(25.0, p_ref=100.0)
    T = run.temperature.copy()
    T[:, :, 2] = 23.0    # third cycle colder
    run = PositioningRun("X", run.targets, run.cycles, run.deviation, T)
    out, _ = correct_to_20C(run, 11.5, reference_mm=100.0)
    expected = run.deviation - 11.5e-6 * (T - 20.0) * (TARGETS[:, None, None] - 100.0)
    assert np.allclose(out.deviation, expected, atol=1e-15)


def test_reference_position_only_shifts_a_constant_temperature_run():
    run = warm_perfect_run(27.0, with_column=False)
    a, _ = correct_to_20C(run, 11.5, temperature_C=27.0, reference_mm=0.0)
    b, info = correct_to_20C(run, 11.5, temperature_C=27.0, reference_mm=400.0)
    fa, fb = evaluate(a).figures_um(), evaluate(b).figures_um()
    for k in ("A_um", "B_um", "E_um", "M_um", "R_um"):
        assert fb[k] == pytest.approx(fa[k], abs=1e-9)
    # shift = cte (T - 20) * 400 mm = 11.5 * 7 * 0.4 um
    assert np.allclose(b.deviation - a.deviation, 11.5 * 7 * 0.4e-3, atol=1e-12)
    assert info.source == "option"


def test_missing_or_double_temperature_refused():
    with pytest.raises(InputError, match="material temperature"):
        correct_to_20C(warm_perfect_run(25.0, with_column=False), 11.5)
    with pytest.raises(InputError, match="give only one"):
        correct_to_20C(warm_perfect_run(25.0), 11.5, temperature_C=25.0)
