"""Built-in five-axis example: a synthetic error set of thesis-like size and a finishing program.

* :func:`example_errors`: smooth component errors of every axis of a five-axis layout, with the
  magnitudes the thesis reports for the DMU 50 (ch. 4 and appendix B: positioning errors up to
  ~20 um on X and ~40 um on Y, straightness of a few um, angular errors up to ~250 urad,
  rotary-axis errors of some um and tens of urad), squareness and location errors.  Synthetic,
  deterministic (seeded), not measured data.
* :func:`hemisphere_program`: a G-code program that sweeps the tool tip over a hemisphere on the
  table with the tool axis along the surface normal, computed with the layout's nominal inverse
  kinematics (so it exercises both rotary axes over their range).
* :func:`write_example`: both, written to a folder (``errors/`` + ``hemisphere.nc``), for the
  demo and for trying ``volerr compensate`` and ``volerr tcpmap``.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from ..machine import iso_names
from ..errors import InputError
from ..fileio import write_text
from ..tables.table import ErrorTable, write_error_dir

#: (translational um, angular urad) amplitude per axis kind, thesis-like
_SCALE = {"linear": (8.0, 80.0), "rotary": (5.0, 30.0)}
_POSITIONING_UM = {"X": 20.0, "Y": 40.0, "Z": 15.0}


def example_errors(model, seed: int = 50, samples: int = 21) -> tuple[dict, dict]:
    """(tables axis -> ErrorTable, constants name -> mm | rad) for ``model``."""
    rng = np.random.default_rng(seed)
    tables = {}
    for a in model.axes:
        kind = "rotary" if a in model.rotary_axes else "linear"
        lo, hi = model.travel[a]
        periodic = kind == "rotary" and hi - lo > 360
        if periodic:
            lo, hi = 0.0, 360.0
        x = np.linspace(lo, hi, samples)
        t = (x - lo) / (hi - lo)
        vals = {}
        for p in model.layout.axes[a].component_errors:
            um, urad = _SCALE[kind]
            amp = urad * 1e-6 if iso_names.is_angle(p) else um * 1e-3
            if p == f"E{a}{a}" and a in _POSITIONING_UM:
                amp = _POSITIONING_UM[a] * 1e-3
            c = rng.uniform(-1, 1, 3)
            if periodic:
                v = amp * (0.6 * c[0] * np.sin(2 * np.pi * t + c[1]) + 0.3 * c[2] *
                           np.sin(4 * np.pi * t))
            else:
                v = amp * (0.7 * c[0] * t + 0.3 * c[1] * np.sin(np.pi * t * (2 + c[2])))
                v = v - v[0]  # zero at the reference position (start of travel)
            vals[p] = v
        tables[a] = ErrorTable(a, x, vals)
    constants = {}
    for p in model.parameters:
        if model.parameter_axis[p] is None:
            constants[p] = rng.uniform(-1, 1) * (15e-3 if iso_names.is_length(p) else 40e-6)
    return tables, constants


def hemisphere_program(model, radius: float = 40.0, center=(30.0, 20.0, 20.0), rings: int = 5,
                       points: int = 36, feed: float = 1500.0, crlf: bool = True) -> str:
    """G-code sweeping the tool tip over the upper hemisphere (tool axis = surface normal)."""
    c = np.asarray(center, dtype=float)
    end = "\r\n" if crlf else "\n"
    lines = ["%", "O5001 (HEMISPHERE FINISHING, TOOL AXIS NORMAL TO THE SURFACE)",
             "N10 G90 G21 G17 G40 G49 (absolute, metric)",
             f"N20 (sphere radius {radius:g} mm at x {c[0]:g} y {c[1]:g} z {c[2]:g})"]
    n = 30
    prev = None
    for r in range(rings):
        polar = np.deg2rad(15.0 + 60.0 * r / max(rings - 1, 1))
        az = np.deg2rad(np.linspace(0.0, 360.0, points, endpoint=False))
        nrm = np.column_stack([np.sin(polar) * np.cos(az), np.sin(polar) * np.sin(az),
                               np.full(points, np.cos(polar))])
        target = np.column_stack([c + radius * nrm, nrm])
        q = np.empty((points, len(model.axes)))
        for k in range(points):
            q[k] = model.inverse(target[k:k + 1], near=prev)[0]
            prev = q[k]
        for a in model.rotary_axes:  # whole turns off an endless axis: keep each ring in travel
            i = model.axes.index(a)
            lo, hi = model.travel[a]
            if hi - lo >= 720:
                q[:, i] -= 360.0 * np.round(q[:, i].mean() / 360.0)
        prev = q[-1]
        lines.append(f"N{n} (ring {r + 1}: polar angle {np.rad2deg(polar):.1f} deg)")
        n += 10
        for k in range(points):
            words = " ".join(f"{a}{v:.4f}" for a, v in zip(model.axes, q[k]))
            lines.append(f"N{n} {'G0' if k == 0 else 'G1'} {words}"
                         + (f" F{feed:g}" if k == 1 else ""))
            n += 10
    lines += [f"N{n} G0 Z{model.travel['Z'][1] - 1:.1f} ; retract", f"N{n + 10} M30", "%"]
    return end.join(lines) + end


def _inside(model, text: str) -> bool:
    from ..nc import gcode

    for b in gcode.blocks(gcode.parse(text), model.axes):
        for a, v in b.target.items():
            lo, hi = model.travel[a]
            if v is not None and not lo <= v <= hi:
                return False
    return True


def example_program(model, radius: float = 40.0) -> str:
    """:func:`hemisphere_program` at the first of a few centres where it stays in travel."""
    (xl, xh), (yl, yh), (zl, zh) = (model.travel[a] for a in ("X", "Y", "Z"))
    centres = [(30.0, 20.0, 20.0), (30.0, 20.0, 60.0), (0.0, 0.0, 120.0),
               (0.5 * (xl + xh), 0.5 * (yl + yh), zl + 2 * radius),
               (0.5 * (xl + xh), 0.5 * (yl + yh), 0.5 * (zl + zh))]
    for c in centres:
        text = hemisphere_program(model, radius, c)
        if _inside(model, text):
            return text
    raise InputError(f"{model.name}: no example hemisphere fits the travel")


def write_example(directory, layout: str = "DMU50") -> dict:
    """Write ``errors/`` and ``hemisphere.nc`` for ``layout`` into ``directory``; return paths."""
    from ..machine.model import load

    model = load(layout)
    d = Path(directory)
    tables, constants = example_errors(model)
    write_error_dir(d / "errors", tables, constants)
    prog = d / "hemisphere.nc"
    write_text(prog, example_program(model))
    return {"errors": d / "errors", "program": prog}
