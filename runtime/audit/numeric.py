"""Numeric spot check of a generated model against the printed equations of its layout.

No sympy: the printed expressions of ``volerr/derive/audit/data/printed_pahk.toml`` (their OCR
reading where the data file gives one) are evaluated with numpy at random points, with random error
values, and compared with the generated model (first-order volumetric error; random error by Pahk's
term-wise quadrature and by exact propagation). A difference at rounding level (~1e-12 um) means
the generated code reproduces the printed equation; anything larger is a real difference, which
``volerr audit`` names and explains.

Units: positions and probe offsets mm, translational errors mm, angular errors rad; reported
differences in um.
"""

from __future__ import annotations

import ast
import re
import tomllib
from importlib import resources

import numpy as np

from ..machine import iso_names
from ..errors import InputError
from ..units import UM_PER_MM

DATA_FILE = "printed_pahk.toml"
_FUNC = re.compile(r"\b(R?)(dx|dy|dz|Ex|Ey|Ez)\((X|Y|Z)o?\)")
_SCALAR = {"a": "alpha", "Ra": "Ralpha"}


def printed_equations(layout: str, data: dict | None = None) -> list[dict]:
    """The printed volumetric and random-error equations of ``layout`` (data file order)."""
    if data is None:
        data = tomllib.loads((resources.files("volerr.derive.audit") / "data" / DATA_FILE)
                             .read_text(encoding="utf-8"))
    return [e for e in data.get("equation", [])
            if e.get("layout") == layout and e.get("kind") in ("volumetric", "random")]


def _compile(text: str):
    """Printed expression -> code object over identifiers dx_X, REy_Y, alpha, X, Xp ..."""
    src = _FUNC.sub(lambda m: f"{m.group(1)}{m.group(2)}_{m.group(3)}", text)
    tree = ast.parse(src, mode="eval")
    allowed = (ast.Expression, ast.BinOp, ast.UnaryOp, ast.Name, ast.Constant, ast.Load,
               ast.Add, ast.Sub, ast.Mult, ast.Pow, ast.USub, ast.UAdd)
    for node in ast.walk(tree):
        if not isinstance(node, allowed):
            raise ValueError(f"unsupported syntax in {text!r}")
    return compile(tree, "<printed>", "eval")


def _paper_values(model, values: dict, prefix: str = "") -> dict:
    """ISO values -> paper-symbol identifiers with the layout's signs (``-dx(Y)`` = EXY ...)."""
    out = {}
    for iso, sym in model.paper_symbols.items():
        sign = -1.0 if sym.startswith("-") else 1.0
        name = sym.lstrip("-")
        m = re.fullmatch(r"(dx|dy|dz|Ex|Ey|Ez)\((X|Y|Z)\)", name)
        ident = f"{m.group(1)}_{m.group(2)}" if m else name
        v = values.get(iso, 0.0)
        out[prefix + ident] = v if prefix else sign * v
    for short, long in _SCALAR.items():
        if prefix + long in out or long in out:
            out[short] = out.get(long, out.get(prefix + long))
    if prefix:
        out["Ra"] = out.get("Ralpha", 0.0)
    return out


def _evaluate(text: str, namespace: dict):
    code = _compile(text)
    return eval(code, {"__builtins__": {}}, namespace)  # noqa: S307 - whitelisted AST above


def spot_check(model, n: int = 200, seed: int = 0, translational_mm: float = 0.01,
               angular_rad: float = 20e-6, probe_mm: float = 50.0,
               data: dict | None = None) -> list[dict]:
    """Evaluate ``model`` and the printed equations of its layout at ``n`` random points.

    Returns one dict per printed component: ``layout, equation, component, against,
    max_diff_um, max_value_um, status`` where ``status`` is "agrees" (difference at rounding
    level), "differs" or "unparsable" (garbled printed text without an OCR reading)."""
    eqs = printed_equations(model.name, data)
    if not eqs:
        return []
    rng = np.random.default_rng(seed)
    pos = {a: rng.uniform(*model.travel[a], n) for a in model.axes}
    probe = rng.uniform(-probe_mm, probe_mm, (n, 3))
    errors = {}
    for p in model.parameters:
        angular = iso_names.is_angle(p)
        errors[p] = rng.normal(0.0, angular_rad if angular else translational_mm, n)
    sigmas = {p: abs(v[0]) + 1e-9 for p, v in errors.items()}
    base = {**pos, "Xp": probe[:, 0], "Yp": probe[:, 1], "Zp": probe[:, 2]}
    out = []
    for eq in eqs:
        comps = list(eq.get("expr", {}))
        if eq["kind"] == "volumetric":
            model_vals = model.volumetric_error(pos, errors, probe)
            ns = {**base, **_paper_values(model, errors)}
            targets = {c: ("first-order model", model_vals[:, i]) for i, c in enumerate(comps)}
        else:
            tw = model.random_error(pos, sigmas, probe, method="termwise")
            ex = model.random_error(pos, sigmas, probe, method="exact")
            ns = {**base, **_paper_values(model, errors), **_paper_values(model, sigmas, "R")}
            targets = {c: ("term-wise quadrature", tw[:, i], ex[:, i]) for i, c in enumerate(comps)}
        for c in comps:
            text = eq.get("ocr", {}).get(c, eq["expr"][c])
            row = {"layout": model.name, "equation": eq["id"], "component": c,
                   "against": targets[c][0]}
            try:
                val = np.broadcast_to(np.asarray(_evaluate(text, ns), dtype=float), (n,))
            except (ValueError, SyntaxError, NameError, TypeError) as exc:
                out.append({**row, "max_diff_um": float("nan"), "max_value_um": float("nan"),
                            "status": f"unparsable ({exc})"})
                continue
            if eq["kind"] == "random":
                val = np.sqrt(np.maximum(val, 0.0))
            ref = targets[c][1]
            diff = float(np.max(np.abs(val - ref))) * UM_PER_MM
            scale = float(np.max(np.abs(ref))) * UM_PER_MM
            row.update(max_diff_um=diff, max_value_um=scale,
                       status="agrees" if diff <= 1e-9 * max(scale, 1.0) + 1e-9 else "differs")
            if eq["kind"] == "random":
                row["max_diff_exact_um"] = float(np.max(np.abs(val - targets[c][2]))) * UM_PER_MM
            out.append(row)
    return out


def check_layout_has_printed(name: str) -> None:
    """Raise InputError when a layout has no printed equation to spot-check against."""
    if not printed_equations(name):
        raise InputError(f"layout {name} has no printed equation in {DATA_FILE}")
