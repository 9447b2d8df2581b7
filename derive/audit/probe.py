"""Audit of Pahk's probe error model (sec. 3, eq. 11-17) against :mod:`volerr.derive.probe`.

The printed material is the parsed ``data/printed_probe.toml`` (no file I/O here).
The authority is the construction of eq. (11) itself (cross products of the probe axis with
e_z) and, for the signs of eq. (13) and (17), a first-order model of a trigger probe on a
surface: the ball centre is recorded ``delta`` (pretravel) nearer the surface than at the
contact, the calibration gives ``R_eff = r - mean(delta)`` and ``Probe = delta - mean(delta)``.

How each item is judged
* eq. 11: the printed closed forms against the normalised cross products
  (``simplify(derived - printed) == 0``, with |e'_z x e_z| = sin A for 0 < A < 180 deg);
* eq. 12: the printed matrix against Tp as the equation states it (``[x'] = Tp [x]``: rows =
  basis vectors) and against its transpose;
* eq. 14: ``Tp^-1 M`` with the printed matrix against the derived probe-frame direction;
* eq. 15, 16: against the angle from the probe axis and the azimuth (atan2), symbolically where
  sympy can, and numerically in all four quadrants;
* eq. 13, 17: the sign of the combined error against the trigger-probe model.
"""

from __future__ import annotations

import math

import numpy as np
import sympy as sp

from .. import probe as d
from .framework import Verdict, fmt, is_zero

DATA_FILE = "printed_probe.toml"
SOURCE = "Pahk 1995"
LAYOUT = "probe"

_LOCALS = {"A": d.A, "B": d.B, "Mx": d.MX, "My": d.MY, "Mz": d.MZ, "Mxp": d.MXP,
           "Myp": d.MYP, "Mzp": d.MZP}


def _parse(text: str):
    return sp.sympify(text, locals=_LOCALS)


def _vec(items) -> sp.Matrix:
    return sp.Matrix([_parse(t) for t in items])


def _mat(rows) -> sp.Matrix:
    return sp.Matrix([[_parse(t) for t in r] for r in rows])


def _v(eq, same, erratum, evidence, printed, derived, component="",
       category: str = "printing_error", **fields) -> Verdict:
    return Verdict(SOURCE, eq, LAYOUT, "identical" if same else "differs",
                   "" if same else erratum, evidence, printed, derived, component,
                   category="identical" if same else category, **fields)


def _zero(m) -> bool:
    """``simplify(m) == 0`` (a matrix: entry by entry, as sympy simplifies one), each entry
    built as 0 taken as it is (:func:`framework.is_zero`)."""
    return all(is_zero(x) for x in m) if hasattr(m, "shape") else is_zero(m)


def _by_id(printed: dict) -> dict:
    return {str(e["id"]): e for e in printed.get("equation", [])}


def audit_basis(eq: dict) -> list[Verdict]:
    ex, ey, ez = d.basis()
    out = []
    pz = _vec(eq["ez"])
    out.append(_v("11", _zero(pz - d.probe_axis()), "", "definition of the probe axis "
                  "(z' along the stylus, +z for A = 0)", fmt(list(pz)), fmt(list(ez)), "e'_z"))
    for name, derived, key in (("e'_y", ey, "ey"), ("e'_x", ex, "ex")):
        p = _vec(eq[key])
        same = _zero(p - derived)
        ev = ("normalised cross product of eq. (11), |e'_z x e_z| = |sin A| taken as sin A "
              "(0 < A < 180 deg); at A = 0 the cross product vanishes and the construction is "
              "undefined: its limit A -> 0+ is the machine frame turned by B about z")
        out.append(_v("11", same, "closed form differs", ev, fmt(list(p)), fmt(list(derived)),
                      name))
    return out


def audit_transform(eq: dict) -> list[Verdict]:
    printed = _mat(eq["ocr"]["matrix"])
    derived = d.machine2probe()  # eq. (12) as stated: [x', y', z'] = Tp [x, y, z]
    same = _zero(printed - derived)
    is_transpose = _zero(printed - derived.T)
    ev = [eq["ocr"]["note"]]
    if is_transpose:
        ev.append("the printed matrix has e'_x, e'_y, e'_z of eq. (11) as its columns, so it "
                  "maps probe to machine coordinates ([x, y, z] = Tp [x', y', z']); eq. (12) "
                  "states [x', y', z'] = Tp [x, y, z], which needs them as rows: the print is "
                  "the transpose (= inverse) of the stated Tp; eq. (14) M' = Tp^-1 M is "
                  "consistent with the printed matrix, so the statement of eq. (12) is the "
                  "slip; volerr names the two matrices probe2machine (the print) and "
                  "machine2probe (the statement)")
    v = _v("12", same, "transposed matrix (statement and matrix disagree)" if is_transpose
           else "matrix differs", "; ".join(ev) + (
               ". Category printing_error: a whole well-formed matrix and a well-formed "
               "statement that contradict each other, not extraction damage" if is_transpose
               else ""), fmt(printed.tolist()), fmt(derived.tolist()), "Tp")
    if is_transpose:
        v.readings_tried = ["Tp as eq. (12) states it ([x', y', z'] = Tp [x, y, z]: the basis "
                            "vectors of eq. (11) as rows): the printed matrix differs",
                            "the transpose (basis vectors as columns, probe to machine): the "
                            "printed matrix exactly; eq. (14) M' = Tp^-1 M needs this one"]
        v.readings_used = ["inconsistent:eq. 12 statement vs matrix"]
    return [v]


