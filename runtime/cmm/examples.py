"""Built-in example error sets, modelled on the two CMMs of Pahk (1995), sec. 4.

The paper prints only summary figures of its measured data, so the example sets are
*synthetic*: smooth, deterministic functions whose peak-to-peak bands, repeatabilities and
squareness values are the printed ones where the paper gives them, and plausible values
elsewhere.  They are demonstration data, not the paper's measurements; the diagonals computed
from them are therefore not expected to equal the paper's printed diagonals.

``MB1`` -- CMM A (moving bridge, 900 x 575 x 400 mm), 17 parameters as the paper counts them:

* positioning EXX (band 6.15 um, printed), EYY (23.0 um, printed), EZZ (4.0 um);
* straightness EYX, EZX, EXY, EZY (bands 3, 4, 5, 6 um);
* angular EAX EBX ECX EAY EBY ECY EAZ; the X pitch EBX has the printed band 11.18 urad, the
  others 4 .. 8 urad.  (The paper does not say which seven of the nine were measured; the Z
  angular errors act only through a probe offset in this layout);
* squareness as printed, XY 14.1, XZ 56.4, YZ -32 urad, i.e. alpha, beta1, beta2, converted to
  ISO names through the layout's ``paper_symbols`` (MB1: EC0Y = alpha, EB0Z = -beta1,
  EA0Z = beta2);
* repeatability: the paper states it as the largest 2 sigma over the positions: 10.75 um (EXX),
  21.0 um (EYY), 12.30 urad (EBX); in the example sigma is zero at the reference position
  (every run is zeroed there) and grows like sqrt(distance) to that value at the end of
  travel (``_s_`` columns: repeatability of one reading).

``MH2`` -- CMM B (moving horizontal arm, 1100 mm cube), 10 parameters:

* positioning EXX (band 71.0 um, repeatability 3.1 um, printed), EZZ (14.5 um, 1.9 um,
  printed), EYY (18 um, 2.0 um);
* angular: the printed pitch about Y (EBX, band 39.0 urad, repeatability 4.3 urad) and ECX,
  EAZ, ECZ (bands 20, 15, 12 urad, repeatability 2 urad): errors of the column and carriage
  that the horizontal arm turns into Abbe errors;
* squareness as printed, XY 43.2, YZ -48.9, ZX 108.9 urad (alpha, beta2, beta1).

All tables start at zero error and zero standard deviation at the first position (the
reference of a laser measurement); repeatability grows with sqrt(distance) as above.
"""

from __future__ import annotations

import numpy as np

from ..machine import iso_names
from ..units import MM_PER_UM, RAD_PER_URAD
from ..errors import InputError
from ..tables.table import ErrorTable, write_error_dir

#: per layout: axis -> (step mm, {name: (band, repeatability_2sigma or None)}) in um / urad;
#: constants: paper symbol -> value (urad)
SPECS = {
    "MB1": {
        "seed": 1995,
        "tables": {
            "X": (50.0, {"EXX": (6.15, 10.75), "EYX": (3.0, None), "EZX": (4.0, None),
                         "EAX": (6.0, None), "EBX": (11.18, 12.30), "ECX": (5.0, None)}),
            "Y": (25.0, {"EYY": (23.0, 21.0), "EXY": (5.0, None), "EZY": (6.0, None),
                         "EAY": (8.0, None), "EBY": (7.0, None), "ECY": (6.0, None)}),
            "Z": (25.0, {"EZZ": (4.0, None), "EAZ": (4.0, None)}),
        },
        "squareness": {"alpha": 14.1, "beta1": 56.4, "beta2": -32.0},
    },
    "MH2": {
        "seed": 1996,
        "tables": {
            "X": (50.0, {"EXX": (71.0, 3.1), "EBX": (39.0, 4.3), "ECX": (20.0, 2.0)}),
            "Y": (50.0, {"EYY": (18.0, 2.0)}),
            "Z": (50.0, {"EZZ": (14.5, 1.9), "EAZ": (15.0, 2.0), "ECZ": (12.0, 2.0)}),
        },
        "squareness": {"alpha": 43.2, "beta1": 108.9, "beta2": -48.9},
    },
}

EXAMPLES = tuple(SPECS)


def _smooth(rng, t: np.ndarray, band: float) -> np.ndarray:
    """A smooth curve on t in [0, 1], zero at t = 0, peak-to-peak ``band``."""
    trend = rng.uniform(-1.0, 1.0)
    y = trend * t
    for k in range(1, 5):
        y = y + rng.normal(0.0, 0.6 / k) * np.sin(np.pi * k * t + rng.uniform(0, 2 * np.pi))
    y = y - y[0]
    return y * (band / np.ptp(y))


def _paper_to_iso(paper_symbols: dict, squareness: dict) -> dict:
    """Printed squareness (paper symbols, urad) -> ISO name -> value in rad, signs from the layout."""
    out = {}
    for iso, sym in paper_symbols.items():
        sign, bare = (-1.0, sym[1:]) if sym.startswith("-") else (1.0, sym.lstrip("+"))
        if bare in squareness:
            out[iso] = sign * squareness[bare] * RAD_PER_URAD
    return out


def example_errors(layout: str = "MB1"):
    """-> (tables {axis: ErrorTable}, constants {name: rad}) of a built-in example set."""
    if layout not in SPECS:
        raise InputError(f"no built-in example error set for {layout!r} (have {', '.join(EXAMPLES)})")
    from ..machine.layout import read_layout
    lay = read_layout(layout)
    spec = SPECS[layout]
    rng = np.random.default_rng(spec["seed"])
    tables = {}
    for ax, (step, params) in spec["tables"].items():
        lo, hi = lay.axes[ax].travel
        x = np.linspace(lo, hi, int(round((hi - lo) / step)) + 1)
        t = (x - lo) / (hi - lo)
        values, std = {}, {}
        for name, (band, rep) in params.items():
            scale = MM_PER_UM if iso_names.is_length(name) else RAD_PER_URAD
            values[name] = np.round(_smooth(rng, t, band), 4) * scale
            if rep is not None:
                std[name] = np.round((rep / 2.0) * np.sqrt(t), 4) * scale
        tables[ax] = ErrorTable(ax, x, values, s=std)  # repeatability of one reading
    constants = _paper_to_iso(lay.paper_symbols, spec["squareness"])
    return tables, constants


def write_example_errors(directory, layout: str = "MB1", inputs=()):
    """Write the example error set of ``layout`` as an error directory (X.csv ... constants.csv)."""
    tables, constants = example_errors(layout)
    return write_error_dir(directory, tables, constants, inputs=inputs)
