"""The parameters of a calibration: which are fitted (``--parameters``), and how each column of
the design is named and reported.

A constant (squareness, location error of a rotary axis) is one column, reported in um or urad.
A component error of an axis is a Legendre series in its own axis position over the measured
range ``[lo, hi]``: ``e(q) = sum_k c_k P_k(u)``, ``u = (2 q - lo - hi) / (hi - lo)``.  Its terms
are reported as

* ``NAME@offset`` = ``c_0``, the mean value over the range (um / urad);
* ``NAME@slope`` = ``2 c_1 / (hi - lo)``, the slope of the least-squares straight line of the
  function over the range (the Legendre terms are orthogonal on it), per mm of a linear axis
  or per deg of a rotary axis (``um/mm``, ``urad/mm``, ``um/deg``, ``urad/deg``);
* ``NAME@P2`` ... ``NAME@Pk`` = ``c_k`` (um / urad).

A rotary axis measured over (nearly) a full turn has Fourier series instead
(:func:`volerr.estimate.design.series_basis`): ``NAME@offset``, ``NAME@cos1``, ``NAME@sin1``,
``NAME@cos2`` ... (um / urad); the first harmonic of its radial and tilt errors is its
location error (ISO 230-7), fixed there by the gauge.
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field

from ..errors import require

GROUPS = ("all", "constants", "squareness", "location", "linear", "rotary")

#: a term of a component error's series as printed: offset, slope, P2 ..., cos1, sin1 ...
_TERM = re.compile(r"^(offset|slope|p(\d+)|cos(\d+)|sin(\d+))$")


@dataclass
class Request:
    """What ``--parameters`` asks for: ``parameters`` the model's parameters with at least one
    column fitted (model order); ``only`` parameter -> the series terms fitted (degrees ``k``
    of the labels ``(p, k)``; a parameter absent from it: its whole series); ``reversals`` the
    linear axes whose reversal ``RV_<axis>`` is fitted (ISO 230-2's B, from the readings'
    directions of motion)."""

    parameters: list
    only: dict = field(default_factory=dict)
    reversals: list = field(default_factory=list)

    def max_term(self) -> int:
        """Highest series degree a term request needs (0 when none)."""
        return max((max(ks) for ks in self.only.values()), default=0)

    def fits(self, label) -> bool:
        """The design column ``label`` ``(parameter, k)`` is requested."""
        p, k = label
        return p == "setup" or (p in self.parameters
                                and (p not in self.only or k in self.only[p]))


def term_degree(term: str) -> int | None:
    """Series degree ``k`` of a printed term (``offset`` 0, ``slope`` 1, ``P2`` 2 ...;
    Fourier ``cos1`` 1, ``sin1`` 2, ``cos2`` 3 ...); None when not a term name."""
    m = _TERM.match(term.lower())
    if not m:
        return None
    if m.group(2):
        return int(m.group(2))
    if m.group(3):
        return 2 * int(m.group(3)) - 1 if int(m.group(3)) >= 1 else None
    if m.group(4):
        return 2 * int(m.group(4)) if int(m.group(4)) >= 1 else None
    return 0 if m.group(1) == "offset" else 1


def _group(w: str, model) -> set:
    axis_of = model.parameter_axis
    squareness = set(model.layout.squareness)
    if w == "all":
        return set(model.parameters)
    if w == "constants":
        return {p for p in model.parameters if axis_of.get(p) is None}
    if w == "squareness":
        return {p for p in model.parameters if p in squareness}
    if w == "location":
        return {p for p in model.parameters if axis_of.get(p) is None and p not in squareness}
    if w == "linear":
        return {p for p in model.parameters if axis_of.get(p) is not None
                and axis_of[p] not in model.rotary_axes}
    return {p for p in model.parameters if axis_of.get(p) in model.rotary_axes}


def request(spec, model, default=("all",)) -> Request:
    """The :class:`Request` of ``spec`` (``--parameters``: comma list of parameter names, terms
    as printed -- ``EXX@slope``, ``EZY@P2``, ``EXC@cos1`` --, reversals ``RV_X``, axis names
    and groups); None: the words ``default`` (a list, e.g.
    :func:`volerr.calibrate.defaults.default_parameters`).  Empty or malformed text is refused
    (InputError, one line)."""
    if spec is None:
        words, text = list(default), ",".join(default)
    else:
        text = str(spec)
        words = [w.strip() for w in text.split(",")]
        require(text.strip() and all(words), f"--parameters {text!r}: empty name (give a comma "
                f"list of parameter names, terms such as EXX@slope, axes or groups: "
                f"{', '.join(GROUPS)})")
    whole, only, reversals = set(), {}, []
    for word in words:
        # a combination as printed (EXX@slope-EYY@slope): each of its terms
        for part in re.split(r"\s*[-+]\s*", word) if "@" in word else [word]:
            require(part, f"--parameters: {word!r}: malformed combination")
            _add(part, model, whole, only, reversals)
    for p in whole:
        only.pop(p, None)
    chosen = whole | set(only)
    require(chosen or reversals, f"--parameters {text!r} selects no parameter of layout "
                                 f"{model.name}")
    return Request([p for p in model.parameters if p in chosen], only, reversals)


def _add(word: str, model, whole: set, only: dict, reversals: list) -> None:
    """Add one word of ``--parameters`` to the request being built."""
    w = word.lower() if word.lower() in GROUPS else word.upper()
    if w in GROUPS:
        whole |= _group(w, model)
    elif w in model.axes:
        whole |= {p for p in model.parameters if model.parameter_axis.get(p) == w}
    elif w.startswith("RV_"):
        axis = word[3:]
        require(axis in model.axes and axis not in model.rotary_axes,
                f"--parameters: {word!r}: a reversal RV_<axis> names a linear axis of layout "
                f"{model.name} ({', '.join(a for a in model.axes if a not in model.rotary_axes)})")
        if axis not in reversals:
            reversals.append(axis)
    elif "@" in w:
        name, _, term = word.partition("@")
        name = name.upper()
        k = term_degree(term)
        require(name in model.parameters, f"--parameters: {word!r}: {name!r} is not a "
                f"parameter of layout {model.name}")
        require(model.parameter_axis.get(name) is not None, f"--parameters: {word!r}: {name} "
                f"is a constant (no series terms): give {name}")
        require(k is not None, f"--parameters: {word!r}: unknown term {term!r} (offset, slope, "
                f"P2, P3 ..., cos1, sin1 ...)")
        only.setdefault(name, set()).add(k)
    else:
        require(w in model.parameters, f"--parameters: {word!r} is neither a parameter of "
                f"layout {model.name} nor a term (EXX@slope), a reversal (RV_X), an axis or a "
                f"group ({', '.join(GROUPS)})")
        whole.add(w)


def resolve(spec: str | None, model, default: str = "all") -> list:
    """Parameter names of ``spec`` (comma list of names, axis names and groups; None: the
    ``default`` group), in the model's order."""
    return request(spec, model, [w.strip() for w in default.split(",")]).parameters