def audit_direction(eq: dict, tp_printed: sp.Matrix) -> list[Verdict]:
    m = sp.Matrix([d.MX, d.MY, d.MZ])
    printed = sp.simplify(tp_printed.inv() * m)
    derived = d.direction_in_probe_frame()
    same = _zero(printed - derived)
    ev = ("with the printed matrix Tp (columns = probe axes), Tp^-1 = Tp^T and Tp^-1 M has the "
          "components e'_x.M, e'_y.M, e'_z.M: the probe-frame direction; with Tp as eq. (12) "
          "states it, the formula would need Tp M")
    return [_v("14", same, "inverse of the wrong matrix", ev, fmt(list(printed)),
               fmt(list(derived)), "M'")]


def _angles_numeric(fn_printed, fn_derived, periodic: bool) -> tuple[bool, str]:
    rng = np.random.default_rng(1995)
    worst, where = 0.0, None
    for _ in range(400):
        v = rng.normal(size=3)
        a, b = fn_printed(*v), fn_derived(*v)
        diff = abs(a - b)
        if periodic:
            diff = abs((a - b + math.pi) % (2 * math.pi) - math.pi)
        if diff > worst:
            worst, where = diff, v
    if worst < 1e-12:
        return True, "agree at 400 random directions (all octants)"
    return False, (f"differ by up to {math.degrees(worst):.1f} deg, e.g. at M' = "
                   f"({where[0]:.2f}, {where[1]:.2f}, {where[2]:.2f})")


#: Pahk's probe calibration (sec. 3.2, after eq. (13)): 100 points on 5 latitude
#: circles, 18 deg apart along each angle -- so 20 azimuths per circle
_CAL_POINTS, _CAL_CIRCLES, _CAL_STEP_DEG = 100, 5, 18
_CALIBRATION_AZIMUTH = (
    f"The text supports that reading: the calibration measures '{_CAL_POINTS + 1} points (100 "
    f"on {_CAL_CIRCLES} latitude circles and one at the top)' at {_CAL_STEP_DEG} deg steps "
    f"('전체적으로 101 점을 측정하였으며(5개의 위도원을 따른 100개의 점과 꼭대기의 한 점)'), i.e. "
    f"{_CAL_POINTS // _CAL_CIRCLES} azimuths per circle, {_CAL_POINTS // _CAL_CIRCLES} x "
    f"{_CAL_STEP_DEG} = {_CAL_POINTS // _CAL_CIRCLES * _CAL_STEP_DEG} deg: the probe error map "
    f"(Fig. 3(b), a (phi, theta) grid) spans the full azimuth, which a one-argument arctangent "
    f"(a 180 deg range) cannot index and atan2 can")


def audit_angles(eq15: dict, eq16: dict) -> list[Verdict]:
    out = []
    phi_d, theta_d = d.direction_angles()
    p15 = _parse(eq15["expr"])
    defn = d.eq15_phi()  # angle between M' and e'_z
    f_p = sp.lambdify((d.MXP, d.MYP, d.MZP), p15, "math")
    f_d = sp.lambdify((d.MXP, d.MYP, d.MZP), phi_d, "math")
    same_sym = sp.simplify(p15 - defn) == 0
    same_num, ev = _angles_numeric(f_p, f_d, False)
    out.append(_v("15", same_sym and same_num, "angle differs",
                  "phi = angle between M' and the probe axis z'; the generated code uses the "
                  "equal, rounding-safe atan2(sqrt(Mx'^2 + My'^2), Mz'); " + ev,
                  fmt(p15), fmt(phi_d), "phi"))
    p16 = _parse(eq16["expr"])
    g_p = sp.lambdify((d.MXP, d.MYP, d.MZP), p16, "math")
    g_d = sp.lambdify((d.MXP, d.MYP, d.MZP), theta_d, "math")
    same_num, ev = _angles_numeric(g_p, g_d, True)
    out.append(_v("16", same_num, "quadrant lost (one-argument arctangent)",
                  "tan^-1(My'/Mx') lies in (-90, 90) deg and cannot tell M' from -M' in the "
                  "xy-plane: for Mx' < 0 it is off by 180 deg (e.g. M' = (-1, 0, 0): 0 instead "
                  "of 180 deg); the azimuth is the two-argument atan2(My', Mx') in [0, 360); "
                  + ev + ". Category convention: read tan^-1(My'/Mx') as the quadrant-correct "
                  "azimuth (the common convention for an angle written as tan^-1(y/x), the "
                  "two-argument atan2(My', Mx') mod 360 deg), the printed eq. (16) is the "
                  "derived azimuth exactly (" + _atan2_check(theta_d) + "). " + _CALIBRATION_AZIMUTH,
                  fmt(p16), fmt(theta_d), "theta", category="convention",
                  alternative="atan2(My', Mx') mod 2 pi",
                  statement="tan^-1(y/x) written for the quadrant-correct atan2(y, x)"))
    out[-1].readings_tried = ["tan^-1(My'/Mx') literally (one-argument, -90 .. 90 deg): differs "
                              "by 180 deg for Mx' < 0",
                              "tan^-1(y/x) read as the two-argument atan2(y, x) mod 360 deg: "
                              "exact at 400 directions"]
    out[-1].readings_used = ["notation:tan^-1(y/x) for atan2(y, x)"]
    return out


