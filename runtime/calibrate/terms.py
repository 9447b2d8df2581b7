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

from ..errors import require

GROUPS = ("all", "constants", "squareness", "location", "linear", "rotary")


def resolve(spec: str | None, model, default: str = "all") -> list:
    """Parameter names of ``spec`` (comma list of names, axis names and groups; None: the
    ``default`` group), in the model's order."""
    text = spec if spec else default
    axis_of = model.parameter_axis
    squareness = set(model.layout.squareness)
    chosen = set()
    for word in [w.strip() for w in text.split(",") if w.strip()]:
        w = word.upper() if word.lower() not in GROUPS else word.lower()
        if w == "all":
            chosen |= set(model.parameters)
        elif w == "constants":
            chosen |= {p for p in model.parameters if axis_of.get(p) is None}
        elif w == "squareness":
            chosen |= {p for p in model.parameters if p in squareness}
        elif w == "location":
            chosen |= {p for p in model.parameters if axis_of.get(p) is None
                       and p not in squareness}
        elif w == "linear":
            chosen |= {p for p in model.parameters if axis_of.get(p) is not None
                       and axis_of[p] not in model.rotary_axes}
        elif w == "rotary":
            chosen |= {p for p in model.parameters if axis_of.get(p) in model.rotary_axes}
        elif w in model.axes:
            chosen |= {p for p in model.parameters if axis_of.get(p) == w}
        else:
            require(w in model.parameters, f"--parameters: {word!r} is neither a parameter of "
                    f"layout {model.name} nor an axis or a group ({', '.join(GROUPS)})")
            chosen.add(w)
    require(chosen, f"--parameters {text!r} selects no parameter of layout {model.name}")
    return [p for p in model.parameters if p in chosen]


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
