"""Audit of the instrument formulas of Ellingsdalen (2021): the laser tracker's spherical
coordinates (project report eq. 25), the multilateration residual (eq. 26), and the U / MPE
specifications of project report sec. 2.8 against the values the conference paper quotes in its
sec. 6 (sympy / numpy, no file I/O).

The printed material is the parsed ``data/printed_metrology.toml``.

* eq. 25: a tracker measures the distance r, the azimuth az (in the xy-plane from +x) and the
  elevation el (from the xy-plane): x = r cos el cos az, y = r cos el sin az, z = r sin el.
  The printed form is the physics convention of ISO 80000-2 (theta the polar angle from +z,
  phi the azimuth), with the angle names of the sentence below it tried both ways;
* eq. 26: the station i at (X_i, Y_i, Z_i) reads the length l_ij relative to its zero position;
  the distance to the target is the dead path plus the reading, so the residual is
  |x_j - X_i| - (l_ij + L_i); the sign of the estimated dead path is free;
* specifications a + b L/1000 um: units (L in mm, b in um/m), the same values in both
  documents, and the printed comparisons evaluated over 0 .. 10 m.
"""

from __future__ import annotations

import numpy as np
import sympy as sp

from .framework import Verdict, category_of

DATA_FILE = "printed_metrology.toml"
SOURCE = "Ellingsdalen 2021"
LAYOUT = "-"
DOCS = {"paper": "conference paper (appendix A)", "project": "project report (appendix B)"}


def _v(item, comp, category, erratum, evidence, printed, derived, tried=(), used=(),
       **fields) -> Verdict:
    eq = f"{item['doc']} {item['id']}" if item["id"].startswith("sec.") else \
        f"{item['doc']} eq. {item['id']}"
    same = category == "identical"
    return Verdict(SOURCE, eq, LAYOUT, "identical" if same else "differs",
                   "" if same else erratum, evidence, printed, derived, comp,
                   category=category, readings_tried=list(tried), readings_used=list(used),
                   **fields)


def audit_spherical(item: dict) -> list[Verdict]:
    r, th, ph, az, el = sp.symbols("r theta phi az el", real=True)
    loc = {"r": r, "theta": th, "phi": ph}
    printed = [sp.sympify(item["expr"][c], locals=loc) for c in "xyz"]
    tracker = [r * sp.cos(el) * sp.cos(az), r * sp.cos(el) * sp.sin(az), r * sp.sin(el)]
    readings = {
        "theta the polar angle from +z (90 deg - elevation), phi the azimuth (ISO 80000-2)":
            {th: sp.pi / 2 - el, ph: az},
        "theta the azimuth, phi the elevation (the sentence, respectively)": {th: az, ph: el},
        "theta the elevation, phi the azimuth (the two names exchanged)": {th: el, ph: az},
    }
    tried, hit = [], None
    rng = np.random.default_rng(25)
    pts = [dict(zip((r, az, el), (rng.uniform(1, 5), *rng.uniform(-3, 3, 2)))) for _ in range(4)]
    for name, sub in readings.items():
        ok = all(abs(float((p.subs(sub, simultaneous=True) - t).subs(pt))) < 1e-12
                 for pt in pts for p, t in zip(printed, tracker))
        tried.append(f"{name}: " + ("exact" if ok else "differs"))
        if ok and hit is None:
            hit = name
    out = []
    key = ["notation:spherical coordinates, theta polar and phi azimuth (ISO 80000-2)"]
    out.append(_v(item, "formulas", category_of(key) if hit else "printing_error",
                  "spherical coordinates in the physics convention",
                  f"a tracker's reading (distance r, azimuth az from +x in the xy-plane, "
                  f"elevation el from the xy-plane) is x = r cos el cos az, y = r cos el sin "
                  f"az, z = r sin el. The printed formulas are exactly that with {hit}: the "
                  f"physics convention of ISO 80000-2 and of the source the figure cites "
                  f"([16], Wikipedia 'Spherical coordinate system'); theta is then the zenith "
                  f"angle, 90 deg - elevation" if hit else "no reading of the angles "
                  "reproduces the tracker's coordinates",
                  "; ".join(f"{c} = {item['expr'][c]}" for c in "xyz"),
                  "x = r cos(el) cos(az), y = r cos(el) sin(az), z = r sin(el)", tried,
                  key if hit else [], statement="theta polar (zenith) angle from +z, phi "
                                               "azimuth from +x (ISO 80000-2)" if hit else ""))
    out.append(_v(item, "angle names", "printing_error", "theta named azimuth and phi "
                  "elevation; in eq. 25 theta is the polar angle and phi the azimuth",
                  f"the sentence under eq. 25 says '{item['names']}'. Read 'respectively' "
                  f"(theta = azimuth, phi = elevation) the formulas do not give the tracker's "
                  f"coordinates; in the formulas phi is the azimuth and theta the angle from "
                  f"+z, which is 90 deg minus the elevation, not the elevation either way. "
                  f"The one reading under which the formulas give the tracker's coordinates "
                  f"(theta the polar angle, phi the azimuth; see the verdict on the formulas) "
                  f"makes theta neither of the two angles the sentence names; read as an "
                  f"unordered description ('the two angles are the azimuth and the "
                  f"elevation'), phi is the azimuth but theta is still not the elevation. "
                  f"Category printing_error: a well-formed statement that contradicts the "
                  f"equation it explains under every reading (prose, no extraction damage: "
                  f"each word is spelled right)", item["names"],
                  "phi the azimuth, theta the polar angle (90 deg - elevation)",
                  [t.replace(": exact", ": exact for the formulas, but then theta is the polar "
                                        "angle, which the sentence names neither azimuth nor "
                                        "elevation") for t in tried],
                  ["inconsistent:project eq. (25) angle names"]))
    return out