def _atan2_check(theta_d) -> str:
    g = sp.lambdify((d.MXP, d.MYP, d.MZP), theta_d, "math")
    ok, ev = _angles_numeric(lambda x, y, z: math.atan2(y, x) % (2 * math.pi), g, True)
    return ("atan2 reading " + ev) if ok else ("the atan2 reading also differs: " + ev)


def audit_signs(eq13: dict, eq17: dict) -> list[Verdict]:
    """Trigger-probe model: surface point S, outward normal n, ball radius r, pretravel
    delta; recorded centre S + (r - delta) n; the point reported is centre - R_eff n."""
    r, delta, mean, rs = sp.symbols("r delta delta_mean R_s", real=True)
    reff = r - mean                                 # calibration mean of eq. (13)
    rm = rs + r - delta                             # on the sphere: distance of the centres
    probe_printed = sp.solve(sp.Eq(sp.Symbol("Reff") - sp.Symbol("Probe"),
                                   sp.Symbol("Rm") - sp.Symbol("Rs")), sp.Symbol("Probe"))[0]
    probe_val = probe_printed.subs({"Reff": reff, "Rm": rm, "Rs": rs})
    out = [_v("13", sp.simplify(probe_val - (delta - mean)) == 0, "sign of Probe",
              "with R_eff the mean of R_m - R_s, Probe = delta - mean(delta): positive where "
              "the probe triggers late (ball centre recorded nearer the sphere)",
              fmt(probe_printed), fmt(delta - mean), "Probe")]
    n = sp.Matrix(sp.symbols("n_x n_y n_z", real=True))
    # actual minus reported contact point: the sign convention of dX of eq. (4) (actual minus
    # nominal), so that the two terms of eq. (17) add up in one convention
    error = -((r - delta) - reff) * n
    probe_sym = sp.Symbol("Probe")
    printed = [_parse(t) for t in eq17["expr"]]
    dxyz = sp.Matrix(sp.symbols("dX dY dZ"))     # as parsed (plain symbols)
    # M of eq. (17) is the probe's contact (approach) direction, into the surface: M = -n
    printed_term = (sp.Matrix(printed) - dxyz).subs({d.MX: -n[0], d.MY: -n[1], d.MZ: -n[2]})
    derived_term = error
    same = _zero(printed_term.subs(probe_sym, delta - mean) - derived_term)
    out.append(_v("17", same, "sign of the probe term",
                  "dX of eq. (4) is actual minus nominal; a trigger probe reports a point "
                  "Probe(n) inside the surface (n the outward normal, the (phi, theta) of eq. "
                  "13), so the actual contact lies +Probe n from the reported one.  Eq. (17)'s "
                  "-Probe M is that term with M the contact (approach) direction, into the "
                  "surface, M = -n, as Pahk names it; volerr's `direction` is the outward "
                  "normal n, so Model.volumetric_error adds +Probe(n) n",
                  fmt(list(printed_term)), fmt(list(derived_term.subs(delta - mean,
                                                                      probe_sym))),
                  "dXc"))
    return out


def audit(printed: dict, layouts=None) -> list[Verdict]:
    """Verdicts on eq. (11)-(17) of Pahk sec. 3 (layout-independent: skipped when the audit
    is restricted to named layouts)."""
    if layouts:
        return []
    eqs = _by_id(printed)
    out = audit_basis(eqs["11"])
    out += audit_transform(eqs["12"])
    out += audit_direction(eqs["14"], _mat(eqs["12"]["ocr"]["matrix"]))
    out += audit_angles(eqs["15"], eqs["16"])
    out += audit_signs(eqs["13"], eqs["17"])
    return out
