"""Audit of printed code listings (Ellingsdalen 2021, Listings 3.1, 3.3, 3.4): run them.

The printed code comes as the parsed ``data/printed_listings.toml`` (the statements as
printed, with the extraction repairs listed there).  The audit executes that code with numpy on
small examples whose intended result is known in closed form, and compares:

* negative positions: ``curve_fit`` builds the model array for an axis travelling to negative
  positions as ``axis = 0, -1, -2, ...`` (element k = position -k), and Listing 3.4 reads it as
  ``error_model[round(pos)]``: a negative index counts from the END of the array, so the value
  read for ``pos = -k`` is the one of position ``-(n - k)`` (n = array length), a mirror image
  of the curve about the middle of the travel;
* the polynomial: for ``degree > 1`` the loop adds the coefficients ``1 .. degree-1`` only, so
  the constant term (coefficient ``degree``) is never added.

The intended model is ``np.polyval(coefficients, pos)``; differences are reported in um (the
error tables are in um; the listings multiply by 1e-3 to get mm).
"""

from __future__ import annotations

import functools

import numpy as np

from .framework import Verdict

DATA_FILE = "printed_listings.toml"
LAYOUTS = ("DMU50",)
SOURCE = "Ellingsdalen 2021"
LAYOUT = "DMU50"


def run_printed(code: str, axis_mm, error_um, degree: int, pos_mm: float) -> tuple:
    """Execute the printed lookup: returns (value read, coefficients of the fit)."""
    ns = {"np": np, "Axis": np.asarray(axis_mm, float),
          "error_parameter": np.asarray(error_um, float), "degree": degree, "pos": pos_mm}
    exec(_compiled(code), ns)  # noqa: S102 - our own data file
    return float(ns["value"]), ns["curve_error"][0]


@functools.lru_cache(maxsize=None)
def _compiled(code: str):
    """The printed listing compiled once (it runs at ~2500 positions; compiling was half the
    audit's time)."""
    return compile(code, "<printed listing>", "exec")


def _example_negative():
    """Z-like axis measured at 0, -40, ..., -400 mm (11 positions as in the thesis), error a
    cubic that is zero at the reference position (um)."""
    axis = np.linspace(0.0, -400.0, 11)
    u = axis / 400.0
    return axis, 20.0 * u + 40.0 * u ** 2 + 12.0 * u ** 3, 3


def _example_constant():
    """X-like axis 0 .. 500 mm in 50 mm steps (Figure 3.11), a smooth error zero at 0 plus a
    1 um (1 sigma) measurement scatter (seeded), fitted with degree 4 as Listing 3.4 does."""
    axis = np.linspace(0.0, 500.0, 11)
    rng = np.random.default_rng(2021)
    smooth = 20.6 * np.sin(np.pi * axis / 1000.0) ** 2
    noise = rng.normal(0.0, 1.0, axis.size)
    noise[0] = 0.0                       # the error at the reference position is zero
    return axis, smooth + noise, 4


