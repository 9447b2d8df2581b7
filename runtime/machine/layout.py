"""Machine layout files: the one description that drives everything about a machine.

A layout is a TOML file (shipped ones live in ``volerr/layouts/``).  It declares

* ``[axes.NAME]``: ``kind = "linear" | "rotary"``, ``direction`` (unit vector, in the frame
  of the body the axis rides on), ``travel = [min, max]`` (mm or deg), for rotary axes
  ``point`` (a point on the axis, mm) and optionally ``location_errors`` (ISO names such as
  ``EX0C``; default: the four that are not along/about the axis direction).
* ``[frames.NAME]``: fixed nominal transforms, ``translation = [x, y, z]`` (numbers or
  expressions in the layout parameters) and ``rotation = {axis = [..], angle_deg = ..}``.
* ``[chain]``: ``tool = [...]`` lists axes and frames from the base (bed) to the probe or tool;
  ``workpiece = [...]`` from the base to the workpiece (table axes).  Order is physical:
  each entry rides on the one before it.
* ``[squareness]``: ISO squareness name -> the axis whose line of motion carries it in the model,
  e.g. ``EC0Y = "X"`` (Pahk puts alpha on the X axis of MB1).
* ``[parameters]``: named numbers (mm) usable in frame expressions, kept symbolic in the
  derivation (e.g. DMU 50 ``d``).
* ``[paper_symbols]``: ISO name -> symbol, with sign, used in the source document.
* ``[effects.NAME]`` (optional; written by ``volerr loop`` for an augmented model):
  ``kind`` (``thermal``, ``drift``, ``reversal``, ``coupling``, ``periodic``, ``higher_order``,
  ``probe_direction``, ``setup`` ...), free descriptive keys (``axis``, ``period`` ...), and
  ``terms = [{parameter = "KT_X", target = "EXX", basis = "X*(T_C - 20)"}, ...]``: each term adds
  ``parameter * basis`` to ``target``, a component or location error of an axis (``EXX``,
  ``EX0C``), a squareness, one of the six twist coordinates ``dx dy dz ex ey ez`` of an extra
  error factor at the workpiece end (``work.dx``: the measuring instrument's placement) or at
  the tool end (``tool.dx``: the probe) of the chain, or a *nominal symbol* of the chain
  (:attr:`Layout.symbols`: ``probe.Xp probe.Yp probe.Zp`` the probe / tool offset, ``axis.C``
  an axis position, ``param.d`` a layout parameter, ``frame.F.x|y|z|angle`` a fixed frame's
  translation or angle; mm or rad), whose value the actual machine has changed by the term
  (:mod:`volerr.derive.symbols`).  A parameter may appear in several terms of one effect.
  The parameters become error parameters of the model (after all others); names in a basis
  (:mod:`volerr.machine.expressions`) that are not axes or the probe offset ``Xp Yp Zp`` (a
  term proportional to each point's offset, ``Zp*(T - 20)``) are *covariates*: extra arguments
  of the generated functions (``T_C``, ``t_s``, ``dir_X`` ...).

Sign conventions (ISO 230-1 / ISO 841): every axis ``direction`` is the direction in which the
tool (probe) moves *relative to the workpiece* for a positive command, whether the tool side
or the table moves.  Component errors of an axis are likewise those of the tool relative to the
workpiece caused by that axis: for a table axis they are minus the table's own error motion.
Error motions of an axis are expressed in the frame of the body the axis rides on, i.e. after
the nominal rotations of the axes and frames below it in its chain (for a C table on a tilting
B axis, ``EAC`` is about the x axis of the tilted B body; on the shipped CMMs, where no frame
is rotated, that is the machine x axis).
Squareness ``E{R}0{B}`` is the small right-hand rotation about axis ``R`` of the line of motion
of ``B`` relative to the reference axis (X for EC0Y and EB0Z, Y for EA0Z); when the layout
assigns it to the reference axis instead, that axis is rotated by the opposite angle, which
describes the same physical angle between the two lines.
"""

from __future__ import annotations

import hashlib
import math
import re
import tomllib
from dataclasses import dataclass, field
from importlib import resources
from pathlib import Path

