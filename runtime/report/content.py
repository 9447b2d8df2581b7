"""What a certificate holds, in order (ISO/IEC 17025:2017 7.8.2, 7.8.4), as sections
(heading, kind, payload) that :func:`volerr.report.pdf.render` sets on A4 pages:

1. the identification (:class:`volerr.certificate.Identification`), its warnings;
2. the test conditions of the standard (:func:`volerr.report.conditions.of`: from the data,
   else the identification file's ``[conditions]``, else "not stated"; for a result of no
   standard the file's conditions, else the command's ``doc["conditions"]``);
3. the results: each reported value with its standard uncertainty u (k = 1), the coverage
   factor k = 2 and the expanded uncertainty U = k u (the result's rows, :meth:`table`);
4. the verdicts and the decision rule, where a tolerance was given;
5. the uncertainty budget of every quantity that has one (``doc["budgets"]``,
   :mod:`volerr.report.budget`);
6. the notes, then the figures.

Units: the rows' units as µm and µrad (never "um")."""

from __future__ import annotations

import re

from .fmt import number, unit, value_for  # noqa: F401  (the page's numbers and units)

#: the coverage factor of the expanded uncertainties on a certificate (about 95 % for a
#: normal distribution, ISO/TR 230-9 and the GUM's usual choice)
K_CERTIFICATE = 2.0


def identification_of(doc: dict, ident=None):
    """The :class:`Identification` given, else the one of ``doc["identification"]``."""
    from ..certificate import Identification

    if ident is not None:
        return ident
    d = dict(doc.get("identification") or {})
    known = set(Identification.__dataclass_fields__)
    kw = {k: d.pop(k) for k in list(d) if k in known and k != "conditions"}
    kw["machine_details"] = kw.get("machine_details") or {}
    return Identification(**{k: v for k, v in kw.items() if v is not None}, conditions=d)


def result_rows(rows) -> list:
    """Header and one row per reported value: name, value, u, k, U, unit."""
    out = [["quantity", "value", "u (k = 1)", "k", "U = k u", "unit"]]
    for r in rows:
        k = K_CERTIFICATE
        U = None if r.std is None else k * float(r.std)
        out.append([row_name(r.name), value_for(r.value, r.std), number(r.std, 3),
                    f"{k:g}", number(U, 3), unit(r.unit)])
    return out


def row_name(name: str) -> str:
    """A result row's name as printed: a JSON key after the last colon in words
    (``"x1:mae_before"`` -> ``"x1: MAE before"``, ``"KT_EZZ:tau"`` -> ``"KT_EZZ: time
    constant"``, ``"max_abs_dx"`` -> ``"largest |dx|"``); a parameter's own name
    (``EXX@slope``, ``KT_EXZ_T_spindle_0``, ``tool_dz``... in upper case or after no colon
    without an underscore) kept."""
    from .fmt import words

    head, sep, key = str(name).rpartition(":")
    if re.fullmatch(r"[a-z][a-z0-9]*_[a-z0-9_]*", key) or (sep and re.fullmatch(r"[a-z]\w*", key)):
        return f"{head}{sep} {words(key)}".strip()
    return str(name)


def budget_rows(b: dict) -> list:
    """Header and one row per source of a budget, then the combined u, k and U."""
    q = unit(b["unit"])
    out = [["source", "u(x_i)", "unit of x_i", "sensitivity c_i", f"contribution / {q}"]]
    for s in b["sources"]:
        out.append([s["source"], number(_noise_free(s["u"], b, s["unit"]), 3), unit(s["unit"]),
                    number(s["sensitivity"], 3),
                    number(_noise_free(s["contribution"], b, b["unit"]), 3)])
    out.append(["combined standard uncertainty u", "", "", "", number(b["u"], 4)])
    out.append([f"expanded uncertainty U (k = {b['k']:g})", "", "", "", number(b["U"], 4)])
    return out


#: below this fraction of the combined u a value of a budget is rounding noise of the
#: arithmetic (a source that the quantity does not depend on), printed as 0
NOISE = 1e-9


