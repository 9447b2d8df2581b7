"""Observation equations of the measuring instruments (sympy).

Every instrument a calibration engineer uses reads a function of the *actual* tool point of the
machine and of a few set-up unknowns of its own (where the pivot ball really is, the bar's real
length, the sphere's real centre ...).  Written with

* ``t = (tx, ty, tz)``: the nominal tool point in the workpiece frame (mm), from the layout's
  nominal chain at the commanded positions;
* ``e = (ex, ey, ez)``: the volumetric error there, actual minus nominal (mm), which the
  layout's generated ``sensitivity`` gives as a linear function of the error parameters;
* the instrument's known geometry (pivot, nominal length, sphere centre ..., mm);
* its set-up unknowns ``s`` (mm or rad),

a reading is ``y = f(t + e, geometry, s)``.  This module states ``f`` for each instrument and
derives, by differentiation at ``e = 0, s = 0``:

* ``nominal``: ``f(t, geometry, 0)``, the reading of the nominal machine;
* ``projection``: ``df/de`` (readings x 3): how the instrument sees the volumetric error;
* ``setup``: ``df/ds`` (readings x set-up unknowns).

To first order ``y = nominal + projection @ e + setup @ s``, and since ``e`` is the layout's
sensitivity times the parameters, ``projection @ sensitivity`` is the instrument's row of the
design for any layout, shipped or a user's file.  The generated module
``volerr.generated.instruments`` holds one function per instrument returning the array
``(readings, 1 + 3 + n_setup, *shape)``: column 0 the nominal reading, columns 1-3 the
projection, then the set-up columns in the order of ``SETUP[kind]``.

Instruments (signs and frames stated once, here):

``ballbar``
    telescoping ballbar (ISO 230-4, ISO 10791-6): one reading, the bar length minus the nominal
    length ``L``: ``|t + e - (p + dp)| - L + dL``; ``p`` the nominal centre of the
    workpiece-side (pivot) ball, ``dp`` its unknown offset, ``dL`` the unknown length offset of
    the bar (zero error of the transducer / calibrator).
``sphere``
    touch probe on a sphere, or R-test: three readings, the tool point minus the sphere centre
    in the workpiece frame, ``t + e - (c + dc)``; ``c`` the nominal centre, ``dc`` the unknown
    offset of the placement.  (A reading given in the machine's linear-axis frame is this
    vector rotated by the orientation of the workpiece frame, which the layout's generated
    ``work_rotation`` gives; that rotation is applied by the runtime.)
``deviations``
    a CMM against a reference, or a laser tracker, reading the 3-D deviation of the tool point:
    ``t + e - t``; its set-up (the instrument's rigid placement) acts through the chain and is
    the layout's generated ``setup_sensitivity`` (not a function of ``t`` alone).
"""

from __future__ import annotations

import hashlib
from pathlib import Path

import sympy as sp

from .codegen import Function, render_module

TOOL = sp.Matrix(sp.symbols("tx ty tz", real=True))
ERROR = sp.Matrix(sp.symbols("ex ey ez", real=True))


def _vec(names: str) -> sp.Matrix:
    return sp.Matrix(sp.symbols(names, real=True))


def ballbar():
    """(geometry symbols, set-up symbols, reading expressions) of a telescoping ballbar."""
    pivot = _vec("px py pz")
    length = sp.Symbol("L", positive=True)
    dp = _vec("dpx dpy dpz")
    dl = sp.Symbol("dL", real=True)
    r = TOOL + ERROR - (pivot + dp)
    reading = sp.sqrt(r.dot(r)) - length + dl
    return [*pivot, length], [*dp, dl], sp.Matrix([reading])


def sphere():
    """(geometry symbols, set-up symbols, reading expressions) of a sphere probed at the tool
    point (touch probe cycle or R-test), in the workpiece frame."""
    centre = _vec("cx cy cz")
    dc = _vec("dcx dcy dcz")
    return [*centre], [*dc], TOOL + ERROR - (centre + dc)


#: instrument kind -> its observation equation
INSTRUMENTS = {"ballbar": ballbar, "sphere": sphere}
#: instrument kind -> names of its set-up unknowns in the generated column order
SETUP = {"ballbar": ("pivot_dx", "pivot_dy", "pivot_dz", "length"),
         "sphere": ("centre_dx", "centre_dy", "centre_dz")}


def linearised(kind: str) -> tuple[list, sp.Matrix]:
    """(geometry symbols, matrix (readings, 1 + 3 + n_setup)) of an instrument: nominal
    reading, projection d/de and set-up columns d/ds, all at ``e = 0, s = 0``."""
    geometry, setup, reading = INSTRUMENTS[kind]()
    at_zero = {**{s: 0 for s in ERROR}, **{s: 0 for s in setup}}
    cols = [reading.subs(at_zero)]
    cols += [reading.diff(s).subs(at_zero) for s in ERROR]
    cols += [reading.diff(s).subs(at_zero) for s in setup]
    out = sp.Matrix.hstack(*cols).applyfunc(sp.simplify)
    return geometry, out


def functions() -> list[Function]:
    out = []
    for kind in INSTRUMENTS:
        geometry, m = linearised(kind)
        rows, cols = m.shape
        out.append(Function(
            kind, [str(s) for s in [*TOOL, *geometry]], list(m),
            f"{kind}: array ({rows}, {cols}, *shape) -- per reading: nominal reading (mm), "
            f"projection of the volumetric error (3 columns, mm/mm), set-up columns "
            f"{', '.join(SETUP[kind])} (mm/mm).", shape=(rows, cols)))
    return out


def source_sha256() -> str:
    """sha256 of this derivation's source text (recorded in the generated header)."""
    return hashlib.sha256(Path(__file__).read_bytes()).hexdigest()


def generate_module() -> str:
    """Text of ``generated/instruments.py`` (deterministic; registered in ``derive --all``)."""
    header = {
        "title": "Observation equations of the measuring instruments, linearised.",
        "layout": "--all",
        "layout_file": "derive/observations.py",
        "sha256": source_sha256(),
        "sources": ("derive/observations.py",),
        "units": "Tool point (tx, ty, tz), instrument geometry and readings in mm, in the "
                 "workpiece frame; projections and set-up columns mm/mm.  Reading = nominal + "
                 "projection @ (volumetric error) + set-up columns @ (set-up unknowns).",
    }
    constants = {"KINDS": repr(tuple(INSTRUMENTS)),
                 "SETUP": repr({k: SETUP[k] for k in INSTRUMENTS})}
    return render_module(header, constants, functions())