from ..errors import InputError, require, require_file

LINEAR_COMPONENTS = ("EX", "EY", "EZ", "EA", "EB", "EC")
#: squareness name -> (rotation axis index, carrier axis, reference axis)
SQUARENESS = {"EC0Y": (2, "Y", "X"), "EB0Z": (1, "Z", "X"), "EA0Z": (0, "Z", "Y")}
_ROTATION_LETTER = {"A": 0, "B": 1, "C": 2}
_NAME = re.compile(r"^[A-Za-z][A-Za-z0-9_]*$")


@dataclass(frozen=True)
class Axis:
    """One machine axis. ``direction`` is a unit vector; ``point`` lies on a rotary axis (mm)."""

    name: str
    kind: str
    direction: tuple[float, float, float]
    travel: tuple[float, float]
    point: tuple = (0.0, 0.0, 0.0)
    location_errors: tuple[str, ...] = ()

    @property
    def component_errors(self) -> tuple[str, ...]:
        """ISO names of the six error motions of this axis, e.g. EXX ... ECX."""
        return tuple(prefix + self.name for prefix in LINEAR_COMPONENTS)


@dataclass(frozen=True)
class Frame:
    """A fixed nominal transform: rotate about ``rotation_axis`` by ``angle_deg``, then translate."""

    name: str
    translation: tuple = (0.0, 0.0, 0.0)
    rotation_axis: tuple = (0.0, 0.0, 1.0)
    angle_deg: object = 0.0


#: twist coordinates of the extra error factors ``work.*`` / ``tool.*`` of effect terms
TWIST_KEYS = ("dx", "dy", "dz", "ex", "ey", "ez")
#: the probe / tool offset components as nominal symbols (effect targets)
PROBE_SYMBOLS = ("probe.Xp", "probe.Yp", "probe.Zp")
#: the probe / tool offset components, names usable in an effect basis (a proportional term)
PROBE_NAMES = ("Xp", "Yp", "Zp")
#: keys of a fixed frame's nominal symbols: translation components (mm) and angle (rad)
FRAME_KEYS = ("x", "y", "z", "angle")


@dataclass(frozen=True)
class EffectTerm:
    """``parameter * basis`` added to ``target`` (see the module docstring)."""

    parameter: str
    target: str
    basis: str


@dataclass(frozen=True)
class Effect:
    """A declared effect: its ``kind``, terms and free descriptive ``info``."""

    name: str
    kind: str
    terms: tuple
    info: dict = field(default_factory=dict)

    @property
    def parameters(self) -> tuple[str, ...]:
        return tuple(dict.fromkeys(t.parameter for t in self.terms))


