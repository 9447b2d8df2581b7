"""Effects: symbolic extensions of a layout's chain (sympy).

A layout may declare ``[effects.NAME]`` tables (format: :mod:`volerr.machine.layout`).  Each term adds
``parameter * basis`` to a target of the chain:

* a component error of an axis (``EXX`` ... ``ECZ``), a squareness (``EC0Y`` ...) or a location
  error of a rotary axis (``EX0C`` ...): the term is added to that parameter wherever it enters
  the axis' error twist, so it propagates
  through the chain exactly like the error it modifies (Abbe arms included).  Examples:
  ``thermal`` -- scale expansion ``EXX += KT_X * X * (T_C - 20)``; ``reversal`` --
  ``EXX += RV_X * dir_X``; ``coupling`` -- ``EZX += c * x * y`` (a straightness of X that
  depends on Y: a cross term no sum of one-dimensional functions can absorb); ``periodic`` --
  ``EXX += a sin(2 pi X / P) + b cos(2 pi X / P)``; ``higher_order`` -- Legendre terms of a
  component beyond the fitted degree.
* ``work.<k>``: an extra error twist ``I + D_work`` standing first in ``tool2work`` (the
  workpiece / measuring-instrument end): ``setup`` (rigid placement of the instrument, six
  coordinates, per set-up group through ``ind(setup, g)``) and ``drift`` (``work.dx += k t_s``).
* ``tool.<k>``: an extra error twist standing last (the probe / tool end), in the tool frame:
  ``probe_direction`` (``tool.dx += r nx`` ...: an effective probe-radius error along the
  probing direction).
* a nominal symbol of the chain (:attr:`volerr.machine.layout.Layout.symbols`): ``probe.Xp``
  ``probe.Yp`` ``probe.Zp`` (the probe / tool offset: a translation at the tool end, in the
  tool frame), ``axis.<A>`` (the axis position, mm or rad), ``param.<p>`` (a layout parameter
  such as the DMU 50's ``d``, wherever it enters the chain), ``frame.<F>.x|y|z|angle`` (a
  fixed frame's translation, mm, or angle, rad): the term is the change of the symbol's
  value; an error factor ``I + F^-1 dF/ds * change`` follows every nominal factor ``F`` that
  holds the symbol (:mod:`volerr.derive.symbols`).  ``Xp Yp Zp`` may appear in a basis: a
  *proportional* term such as ``probe.Zp += k * Zp * (T - 20)`` (a stylus or tool that grows
  with temperature by ``k`` per K of its own length).

Covariates (``T_C``, ``t_s``, ``dir_X``, ``nx`` ...) are plain real symbols; the code generator
makes them arguments of the generated functions.  Rotary positions are in rad here, as
everywhere in the derivation.
"""

from __future__ import annotations

import sympy as sp

from volerr.machine.layout import TWIST_KEYS, Layout

_SYMPY_FUNCTIONS = {
    "sin": sp.sin, "cos": sp.cos, "exp": sp.exp, "sqrt": sp.sqrt, "abs": sp.Abs, "pi": sp.pi,
    "ind": lambda a, b: sp.Piecewise((1, sp.Eq(a, b)), (0, True)),
    "legendre": lambda n, x: sp.expand(sp.legendre(int(n), x)),
    "lag": lambda u, tau, t=None: _lag_symbol(u, tau, t),
}


def _lag_symbol(u, tau, t=None) -> sp.Symbol:
    """A lag ``lag(C, tau_s[, time])`` as a plain real symbol (computed by the generated
    module from the series: :mod:`volerr.derive.lags`)."""
    from volerr.machine.lags import lag_symbol

    return sp.Symbol(lag_symbol(str(u), float(tau), str(t) if t is not None else "t_s"),
                     real=True)


def basis_expr(text: str) -> sp.Expr:
    """A basis expression (validated by :mod:`volerr.machine.expressions`) as sympy, variables real."""
    from volerr.machine.expressions import variables

    loc = {v: sp.Symbol(v, real=True) for v in variables(text)}
    loc.update(_SYMPY_FUNCTIONS)
    return sp.sympify(text, locals=loc, rational=True)


def additions(layout: Layout) -> dict:
    """target -> sympy expression added to it (sum of parameter * basis of all terms); a term
    on a parameter of another effect (nested effects) is folded into that effect's terms."""
    out: dict = {}
    for e in layout.effects:
        for t in e.terms:
            term = sp.Symbol(t.parameter, real=True) * basis_expr(t.basis)
            out[t.target] = out.get(t.target, 0) + term
    return _fold_nested(out, {p for e in layout.effects for p in e.parameters})


def _fold_nested(add: dict, effect_parameters: set) -> dict:
    """``add`` with every effect parameter ``K`` that is itself a target replaced by
    ``K + (its additions)`` wherever it appears (effects refer to earlier ones only: the
    substitution ends)."""
    inner = {t: add.pop(t) for t in list(add) if t in effect_parameters}
    if not inner:
        return add
    keep = {t: sp.Dummy(t, real=True) for t in inner}
    subs = {sp.Symbol(t, real=True): keep[t] + v for t, v in inner.items()}
    out = {}
    for target, expr in add.items():
        for _ in range(len(subs) + 1):
            new = sp.sympify(expr).xreplace(subs)
            if new == expr:
                break
            expr = new
        out[target] = expr.xreplace({d: sp.Symbol(t, real=True) for t, d in keep.items()})
    return out


def covariate_symbols(layout: Layout) -> tuple:
    """Symbols of the layout's covariates, sorted by name."""
    return tuple(sp.Symbol(c, real=True) for c in layout.covariates)


def apply_effects(layout: Layout, factors: list) -> list:
    """The chain's factors with the layout's effects added (unchanged without effects).

    ``factors`` is the list of :func:`volerr.derive.kinematics.chain_factors` (workpiece end
    first); component and location twists are extended in place, ``work``/``tool`` twists are
    new factors at the two ends."""
    from .htm import Factor, parameter_symbol

    from .symbols import PROBE_TWIST, insert_variations

    add = additions(layout)
    if not add:
        return factors
    for s, k in PROBE_TWIST.items():       # the probe offset: a translation at the tool end
        if s in add:
            add[f"tool.{k}"] = add.get(f"tool.{k}", 0) + add.pop(s)
    nominal = {t: v for t, v in add.items() if t.split(".")[0] in ("param", "axis", "frame")}
    out = insert_variations(list(factors), nominal) if nominal else list(factors)
    subs = {parameter_symbol(t): parameter_symbol(t) + extra for t, extra in add.items()
            if "." not in t}
    for f in out:
        if not f.is_error or f.role not in ("component", "location", "squareness"):
            continue
        for key, value in list(f.twist_args.items()):
            # the parameter as it enters the twist (alone, or q * squareness)
            f.twist_args[key] = sp.sympify(value).xreplace(subs)
    for side in ("work", "tool"):
        args = {k: add[f"{side}.{k}"] for k in TWIST_KEYS if f"{side}.{k}" in add}
        if args:
            factor = Factor(twist_args=args, owner=side, role="effect")
            out = [factor, *out] if side == "work" else [*out, factor]
    return out
