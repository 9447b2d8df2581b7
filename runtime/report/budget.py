"""The uncertainty budget of one reported quantity (GUM, JCGM 100:2008 5.1; ISO/TR 230-9:2005
for machine tool tests): the sources, each with its standard uncertainty u(x_i) in its own
unit, its sensitivity coefficient c_i (unit of the quantity per unit of the source) and its
contribution u_i = |c_i| u(x_i) in the unit of the quantity; the combined standard
uncertainty u_c = sqrt(sum u_i^2) (uncorrelated sources), the coverage factor k and the
expanded uncertainty U = k u_c.

The estimators build their budgets from the numbers they already hold (never retyped):
:func:`budget` returns the JSON form every page and certificate prints,
``{"quantity", "unit", "sources": [{"source", "u", "unit", "sensitivity", "contribution"}],
"u", "k", "U"}``, with ``"rows"`` (the names of the result's rows, :meth:`table`, whose
standard uncertainty it is, where they differ from ``quantity``) and ``"notes"`` (what the
budget leaves out, and why) when given.  :func:`of_row` finds the budget of a row."""

from __future__ import annotations

import math


def source(name: str, u: float, unit: str, sensitivity: float = 1.0) -> dict:
    """One source: standard uncertainty ``u`` (in ``unit``), sensitivity coefficient
    ``sensitivity`` (the quantity's unit per ``unit``); its contribution |c| u."""
    return {"source": name, "u": float(u), "unit": unit, "sensitivity": float(sensitivity),
            "contribution": abs(float(sensitivity)) * float(u)}


def budget(quantity: str, unit: str, sources: list, k: float = 2.0, rows=(),
           notes=()) -> dict:
    """The budget of ``quantity`` (in ``unit``) from its uncorrelated ``sources``
    (:func:`source`): combined u = root sum of squares of the contributions, U = k u.
    ``rows``: the result rows it belongs to (default: the row named ``quantity``);
    ``notes``: sentences printed under the budget."""
    u = math.sqrt(sum(s["contribution"] ** 2 for s in sources))
    out = {"quantity": quantity, "unit": unit, "sources": list(sources), "u": u,
           "k": float(k), "U": float(k) * u}
    if rows:
        out["rows"] = list(rows)
    if notes:
        out["notes"] = list(notes)
    return out


def of_row(budgets, name: str):
    """The budget (of the list ``budgets``, :func:`volerr.report.content.budgets_of`) of the
    result row ``name``: the one listing it in ``"rows"``, else the one whose quantity is the
    name (an axis prefix ``X:`` of the row read as ``X `` as :func:`budgets_of` writes it);
    None when there is none."""
    for b in budgets:
        if name in (b.get("rows") or ()):
            return b
    plain = name.replace(":", " ", 1)
    return next((b for b in budgets if not b.get("rows") and b["quantity"] in (name, plain)),
                None)


def restated(b: dict, u_stated: float) -> dict:
    """The budget ``b`` for a u the report states rounded (``u_stated``, within 1e-3 relative
    of ``b["u"]``): every source's u(x_i) and contribution scaled by u_stated / u, so that
    the combined u is the stated one; ``b`` as it is when they differ by more."""
    f = float(u_stated) / b["u"] if b["u"] > 0 else 1.0
    if abs(f - 1.0) > 1e-3:
        return b
    srcs = [dict(s, u=s["u"] * f, contribution=s["contribution"] * f) for s in b["sources"]]
    return {**b, "sources": srcs, "u": b["u"] * f, "U": b["U"] * f}


def combined(b: dict) -> float:
    """The combined standard uncertainty of a budget recomputed from its contributions."""
    return math.sqrt(sum(s["contribution"] ** 2 for s in b["sources"]))