@dataclass(frozen=True)
class Layout:
    """A parsed, validated machine layout (see the module docstring for the file format)."""

    name: str
    description: str
    kind: str
    axes: dict
    frames: dict
    tool_chain: tuple[str, ...]
    workpiece_chain: tuple[str, ...]
    squareness: dict
    parameters: dict
    paper_symbols: dict
    source: str
    sha256: str
    path: str = ""
    extra: dict = field(default_factory=dict)
    effects: tuple = ()

    @property
    def axis_names(self) -> tuple[str, ...]:
        """Axes in model order: linear X, Y, Z first, then rotary A, B, C (as on a controller)."""
        order = {"X": 0, "Y": 1, "Z": 2, "U": 3, "V": 4, "W": 5, "A": 6, "B": 7, "C": 8}
        return tuple(sorted(self.axes, key=lambda n: (order.get(n, 99), n)))

    @property
    def parameter_names(self) -> tuple[str, ...]:
        """All error parameters in model order: per axis its six component errors, then
        squareness, then rotary location errors."""
        names: list[str] = []
        for a in self.axis_names:
            names.extend(self.axes[a].component_errors)
        names.extend(sorted(self.squareness))
        for a in self.axis_names:
            names.extend(self.axes[a].location_errors)
        for e in self.effects:
            names.extend(p for p in e.parameters if p not in names)
        return tuple(names)

    @property
    def covariates(self) -> tuple[str, ...]:
        """Names in effect bases that are not axes or probe offsets (data columns such as
        ``T_C``), sorted."""
        from .expressions import variables

        names = {v for e in self.effects for t in e.terms for v in variables(t.basis)}
        return tuple(sorted(names - set(self.axes) - set(self.parameters) - set(PROBE_NAMES)))

    @property
    def symbols(self) -> tuple[str, ...]:
        """The nominal symbols of the chain, names as effect targets: the probe / tool offset
        components (``probe.Xp probe.Yp probe.Zp``, mm), the axis positions (``axis.X`` ...,
        mm or rad), the layout parameters (``param.d`` ..., mm) and the translation components
        and angle of every fixed frame in the chain (``frame.F.x`` ... mm, ``frame.F.angle``
        rad), in this order."""
        frames = [e for e in self.workpiece_chain + self.tool_chain if e in self.frames]
        return (PROBE_SYMBOLS + tuple(f"axis.{a}" for a in self.axis_names)
                + tuple(f"param.{p}" for p in sorted(self.parameters))
                + tuple(f"frame.{f}.{k}" for f in frames for k in FRAME_KEYS))

    @property
    def parameter_kind(self) -> dict:
        """Parameter name -> kind: ``translational``, ``angular``, ``squareness``,
        ``location`` or ``effect`` (:mod:`volerr.machine.iso_names`)."""
        from .iso_names import kind_of

        builtin = {n for a in self.axes.values() for n in a.component_errors
                   + a.location_errors} | set(self.squareness)
        return {n: kind_of(n) if n in builtin else "effect" for n in self.parameter_names}

    @property
    def parameter_axis(self) -> dict:
        """Parameter name -> the axis whose position it depends on, or None for constants."""
        out = {}
        for a in self.axis_names:
            for n in self.axes[a].component_errors:
                out[n] = a
        for n in self.parameter_names:
            out.setdefault(n, None)
        return out


def _vector(value, what: str, allow_expr: bool = False) -> tuple:
    require(isinstance(value, list) and len(value) == 3, f"{what} must be a list of 3 numbers")
    for v in value:
        ok = isinstance(v, (int, float)) or (allow_expr and isinstance(v, str))
        require(ok, f"{what} must hold numbers{' or expressions' if allow_expr else ''}, got {v!r}")
    for v in value:
        if isinstance(v, (int, float)):
            require(math.isfinite(v) and abs(v) <= MAX_COORDINATE,
                    f"{what}: {v!r} is not a finite number of at most {MAX_COORDINATE:g}")
    return tuple(float(v) if isinstance(v, (int, float)) else v for v in value)


#: largest coordinate, travel limit or parameter accepted in a layout (mm or deg)
MAX_COORDINATE = 1e6


def _unit(value, what: str) -> tuple[float, float, float]:
    v = _vector(value, what)
    n = math.sqrt(sum(c * c for c in v))
    require(n > 1e-12, f"{what} must not be the zero vector")
    return tuple(c / n for c in v)


def _default_location_errors(name: str, direction) -> tuple[str, ...]:
    """Location errors of a rotary axis: offsets and tilts not along/about its own direction."""
    big = max(range(3), key=lambda i: abs(direction[i]))
    aligned = abs(abs(direction[big]) - 1.0) < 1e-12
    out = []
    for i, t in enumerate("XYZ"):
        if not (aligned and i == big):
            out.append(f"E{t}0{name}")
    for i, r in enumerate("ABC"):
        if not (aligned and i == big):
            out.append(f"E{r}0{name}")
    return tuple(out)