def audit_multilateration(item: dict) -> Verdict:
    x, y, z, X, Y, Z, l, L = sp.symbols("x y z X Y Z l L", real=True)
    loc = {n: s for n, s in zip("x y z X Y Z l L".split(), (x, y, z, X, Y, Z, l, L))}
    printed = sp.sympify(item["expr"], locals=loc)
    dist = sp.sqrt((x - X) ** 2 + (y - Y) ** 2 + (z - Z) ** 2)
    derived = dist - (l + L)
    same = sp.simplify(printed - derived) == 0
    flipped = sp.simplify(printed - derived.subs(L, -L)) == 0
    tried = [f"residual |x - X| - (l + L) (dead path plus reading): "
             f"{'exact' if same else 'differs by the sign of L'}",
             f"dead path defined with the opposite sign (L -> -L): "
             f"{'exact' if flipped else 'differs'}"]
    used = ["flip:project eq. (26) sign of the dead path L_i"]
    cat = "identical" if same else (category_of(used) if flipped else "printing_error")
    return _v(item, "", cat, "dead path subtracted from the reading",
              "a station i reads l_ij relative to its zero position; the distance from the "
              "station to the target is the dead path L_i plus the reading, so the residual "
              "of the least-squares fit is |x_j - X_i| - (l_ij + L_i). The printed "
              "-(l_ij - L_i) is that with L_i -> -L_i: the dead path is an unknown of the fit "
              "and the text defines it only as 'Dead path length', without a sign, so the fit "
              "is the same with L_i' = -L_i (the estimate changes sign): a sign convention",
              item["expr"], sp.sstr(derived), tried, used if cat != "identical" else [],
              statement="L_i the length subtracted from the reading (opposite sign of the "
                        "distance at the zero reading)")


def _spec(item):
    return float(item["a_um"]), float(item["b_um_per_m"])


def audit_spec(item: dict) -> Verdict:
    a, b = _spec(item)
    L = sp.Symbol("L", positive=True)
    expr = a + b * L / 1000                      # um, L in mm: b um per 1000 mm = b um/m
    at2 = float(expr.subs(L, 2000))
    parts = [f"{a:g} um + {b:g} um/m: with L in mm, L/1000 is in m, so the printed "
             f"({a:g} + {b:g} L/1000) um is dimensionally {a:g} um + {b:g} um/m "
             f"({at2:.3g} um at L = 2 m)"]
    same = True
    tried = ["units: consistent"]
    if "paper" in item:
        pa, pb = float(item["paper"]["a_um"]), float(item["paper"]["b_um_per_m"])
        agree = (pa, pb) == (a, b)
        same = same and agree
        parts.append(f"the conference paper (sec. 6) quotes {pa:g} um + {pb:g} um/m: "
                     f"{'the same' if agree else 'different'} ('{item['paper']['text']}')")
        tried.append(f"against the paper's sec. 6: {'the same' if agree else 'differs'}")
    return _v(item, "", "identical" if same else "printing_error", "specifications differ",
              f"{item['what']}: " + "; ".join(parts) + ". The vendor's value itself is not "
              "derivable from the text (a specification)", item["text"],
              f"({a:g} + {b:g} L/1000) um", tried)


def audit_claim(item: dict, specs: dict) -> Verdict:
    L = np.linspace(0.0, 10000.0, 101)               # mm
    a1, b1 = _spec(specs[item["a"]])

    def val(a, b):
        return a + b * L / 1000
    if item["kind"] == "exceeds_constant":
        c = float(item["constant_um"])
        v = val(a1, b1)
        ok = bool(np.all(v > c))
        ev = (f"{a1:g} + {b1:g} L/1000 um ranges {v.min():g} .. {v.max():g} um over L = 0 .. 10 "
              f"m, above the {c:g} um of the absolute distance measurement everywhere")
        return _v(item, "", "identical" if ok else "printing_error", "claim contradicted",
                  ev if ok else ev.replace("above", "not above"), item["text"], ev)
    a2, b2 = _spec(specs[item["b"]])
    ratio = val(a1, b1) / val(a2, b2)
    lo, hi = float(ratio.min()), float(ratio.max())
    if item["kind"] == "ratio_small":
        ok = 1 < lo and hi < 10
        ev = (f"({a1:g} + {b1:g} L/1000) / ({a2:g} + {b2:g} L/1000) = {lo:.2f} .. {hi:.2f} "
              f"over L = 0 .. 10 m: higher, less than 10 times ('slightly higher, the same "
              f"order of magnitude')")
    else:
        ok = lo >= 10
        ev = (f"({a1:g} + {b1:g} L/1000) / ({a2:g} + {b2:g} L/1000) = {lo:.1f} .. {hi:.1f} "
              f"over L = 0 .. 10 m: at least ten times, i.e. 'an order of magnitude larger' "
              f"holds as a lower bound (the ratio is 1.3 to 1.6 orders of magnitude)")
    return _v(item, "", "identical" if ok else "printing_error", "claim contradicted", ev,
              item["text"], f"ratio {lo:.3g} .. {hi:.3g}")


def audit(printed: dict, layouts=None) -> list[Verdict]:
    """Verdicts on the instrument formulas (layout-independent: skipped for named layouts)."""
    if layouts:
        return []
    out = []
    if "spherical" in printed:
        out.extend(audit_spherical(printed["spherical"]))
    if "multilateration" in printed:
        out.append(audit_multilateration(printed["multilateration"]))
    specs = {s["id"]: s for s in printed.get("length_spec", [])}
    for s in printed.get("length_spec", []):
        out.append(audit_spec(s))
    for c in printed.get("claim", []):
        out.append(audit_claim(c, specs))
    return out
