"""Error directories for compensation tests: smooth random error tables and constants of a
layout's model, written in the project's error-directory format."""

from pathlib import Path

import numpy as np

from volerr.tables.table import ErrorTable, write_constants, write_error_table


def write_errors(d: Path, m, seed=0, scale_um=10.0, scale_urad=30.0, only=None):
    """Smooth random error tables over the whole travel (C: 0..360) and constants."""
    rng = np.random.default_rng(seed)
    d.mkdir(parents=True, exist_ok=True)
    for a in m.axes:
        lo, hi = m.travel[a]
        if a in m.rotary_axes and hi - lo > 360:
            lo, hi = 0.0, 360.0
        x = np.linspace(lo, hi, 25)
        t = (x - lo) / (hi - lo)
        vals = {}
        for p in m.layout.axes[a].component_errors:
            if only is not None and p not in only:
                continue
            s = (scale_urad * 1e-6) if p[1] in "ABC" else (scale_um * 1e-3)
            c = rng.normal(0, s, 3)
            v = c[0] * t + c[1] * np.sin(2 * np.pi * t) + c[2] * (t - 0.5) ** 2
            if a in m.rotary_axes and m.travel[a][1] - m.travel[a][0] > 360:
                v = c[0] * np.sin(2 * np.pi * t) + c[1] * np.cos(4 * np.pi * t)  # periodic
            vals[p] = v
        if vals:
            write_error_table(d / f"{a}.csv", ErrorTable(a, x, vals))
    consts = {p: rng.normal(0, 1e-3 * scale_um if p[1] in "XYZ" else 1e-6 * scale_urad)
              for p in m.parameters if m.parameter_axis[p] is None}
    if only is not None:
        consts = {k: v for k, v in consts.items() if k in only}
    if consts:
        write_constants(d / "constants.csv", consts)
    return d