def _parse_axis(an: str, spec: dict, where: str) -> Axis:
    """One ``[axes.NAME]`` table."""
    require(re.fullmatch(r"[XYZUVWABC]", an) is not None,
            f"{where}: unknown axis name {an!r} (use X Y Z U V W A B C)")
    k = spec.get("kind")
    require(k in ("linear", "rotary"), f"{where}: axis {an} kind must be linear or rotary")
    require("direction" in spec, f"{where}: axis {an} has no direction")
    direction = _unit(spec["direction"], f"{where}: axis {an} direction")
    travel = spec.get("travel")
    require(isinstance(travel, list) and len(travel) == 2 and travel[0] < travel[1],
            f"{where}: axis {an} travel must be [min, max] with min < max")
    require(all(isinstance(t, (int, float)) and math.isfinite(t)
                and abs(t) <= MAX_COORDINATE for t in travel),
            f"{where}: axis {an} travel must be finite numbers of at most "
            f"{MAX_COORDINATE:g}, got {travel}")
    point = _vector(spec.get("point", [0, 0, 0]), f"{where}: axis {an} point", True)
    loc = ()
    if k == "rotary":
        loc = tuple(spec.get("location_errors", _default_location_errors(an, direction)))
        for ln in loc:
            require(re.fullmatch(rf"E[XYZABC]0{an}", ln) is not None,
                    f"{where}: bad location error name {ln!r} for axis {an}")
    return Axis(an, k, direction, (float(travel[0]), float(travel[1])), point, loc)


def _parse_axes(raw_axes, where: str) -> dict:
    require(isinstance(raw_axes, dict) and raw_axes, f"{where}: no [axes] declared")
    return {an: _parse_axis(an, spec, where) for an, spec in raw_axes.items()}


def _parse_frames(raw: dict, axes: dict, where: str) -> dict:
    frames = {}
    for fn, spec in raw.items():
        require(fn not in axes, f"{where}: frame {fn!r} has the name of an axis")
        rot = spec.get("rotation", {})
        frames[fn] = Frame(
            fn,
            _vector(spec.get("translation", [0, 0, 0]), f"{where}: frame {fn} translation", True),
            _unit(rot.get("axis", [0, 0, 1]), f"{where}: frame {fn} rotation axis"),
            rot.get("angle_deg", 0.0),
        )
    return frames


def _parse_chain(chain: dict, axes: dict, frames: dict, where: str) -> tuple[tuple, tuple]:
    """(tool chain, workpiece chain): every entry known, none twice, every axis used."""
    require("tool" in chain, f"{where}: [chain] needs a 'tool' list (base to probe/tool)")
    tool = tuple(chain.get("tool", []))
    work = tuple(chain.get("workpiece", []))
    seen = set()
    for entry in tool + work:
        require(entry in axes or entry in frames,
                f"{where}: chain entry {entry!r} is neither an axis nor a frame (missing transform)")
        require(entry not in seen, f"{where}: {entry!r} appears twice in the chain (cycle)")
        seen.add(entry)
    for an in axes:
        require(an in seen, f"{where}: axis {an} is declared but not in any chain")
    return tool, work


def _parse_squareness(raw: dict, axes: dict, where: str) -> dict:
    squareness = dict(raw)
    for sq, carrier in squareness.items():
        require(sq in SQUARENESS, f"{where}: unknown squareness {sq!r} (use EC0Y EB0Z EA0Z)")
        _, moving, reference = SQUARENESS[sq]
        require(carrier in (moving, reference),
                f"{where}: squareness {sq} must be carried by axis {moving} or {reference}")
        require(carrier in axes and axes[carrier].kind == "linear",
                f"{where}: squareness {sq} carrier {carrier} is not a linear axis")
    return squareness


_KNOWN_KEYS = {"name", "description", "kind", "axes", "frames", "chain", "squareness",
               "parameters", "paper_symbols", "source", "effects"}


def _parse_header(text: str, origin: str) -> tuple[dict, str, str, dict]:
    """(TOML document, layout name, kind, parameters)."""
    try:
        doc = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise InputError(f"layout {origin}: not valid TOML ({exc})") from None
    name = doc.get("name")
    require(isinstance(name, str) and _NAME.match(name or ""), f"layout {origin}: 'name' missing")
    where = f"layout {name}"
    kind = doc.get("kind", "cmm")
    require(kind in ("cmm", "machine_tool"), f"{where}: kind must be 'cmm' or 'machine_tool'")
    params = doc.get("parameters", {})
    require(all(isinstance(v, (int, float)) for v in params.values()),
            f"{where}: [parameters] must be numbers")
    require(all(math.isfinite(v) and abs(v) <= MAX_COORDINATE for v in params.values()),
            f"{where}: [parameters] must be finite numbers of at most {MAX_COORDINATE:g}")
    return doc, name, kind, params