def _noise_free(value, b: dict, value_unit: str):
    """``value`` (in ``value_unit``), or 0 when it is in the budget's unit and below
    :data:`NOISE` times its combined u (printed 6.16e-15 µrad where the source adds
    nothing); the JSON keeps the computed value."""
    if value is None or value_unit != b["unit"] or not b.get("u"):
        return value
    return 0.0 if abs(float(value)) < NOISE * abs(float(b["u"])) else value


def budgets_of(doc: dict) -> list:
    """Every budget of the document (``"budgets"``, per run for several runs), its quantity
    named with the run's axis."""
    found = [dict(b, quantity=f"{doc.get('axis', '')} {b['quantity']}".strip())
             for b in (doc.get("budgets") or {}).values()] if isinstance(doc.get("budgets"),
                                                                          dict) else []
    for run in doc.get("runs") or []:
        if isinstance(run, dict):
            found += [dict(b, quantity=f"{run.get('axis', '')} {b['quantity']}".strip())
                      for b in (run.get("budgets") or {}).values()]
    return found


def _headline(doc: dict) -> list:
    """The ISO 10360-2 headline (largest |E0| with its test uncertainty U, k = 2) as a row."""
    from types import SimpleNamespace as Row   # the fields of volerr.results.Row

    U = (doc.get("uncertainty_um") or {}).get("E0") if "max_abs_E_um" in doc else None
    if U is None:
        return []
    return [Row(name="max |E0|", value=doc["max_abs_E_um"], std=U / K_CERTIFICATE, unit="um")]


def _tolerance_items(doc: dict) -> list:
    """A ``"tolerance": {"items": [...], "rule", "verdict"}`` block (``volerr check``)."""
    tol = doc.get("tolerance")
    if not (isinstance(tol, dict) and isinstance(tol.get("items"), list)):
        return []
    rows = [["quantity", "value", "U (k = 2)", "limit", "unit", "verdict"]]
    rows += [[str(i.get("quantity")), number(i.get("value")), number(i.get("U"), 3),
              number(i.get("limit")), unit(i.get("unit", "")), str(i.get("verdict")).upper()]
             for i in tol["items"]]
    out = [("Tolerances", "table", rows)]
    if tol.get("rule"):
        out.append((None, "text", f"Decision rule: {tol['rule']}"))
    return out


def _verdicts(doc: dict) -> list:
    out = []
    per = doc.get("verdicts")
    if isinstance(per, dict) and per:
        out.append(("Verdicts", "pairs", [[k, str(v).upper()] for k, v in per.items()]))
    elif doc.get("verdict"):
        out.append(("Verdict", "text", str(doc["verdict"]).upper()))
    if doc.get("decision_rule") and out:
        out.append((None, "text", f"Decision rule: {doc['decision_rule']}"))
    return out


def sections(doc: dict, rows, figures: dict, ident=None) -> list:
    """The certificate's sections in the order of the module docstring."""
    ident = identification_of(doc, ident)
    out = [("Identification", "pairs", [list(r) for r in ident.rows()])]
    out += [(None, "warn", f"warning: {w}") for w in ident.warnings]
    from . import conditions

    stated = {**ident.conditions, **ident.test_conditions}
    cond = conditions.of(doc, stated) or ident.test_conditions or doc.get("conditions")
    if isinstance(cond, dict) and cond:
        out.append(("Test conditions", "pairs",
                    [[k, v if isinstance(v, str) else number(v)] for k, v in cond.items()]))
    out += conditions.measured(doc)
    rows = list(rows) + _headline(doc)
    if rows:
        out.append(("Results", "table", result_rows(rows)))
        out.append((None, "text", f"u: standard uncertainty; U: expanded uncertainty, "
                                  f"coverage factor k = {K_CERTIFICATE:g} (about 95 %)."))
    out += _verdicts(doc) + _tolerance_items(doc)
    for b in budgets_of(doc):
        out.append((f"Uncertainty budget: {b['quantity']}", "table", budget_rows(b)))
        out += [(None, "text", n) for n in b.get("notes") or ()]
    notes = [n for n in doc.get("notes") or [] if isinstance(n, str)]
    if notes:
        out.append(("Notes", "text", "\n".join(f"\u2013 {n}" for n in notes)))
    for name, fig in (figures or {}).items():
        out.append((f"Figure: {name.replace('_', ' ')}", "figure", (fig, "")))
    return out
