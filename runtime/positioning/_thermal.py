"""Correction of a positioning run to the reference temperature 20 degC (ISO 1, ISO 230-2).

ISO 1 fixes 20 degC as the temperature at which dimensions are defined; ISO 230-2 lets a run
made at another temperature be corrected with the nominal expansion of the machine's scale
(or of the workpiece/material the interferometer's material sensor sits on).

Formula and sign convention
---------------------------
The interferometer (air-compensated) measures true length.  A scale with coefficient of
expansion ``alpha`` at temperature ``T`` is longer by ``alpha (T - 20) L``, so a machine that is
perfect at 20 degC overshoots a target ``P`` by ``alpha (T - 20) (P - P_ref)``: its deviation
(actual minus target) is positive when it is warm and ``alpha > 0``.  The deviation it would show
at 20 degC is::

    x_20 = x - alpha * (T - 20 degC) * (P - P_ref)

``x``, ``x_20`` in mm, ``alpha`` in 1/K (``cte_ppm_per_K * 1e-6``; ppm/K = um/m/K), ``T`` the
material temperature of that reading (degC), ``P`` the target and ``P_ref`` the reference
position (mm) where the expansion is zero: the scale's fixed point, or where the
interferometer reading was set to zero (default 0 mm).  With one temperature for the whole run,
changing ``P_ref`` only shifts every deviation by the same amount, which changes the mean
deviations but none of A, B, E, M, R.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

import numpy as np

from ..errors import require
from ..units import UM_PER_MM

from ._io import PositioningRun

REFERENCE_C = 20.0


@dataclass(frozen=True)
class ThermalCorrection:
    """What :func:`correct_to_20C` did: coefficient (ppm/K), reference position (mm), the
    material temperature range (degC) and the correction range (um) over all readings."""

    cte_ppm_per_K: float
    reference_mm: float
    temperature_C: tuple        # (min, mean, max)
    correction_um: tuple        # (min, max) of -alpha (T - 20) (P - P_ref)
    source: str                 # "column" (per reading) or "option" (one value for the run)

    def as_dict(self) -> dict:
        return {"applied": True, "reference_C": REFERENCE_C,
                "cte_ppm_per_K": self.cte_ppm_per_K, "reference_mm": self.reference_mm,
                "temperature_C": {"min": self.temperature_C[0], "mean": self.temperature_C[1],
                                  "max": self.temperature_C[2]},
                "temperature_source": self.source,
                "correction_um": {"min": self.correction_um[0], "max": self.correction_um[1]},
                "formula": "x_20 = x - cte * (T - 20 C) * (P - P_ref)"}


def correct_to_20C(run: PositioningRun, cte_ppm_per_K: float, temperature_C: float | None = None,
                   reference_mm: float = 0.0) -> tuple[PositioningRun, ThermalCorrection]:
    """The run with every deviation corrected to 20 degC (formula in the module docstring).

    ``temperature_C``: one material temperature for the whole run, used when the file has no
    temperature column (giving both is refused).  Returns (corrected run, what was done)."""
    import math

    from ..units import MATERIAL_TEMPERATURE_RANGE_C, check_cte, check_temperature_C

    check_cte(cte_ppm_per_K, "--cte-ppm-per-K")
    require(math.isfinite(reference_mm), "--cte-reference-mm must be a finite number")
    w = run.source or "positioning run"
    if run.temperature is not None:
        require(temperature_C is None, f"{w}: the file has a material temperature column; "
                                       f"--material-temp-C would override it: give only one")
        T, source = run.temperature, "column"
    else:
        require(temperature_C is not None,
                f"{w}: --cte-ppm-per-K needs the material temperature: a T_C column or "
                f"--material-temp-C")
        check_temperature_C(temperature_C, "--material-temp-C", MATERIAL_TEMPERATURE_RANGE_C)
        T, source = np.full(run.deviation.shape, float(temperature_C)), "option"
    P = run.targets[:, None, None]
    corr = -cte_ppm_per_K * 1e-6 * (T - REFERENCE_C) * (P - reference_mm)   # mm
    out = replace(run, deviation=run.deviation + corr, temperature=T.copy())
    info = ThermalCorrection(float(cte_ppm_per_K), float(reference_mm),
                             (float(T.min()), float(T.mean()), float(T.max())),
                             (float(corr.min() * UM_PER_MM), float(corr.max() * UM_PER_MM)), source)
    return out, info
