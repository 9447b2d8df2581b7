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
``artifact``
    a calibrated artifact (ball plate, hole plate, step gauge) probed by the machine: the
    machine reports the point ``t`` (nominal chain) where its actual probe point ``t + e`` is
    on the artifact's feature, so ``t + e - a = 0`` with ``a`` the actual feature point.  The
    artifact's frame (``u, v, w``) has the nominal orientation ``R`` (columns: its axes in the
    workpiece frame) and origin ``o``; a feature's calibrated coordinates ``p`` (artifact
    frame).  Set-up unknowns, in the artifact frame: the pose correction of the placement
    (translation ``du dv dw``, small rotation ``eu ev ew`` about the artifact's origin) and
    the calibration correction of the feature ``cu cv cw``: ``a = o + R (d + (I + [e]x)(p +
    c))``.  Three readings, the components of ``R^T (t + e - a)`` in the artifact frame
    (written ``R^T (t + e - o) - d - (I + [e]x)(p + c)``, equal for an orthonormal ``R``);
    measured value 0.  A ball uses all three, a hole the in-plane two (u, v), a step-gauge
    face the one along the gauge (u).
``distances``
    a tracking interferometer (self-calibrating multilateration): the distance from a station
    (the centre of its reference sphere, nominally ``s``, unknown offset ``ds``) to the
    reflector at the tool point, plus the station's dead path ``dd`` (the unknown length at
    which its interferometer counts zero): ``|t + e - (s + ds)| + dd``.
``interferometer_positioning``
    a laser interferometer along a beam of direction ``b`` (unit, workpiece frame): the
    moving optic at the tool point ``t`` (its offset from the tool point: the Abbe arms), the
    fixed optic on the workpiece side; reading the displacement along the beam from the
    reference point ``r`` (where it was zeroed): ``(1 + k) b . (t + e - r) + z``, ``k`` the
    scale error of the reading (cosine error of the beam alignment, residual of the air
    compensation), ``z`` the zero offset (zeroing, dead-path error).
``interferometer_straightness``
    straightness optics: the displacement of the moving optic along ``s`` (unit, normal to the
    beam) from the beam line through ``r`` along ``b``: ``s . (t + e - r) + z + m b . (t + e -
    r)``, ``z`` the line's offset and ``m`` its angle (the straightness reflector's alignment:
    straightness is read about a reference line, ISO 230-1).
``interferometer_angular``
    angular optics: two reflectors at ``t1`` and ``t2 = t1 + L n`` (``n`` unit, normal to the
    beam), the reading the optical path difference over ``L``: ``b . ((t2 + e2) - (t1 + e1))
    / L + z`` (rad): the rotation of the moving optic about ``n x b`` (first order).  A reading
    of two points of the same pose: its function has the columns nominal, projection of
    ``e1`` (3), of ``e2`` (3), set-up.
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


def _skew(w: sp.Matrix) -> sp.Matrix:
    """``[w]x``: the matrix of ``w x``."""
    return sp.Matrix([[0, -w[2], w[1]], [w[2], 0, -w[0]], [-w[1], w[0], 0]])


def artifact():
    """(geometry, set-up, readings) of a feature of a calibrated artifact (ball / hole plate,
    step gauge) probed by the machine: the three components in the artifact frame of the
    actual probe point minus the actual feature point (measured value 0)."""
    origin = _vec("ox oy oz")
    R = sp.Matrix(3, 3, sp.symbols("r11 r12 r13 r21 r22 r23 r31 r32 r33", real=True))
    point = _vec("pu pv pw")
    d, e, c = _vec("du dv dw"), _vec("eu ev ew"), _vec("cu cv cw")
    reading = R.T * (TOOL + ERROR - origin) - d - (sp.eye(3) + _skew(e)) * (point + c)
    return [*origin, *R, *point], [*d, *e, *c], reading


def distances():
    """(geometry, set-up, reading) of a tracking interferometer: distance from its station to
    the tool point plus its dead path."""
    station = _vec("sx sy sz")
    ds = _vec("dsx dsy dsz")
    dead = sp.Symbol("dd", real=True)
    r = TOOL + ERROR - (station + ds)
    return [*station], [*ds, dead], sp.Matrix([sp.sqrt(r.dot(r)) + dead])


def interferometer_positioning():
    """(geometry, set-up, reading) of a linear (positioning) interferometer: displacement
    along the beam from the reference point, with scale and zero errors."""
    beam, ref = _vec("bx by bz"), _vec("rx ry rz")
    k, z = sp.symbols("k z", real=True)
    return [*beam, *ref], [z, k], sp.Matrix([(1 + k) * beam.dot(TOOL + ERROR - ref) + z])