def parse_layout(text: str, origin: str = "<string>") -> Layout:
    """Parse and validate layout TOML text. Raises :class:`InputError` on any defect.

    Steps: header (name, kind, parameters), axes, frames, expressions, chains, squareness,
    effects."""
    doc, name, kind, params = _parse_header(text, origin)
    where = f"layout {name}"
    axes = _parse_axes(doc.get("axes"), where)
    frames = _parse_frames(doc.get("frames", {}), axes, where)
    _check_expressions(where, params, axes, frames)
    tool, work = _parse_chain(doc.get("chain", {}), axes, frames, where)
    squareness = _parse_squareness(doc.get("squareness", {}), axes, where)
    symbols = {str(k): str(v) for k, v in doc.get("paper_symbols", {}).items()}
    effects = _parse_effects(doc.get("effects", {}), axes, squareness, params, where,
                             _symbol_targets(axes, frames, tool + work, params))
    return Layout(
        name=name, description=str(doc.get("description", "")), kind=kind, axes=axes,
        frames=frames, tool_chain=tool, workpiece_chain=work, squareness=squareness,
        parameters=dict(params), paper_symbols=symbols, source=str(doc.get("source", "")),
        sha256=hashlib.sha256(text.encode()).hexdigest(), path=origin,
        extra={k: v for k, v in doc.items() if k not in _KNOWN_KEYS}, effects=effects,
    )


def _check_expressions(where: str, params: dict, axes: dict, frames: dict) -> None:
    """Expressions in points, translations and angles: valid, and only declared [parameters]."""
    from .expressions import variables

    items = [(f"axis {a.name} point", v) for a in axes.values() for v in a.point]
    for f in frames.values():
        items += [(f"frame {f.name} translation", v) for v in f.translation]
        items.append((f"frame {f.name} rotation angle_deg", f.angle_deg))
    for what, v in items:
        if isinstance(v, bool) or not isinstance(v, (int, float, str)):
            raise InputError(f"{where}: {what} must be a number or an expression, got {v!r}")
        if not isinstance(v, str):
            continue
        try:
            names = variables(v)
        except InputError as exc:
            raise InputError(f"{where}: {what}: {exc}") from None
        unknown = [n for n in names if n not in params]
        if unknown:
            raise InputError(f"{where}: {what}: unknown name {unknown[0]!r} in {v!r} "
                             f"(declare it under [parameters])")


def _symbol_targets(axes: dict, frames: dict, chain: tuple, params: dict) -> set:
    """Nominal symbols an effect term may target (see :attr:`Layout.symbols`)."""
    out = set(PROBE_SYMBOLS) | {f"axis.{a}" for a in axes} | {f"param.{p}" for p in params}
    return out | {f"frame.{f}.{k}" for f in chain if f in frames for k in FRAME_KEYS}


