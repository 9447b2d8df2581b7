"""Candidate effects on the nominal symbols of the chain: a stylus or tool that grows, a layout
parameter or a frame offset that drifts, the scale of a rotary axis.

The chain's nominal symbols (:attr:`volerr.machine.layout.Layout.symbols`: the probe / tool
offset components ``probe.Xp probe.Yp probe.Zp``, the axis positions ``axis.A``, the layout
parameters ``param.d`` and the fixed frames' offsets and angles ``frame.F.x ... frame.F.angle``)
are parameters P of the candidate space like the declared error parameters.  A candidate's
column is the generated sensitivity of the tool point to the symbol (``symbol_sensitivity``,
projected by each instrument) times its basis, and its effect term targets the symbol itself
(``target = "param.d"``), so the augmented layout carries it as an effect on that symbol
(:mod:`volerr.derive.symbols`).

Which symbols, with which bases:

* a layout parameter or a frame's offset / angle (a constant of the chain): *linear* in each
  covariate (``d += k (T - 20)``), a saturating warm-up in time, one value per level of a
  run / set-up column.  Proportional and linear are the same column for a constant; the
  report gives both the change (um/K) and its ratio to the nominal value (ppm/K);
* the probe / tool offset (varies from point to point): *proportional*, the change scales with
  each point's own offset (``Zp += k Zp (T - 20)``, k in ppm/K): ``probe.length`` scales the
  whole offset vector (a stylus or a tool that grows along itself; terms on the three
  components with one parameter), ``probe.Xp`` ... one component (only where the data hold
  offsets along more than one axis; otherwise the length is that component).  A constant
  change of an offset component is the tool-end translation ``tool.dx ...`` of
  :mod:`volerr.loop.candidates`, already a candidate;
* the position of a rotary axis: *proportional* (``C += k C (T - 20)``, a scale of the angle;
  the constant part is the axis' own angular positioning error ``ECC``, already a candidate).
  The scale of a linear axis is its positioning error's slope (``thermal_X``), already one.

Order of the candidates (ties between candidates that give the same columns go to the one
listed first, :func:`volerr.loop.fitting.rank`): the layout's constants
before the declared parameters (``d`` of the DMU 50 moves the tool exactly as the location
error ``EY0B`` does: the report names the layout's ``d`` and lists the other as
indistinguishable), the probe and axis symbols after the instrument's set-up and before the
tool-end translation (a tool that grows on a single length is named a growing tool length, a
uniform shift of a single stylus stays the instrument's drift).

Units inside: mm, rad, K, h.  Reported: ppm per covariate unit for proportional terms, um (or
urad) per covariate unit for constants.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

PROBE_COMPONENTS = ("Xp", "Yp", "Zp")


@dataclass(frozen=True)
class SymbolTarget:
    """A nominal symbol as a parameter P: ``name`` as reported (``probe.length``, ``probe.Zp``,
    ``axis.C``, ``param.d``, ``frame.F.x``), ``terms`` ((layout target, the variable the basis
    is multiplied by for a proportional term, or None), ...), ``angular`` (a change in rad),
    ``value`` (the nominal value of a constant symbol, mm or rad), ``kind`` ``"symbol"``."""

    name: str
    terms: tuple
    angular: bool = False
    value: float | None = None
    kind: str = "symbol"

    @property
    def proportional(self) -> bool:
        return self.terms[0][1] is not None

    @property
    def chain(self) -> str:
        return self.terms[0][0]

    def make_terms(self, parameter: str, basis: str) -> list:
        """Effect terms (parameter, layout target, basis) of ``parameter * basis``."""
        return [(parameter, t, f"{v}*{basis}" if v else basis) for t, v in self.terms]


def symbol_value(layout, name: str) -> float | None:
    """The nominal value of a constant symbol (``param.d``: mm; ``frame.F.x``: mm;
    ``frame.F.angle``: rad), None for the others."""
    from ..machine.expressions import number

    kind, _, rest = name.partition(".")
    if kind == "param":
        return float(layout.parameters[rest])
    if kind == "frame":
        frame, key = rest.rsplit(".", 1)
        f = layout.frames[frame]
        if key == "angle":
            return float(np.deg2rad(number(f.angle_deg, layout.parameters, "frame angle")))
        return number(f.translation["xyz".index(key)], layout.parameters, "frame translation")
    return None


def targets(model, data) -> tuple[list, list]:
    """(constant symbols, varying symbols) of ``model`` as :class:`SymbolTarget` for the data
    ``data`` (probe components that are zero at every point are left out)."""
    names = set(model.symbols)
    if not names:
        return [], []
    lay = model.layout
    const = []
    for s in model.symbols:
        if s.startswith(("param.", "frame.")):
            const.append(SymbolTarget(s, ((s, None),), s.endswith(".angle"),
                                      symbol_value(lay, s)))
    probe = np.asarray(data.probe)
    used = [k for i, k in enumerate(PROBE_COMPONENTS)
            if f"probe.{k}" in names and np.any(probe[:, i] != 0)]
    varying = []
    if used:
        varying.append(SymbolTarget("probe.length", tuple((f"probe.{k}", k) for k in used)))
    if len(used) > 1:
        varying += [SymbolTarget(f"probe.{k}", ((f"probe.{k}", k),)) for k in used]
    varying += [SymbolTarget(f"axis.{a}", ((f"axis.{a}", a),), True) for a in model.rotary_axes
                if f"axis.{a}" in names]
    return const, varying


def tag(target: SymbolTarget) -> str:
    """Short identifier of a symbol for effect and parameter names."""
    kind, _, rest = target.name.partition(".")
    if kind == "param":
        return rest
    if kind == "axis":
        return f"{rest}_scale"
    return target.name.replace(".", "_")


def unit(target: SymbolTarget, per: str) -> tuple[float, str]:
    """Report factor and unit of the parameter of ``target`` x a covariate basis of unit
    ``per`` (``"1"``: per level or dimensionless)."""
    if target.proportional:
        f, u = 1e6, "ppm"
    else:
        f, u = (1e6, "urad") if target.angular else (1e3, "um")
    return (f, u) if per in ("1", "") else (f, f"{u}/{per}")


def words(model, name: str) -> str:
    """A symbol in the layout's vocabulary: ``stylus length`` (CMM) / ``tool length`` (machine
    tool), ``stylus offset Zp``, ``d`` (with where it enters the chain), ``C axis scale``,
    ``frame F offset x``."""
    from ..machine.expressions import variables

    lay = model.layout
    kind, _, rest = name.partition(".")
    probe = "tool" if lay.kind == "machine_tool" else "stylus"
    if name == "probe.length":
        return f"{probe} length"
    if kind == "probe":
        return f"{probe} offset {rest}"
    if kind == "axis":
        return f"{rest} axis scale"
    if kind == "frame":
        frame, key = rest.rsplit(".", 1)
        return f"frame {frame} {'angle' if key == 'angle' else 'offset ' + key}"
    where = [f"point of axis {a}" for a in lay.axis_names
             if any(isinstance(c, str) and rest in variables(c) for c in lay.axes[a].point)]
    where += [f"frame {f.name}" for f in lay.frames.values()
              if any(isinstance(c, str) and rest in variables(c)
                     for c in (*f.translation, f.angle_deg))]
    return f"{rest} ({', '.join(where)})" if where else rest


def _num(v: float) -> str:
    return f"{v:.3g}"


def describe(model, info: dict, values: dict, units: dict) -> str:
    """One line naming an accepted effect in the layout's vocabulary: ``stylus length grows
    23 ppm/K with T_probe``, ``d (point of axis B) grows 2.1 um/K (13.5 ppm/K of 154.996 mm)
    with T_spindle``; for an effect on a declared parameter ``EXX varies with T_C (linear,
    scale): KT_X = 11.5 um/m/K``.  ``values`` / ``units``: parameter -> value and unit as
    reported."""
    cov, basis = info.get("covariate"), str(info.get("basis", ""))
    symbol = info.get("symbol")
    if symbol is None:
        vals = ", ".join(f"{p} = {_num(v)} {units.get(p, '')}".rstrip()
                         for p, v in values.items())
        return f"{info.get('parameter')} varies with {cov} ({basis}): {vals}"
    subject = words(model, symbol)
    if "indicator" in basis or len(values) != 1:
        vals = ", ".join(f"{_num(v)} {units.get(p, '')}".rstrip() for p, v in values.items())
        return f"{subject} differs per {cov} level (after the first): {vals}"
    (p, v), = values.items()
    verb = "grows" if v >= 0 else "shrinks"
    text = f"{subject} {verb} {_num(abs(v))} {units.get(p, '')}".rstrip()
    if "saturating" in basis:
        text += f" (saturating, time constant {_num(info.get('tau_h', float('nan')))} h)"
    value = info.get("nominal_value")
    if value and not str(units.get(p, "")).startswith("ppm"):
        unit = str(units.get(p, ""))
        per = unit.split("/", 1)[1] if "/" in unit else ""
        factor = 1e-3 if unit.startswith("um") else 1e-6
        rel = 1e6 * abs(v) * factor / abs(value)
        nominal = f"{value:g} mm" if unit.startswith("um") else f"{value:g} rad"
        text += f" ({_num(rel)} ppm{'/' + per if per else ''} of {nominal})"
    return f"{text} with {cov}"