def interferometer_straightness():
    """(geometry, set-up, reading) of straightness optics: displacement along ``s`` from the
    beam line (offset ``z`` and angle ``m`` of the line unknown)."""
    sense, beam, ref = _vec("sx sy sz"), _vec("bx by bz"), _vec("rx ry rz")
    z, m = sp.symbols("z m", real=True)
    r = TOOL + ERROR - ref
    return [*sense, *beam, *ref], [z, m], sp.Matrix([sense.dot(r) + z + m * beam.dot(r)])


#: second point of a two-point reading (angular optics)
TOOL2 = sp.Matrix(sp.symbols("t2x t2y t2z", real=True))
ERROR2 = sp.Matrix(sp.symbols("e2x e2y e2z", real=True))


def interferometer_angular():
    """(geometry, set-up, reading) of angular optics: optical path difference of the
    reflectors at ``t`` and ``t2`` (mm apart) over their separation ``L``, plus a zero offset
    (rad)."""
    beam = _vec("bx by bz")
    sep = sp.Symbol("L", positive=True)
    z = sp.Symbol("z", real=True)
    reading = beam.dot((TOOL2 + ERROR2) - (TOOL + ERROR)) / sep + z
    return [*TOOL2, *beam, sep], [z], sp.Matrix([reading])


#: instrument kind -> its observation equation
INSTRUMENTS = {"ballbar": ballbar, "sphere": sphere, "artifact": artifact,
               "distances": distances,
               "interferometer_positioning": interferometer_positioning,
               "interferometer_straightness": interferometer_straightness,
               "interferometer_angular": interferometer_angular}
#: instrument kind -> names of its set-up unknowns in the generated column order
SETUP = {"ballbar": ("pivot_dx", "pivot_dy", "pivot_dz", "length"),
         "sphere": ("centre_dx", "centre_dy", "centre_dz"),
         "artifact": ("du", "dv", "dw", "eu", "ev", "ew", "cu", "cv", "cw"),
         "distances": ("station_dx", "station_dy", "station_dz", "dead_path"),
         "interferometer_positioning": ("zero", "scale"),
         "interferometer_straightness": ("zero", "slope"),
         "interferometer_angular": ("zero",)}
#: instrument kind -> points of the chain one reading combines (2: a differential reading)
POINTS = {k: 2 if k == "interferometer_angular" else 1 for k in INSTRUMENTS}


def linearised(kind: str) -> tuple[list, sp.Matrix]:
    """(geometry symbols, matrix (readings, 1 + 3 points + n_setup)) of an instrument:
    nominal reading, projection d/de (d/de1, d/de2 for a two-point reading) and set-up
    columns d/ds, all at ``e = 0, s = 0``."""
    geometry, setup, reading = INSTRUMENTS[kind]()
    errors = [*ERROR] + ([*ERROR2] if POINTS[kind] == 2 else [])
    at_zero = {**{s: 0 for s in errors}, **{s: 0 for s in setup}}
    cols = [reading.subs(at_zero)]
    cols += [reading.diff(s).subs(at_zero) for s in errors]
    cols += [reading.diff(s).subs(at_zero) for s in setup]
    out = sp.Matrix.hstack(*cols).applyfunc(sp.simplify)
    return geometry, out


def functions() -> list[Function]:
    out = []
    for kind in INSTRUMENTS:
        geometry, m = linearised(kind)
        rows, cols = m.shape
        proj = ("projection of the volumetric error (3 columns, mm/mm)" if POINTS[kind] == 1
                else "projections of the volumetric errors at the first and the second point "
                     "(3 + 3 columns)")
        out.append(Function(
            kind, [str(s) for s in [*TOOL, *geometry]], list(m),
            f"{kind}: array ({rows}, {cols}, *shape) -- per reading: nominal reading, "
            f"{proj}, set-up columns {', '.join(SETUP[kind])}.", shape=(rows, cols)))
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
                 "workpiece frame (angular readings rad); projections and set-up columns "
                 "per unit of the unknown (mm/mm, mm/rad, rad/mm).  Reading = nominal + "
                 "projection @ (volumetric error) + set-up columns @ (set-up unknowns).",
    }
    constants = {"KINDS": repr(tuple(INSTRUMENTS)),
                 "SETUP": repr({k: SETUP[k] for k in INSTRUMENTS}),
                 "POINTS": repr({k: POINTS[k] for k in INSTRUMENTS})}
    return render_module(header, constants, functions())