def _parse_effects(raw, axes: dict, squareness: dict, params: dict, where: str,
                   symbols: set = frozenset()) -> tuple:
    """Validate ``[effects.NAME]`` tables -> tuple of :class:`Effect` (``symbols``: the
    nominal symbols that may be targets)."""
    from .expressions import variables

    require(isinstance(raw, dict), f"{where}: [effects] must be tables [effects.NAME]")
    targets = {n for a in axes.values() for n in a.component_errors + a.location_errors}
    targets |= set(squareness)     # a squareness that varies (with temperature ...)
    targets |= {f"{side}.{k}" for side in ("work", "tool") for k in TWIST_KEYS}
    targets |= set(symbols)        # a nominal symbol of the chain (param.d, probe.Zp ...)
    builtin = {n for a in axes.values() for n in a.component_errors + a.location_errors}
    builtin |= set(squareness) | set(params) | set(axes) | {"Xp", "Yp", "Zp"}
    seen: dict = {}
    out = []
    for en, spec in raw.items():
        require(isinstance(spec, dict) and isinstance(spec.get("kind"), str),
                f"{where}: effect {en} needs a 'kind'")
        terms = spec.get("terms")
        require(isinstance(terms, list) and terms, f"{where}: effect {en} needs 'terms'")
        parsed = []
        for t in terms:
            require(isinstance(t, dict) and {"parameter", "target", "basis"} <= set(t),
                    f"{where}: effect {en}: each term needs parameter, target and basis")
            pn, target, basis = str(t["parameter"]), str(t["target"]), str(t["basis"])
            require(_NAME.match(pn) is not None and pn not in builtin,
                    f"{where}: effect {en}: bad or clashing parameter name {pn!r}")
            require(seen.setdefault(pn, en) == en,
                    f"{where}: parameter {pn} used by effects {seen[pn]} and {en}")
            # a parameter of an earlier effect is a target too (the loop run on an augmented
            # layout: a thermal coefficient that itself varies): nested effects
            require(target in targets or (target in seen and seen[target] != en),
                    f"{where}: effect {en}: unknown target {target!r}")
            for v in variables(basis):
                require(_NAME.match(v) is not None and v not in builtin - set(axes)
                        - set(PROBE_NAMES) and v not in seen,
                        f"{where}: effect {en}: basis uses {v!r}")
            parsed.append(EffectTerm(pn, target, basis))
        info = {k: v for k, v in spec.items() if k not in ("kind", "terms")}
        out.append(Effect(str(en), spec["kind"], tuple(parsed), info))
    return tuple(out)


def shipped_layout_dir():
    """The folder of the layout files shipped in the package."""
    return resources.files("volerr") / "layouts"


def layout_names() -> list[str]:
    """Names of the shipped layouts, sorted."""
    return sorted(p.name[:-5] for p in shipped_layout_dir().iterdir() if p.name.endswith(".toml"))


def read_layout(name_or_path) -> Layout:
    """A shipped layout by name (``"MB1"``) or a layout file by path."""
    text, origin = layout_text(name_or_path)
    return parse_layout(text, origin)


def layout_text(name_or_path) -> tuple[str, str]:
    """(TOML text, origin label) of a shipped layout name or a layout file path."""
    s = str(name_or_path)
    if s.endswith(".toml") or "/" in s or "\\" in s:
        p = Path(s)
        require_file(p, f"layout file not found: {s}")
        try:
            return p.read_text(encoding="utf-8-sig"), p.name
        except UnicodeDecodeError:
            raise InputError(f"layout file {s}: not a UTF-8 text file") from None
    names = layout_names()
    folded = [n for n in names if n.upper() == s.upper()]
    if s not in names and len(folded) == 1:  # layout names are case-insensitive: mb1 = MB1
        s = folded[0]
    require(s in names, f"unknown layout {s!r}; known layouts: {' '.join(names)}")
    return (shipped_layout_dir() / f"{s}.toml").read_text(encoding="utf-8"), f"{s}.toml"


def _num(v) -> str:
    return f"{v:g}" if isinstance(v, (int, float)) else str(v)


def describe(lay: Layout, width: int = 94) -> str:
    """Several lines on one layout (``volerr layouts --long``): axes with travel (mm / deg)
    and direction, points on rotary axes (mm), parameters (mm), the description wrapped to
    ``width`` columns."""
    import textwrap

    lines = [f"{lay.name}  ({lay.kind})"]
    for a in lay.axis_names:
        ax = lay.axes[a]
        unit = "deg" if ax.kind == "rotary" else "mm"
        text = (f"  {a}: {ax.kind:6s} travel {_num(ax.travel[0])} .. {_num(ax.travel[1])} "
                f"{unit}, direction ({', '.join(_num(c) for c in ax.direction)})")
        if ax.kind == "rotary":
            text += f", through ({', '.join(_num(c) for c in ax.point)}) mm"
        lines.append(text)
    if lay.parameters:
        lines.append("  parameters: " + ", ".join(f"{k} = {_num(v)} mm"
                                                  for k, v in sorted(lay.parameters.items())))
    desc = " ".join(lay.description.split())
    if desc:
        lines.extend(textwrap.wrap(desc, width=width, initial_indent="  ",
                                   subsequent_indent="  "))
    return "\n".join(lines)