def audit_lookup(item: dict) -> list[Verdict]:
    code = item["code"]
    out = []
    repairs = "; ".join(item.get("repairs", []))
    # 1. negative positions
    axis, err, deg = _example_negative()
    rows, worst = [], 0.0
    for pos in np.arange(-400.0, 0.0, 1.0):
        got, coef = run_printed(code, axis, err, deg, pos)
        want = float(np.polyval(coef, pos))
        worst = max(worst, abs(got - want))
        if pos in (-100.0, -300.0, -390.0):
            n = int(abs(axis[-1])) + 1
            rows.append(f"pos {pos:g} mm: the code reads {got:.3f} um (the curve at "
                        f"{-(n + int(pos)):g} mm), the curve there is {want:.3f} um")
    q_worst = 0.0
    for pos in np.arange(0.0, 400.0, 0.25):          # the mirror axis 0 .. 400 mm
        got, coef = run_printed(code, -axis, err, deg, pos)
        q_worst = max(q_worst, abs(got - float(np.polyval(coef, pos))))
    ev = ("What the printed code computes: for an axis whose positions are negative "
          "(Axis[-1] < 0, the branch Listing 3.1 provides), error_model[k] is the curve at "
          "-k mm; Listing 3.4's error_model[round(pos)] with pos < 0 is a negative index and "
          "Python counts it from the end: it reads the curve at -(n - |round(pos)|) mm, "
          "n = len(error_model) (no error raised). Run on an example (positions 0 .. -400 mm "
          "in 40 mm steps, a cubic error zero at 0, degree 3 as printed): "
          + "; ".join(rows) + f"; largest difference from the intended model over -400 .. -1 "
          f"mm: {worst:.2f} um -- a number of this assumed example (curve and travel are not "
          f"printed): the error at a position is |f(pos) - f(pos - n)| for the fitted curve f "
          f"(n = len(error_model)), zero for a constant curve and up to the whole range of f "
          f"over the travel otherwise. Only pos = 0 reads its own value; elsewhere the value is "
          f"right only where the curve happens to be equal at the mirror point. (The same axis with positive positions reads the intended curve "
          f"up to the 1 mm quantisation of round(): {q_worst:.3f} um here.) Extraction repairs: "
          f"{repairs}. Category printing_error: a defect of the printed code, not a convention "
          f"(the fix: error_model[abs(round(pos))], or np.polyval(coefficients, pos))")
    out.append(Verdict(SOURCE, item["id"], LAYOUT, "differs",
                       "negative positions read a mirrored value (negative index wraps around)",
                       ev, item["printed"], item["intended"], "negative positions",
                       category="printing_error", dropped_um=worst,
                       readings_tried=["the printed code run on an axis with negative "
                                       f"positions: off by up to {worst:.2f} um",
                                       "the same code on positive positions: the intended "
                                       f"curve to {q_worst:.3f} um"],
                       readings_used=["inconsistent:Listing 3.4 negative index"]))
    # 2. the constant term
    axis, err, deg = _example_constant()
    diffs = []
    for pos in np.arange(0.0, 501.0, 1.0):
        got, coef = run_printed(code, axis, err, deg, pos)
        diffs.append(got - float(np.polyval(coef, pos)))
    diffs = np.array(diffs)
    const = float(coef[-1])
    same_everywhere = bool(np.allclose(diffs, -const, atol=1e-9))
    ev = (f"What the printed code computes: error_model = c[0] axis^degree + sum over i = 1 .. "
          f"degree-1 of c[i] axis^(degree-i); np.polyfit's coefficients run c[0] .. c[degree], "
          f"so for degree > 1 the constant c[degree] is never added (degree 1 adds c[1] and is "
          f"right). Run on an example (0 .. 500 mm in 50 mm steps, a smooth 20.6 um curve zero "
          f"at 0 plus 1 um scatter, degree 4 as Listing 3.4 uses for E_XX): the fitted "
          f"constant is {const:.3f} um and the printed model differs from np.polyval by "
          f"{'exactly -c[degree] at every position' if same_everywhere else 'varying amounts'}"
          f" ({float(np.max(np.abs(diffs))):.3f} um, a number of this assumed example: the "
          f"data are not printed). The dropped constant is the fit's value at the reference "
          f"position: zero for an exact fit through 0, otherwise of the order of the scatter "
          f"of the data at the reference (about the fit's residual), here 1 um of assumed "
          f"scatter giving {abs(const):.3f} um. Category "
          f"printing_error: a defect of the printed code (range(1, degree + 1) adds it)")
    out.append(Verdict(SOURCE, item["id"], LAYOUT, "differs",
                       "constant term of the polynomial dropped for degree > 1", ev,
                       item["printed"], item["intended"], "constant term",
                       category="printing_error", dropped_um=float(np.max(np.abs(diffs))),
                       readings_tried=["the printed loop range(1, degree) run: differs from "
                                       "np.polyval by -c[degree]",
                                       "degree 1 (the other branch): right"],
                       readings_used=["inconsistent:Listing 3.1 loop range"]))
    return out


def audit(printed: dict, layouts=None) -> list[Verdict]:
    """Verdicts on the printed code listings."""
    if layouts is not None and not set(layouts) & set(LAYOUTS):
        return []
    out = []
    for item in printed.get("listing", []):
        out.extend(audit_lookup(item))
    return out