def term_name(label, fourier: bool = False) -> str:
    """Report name of a design column label ``(parameter, degree or None)``; ``fourier``: the
    parameter's series is a Fourier series (a periodic rotary axis: ``@cos1``, ``@sin1``,
    ``@cos2`` ...)."""
    p, k = label
    if p == "setup":
        return f"setup:{k}"
    if k is None or k == "extra":
        return p
    if k == 0:
        return f"{p}@offset"
    if fourier:
        return f"{p}@{'cos' if k % 2 else 'sin'}{(k + 1) // 2}"
    return f"{p}@slope" if k == 1 else f"{p}@P{k}"


def namer(model, ranges: dict):
    """``label -> report name`` of this model and measured range (Fourier series of the
    periodic rotary axes: :func:`volerr.estimate.design.periodic`)."""
    from ..estimate.design import periodic

    def name(label) -> str:
        axis = model.parameter_axis.get(label[0]) if label[0] != "setup" else None
        return term_name(label, bool(axis) and periodic(model, axis, ranges))

    return name


def is_angular(name: str) -> bool:
    """An angular parameter (rad inside): E[ABC]* components and E[ABC]0* constants."""
    return len(name) >= 3 and name[0] == "E" and name[1] in "ABC"


def report(label, value: float, std: float, model, ranges: dict, unit=None) -> dict:
    """``{"value", "unit", "std"}`` of a column's coefficient (mm or rad inside; ``unit``:
    (factor, unit) of an extra term)."""
    from ..estimate.design import periodic

    p, k = label
    angular = is_angular(p)
    factor, unit = unit or ((1e6, "urad") if angular else (1e3, "um"))
    if k == 1 and not periodic(model, model.parameter_axis[p], ranges):
        axis = model.parameter_axis[p]
        lo, hi = ranges[axis]
        factor *= 2.0 / (hi - lo)
        unit += "/deg" if axis in model.rotary_axes else "/mm"
    return {"value": float(value) * factor, "unit": unit, "std": float(std) * abs(factor)}
