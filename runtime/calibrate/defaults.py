"""What ``volerr calibrate`` fits when no ``--parameters`` is given: what each instrument of the
campaign is used for (documented per kind in ``docs/formats.md``, section ``calibrate-json``),
the union for a mixed campaign.

* ``ballbar`` (ISO 230-4 circles, ISO 10791-6 rotary sweeps): the squareness errors, the scale
  errors of the linear axes (``E<dir><axis>@slope`` of their positioning errors: with the bar
  length unknown only their differences are determined, reported as combinations), the
  curvature of the straightness errors (``@P2``), the reversal of every linear axis
  (``RV_<axis>``, fitted when the files hold both directions of motion) and, on a layout with
  rotary axes, their location errors (fitted when a trace sweeps the axis) -- what
  ``volerr ballbar evaluate`` diagnoses;
* ``sphere`` (touch probe on a sphere, R-test): the location errors of the rotary axes;
* ``artifact`` (ball / hole plate, step gauge): the component errors of the linear axes and
  the squareness errors (the ball-plate method determines a CMM's 21 parameters);
* ``interferometer`` (laser lines): the component errors of the linear axes (a run determines
  the errors of its axis and mode; the report names what the runs leave undetermined);
* ``distances`` (tracking interferometer) and ``deviations`` (3-D deviations): every parameter
  of the layout.
"""

from __future__ import annotations

import numpy as np

from ..machine.iso_names import along_component

#: instrument kind -> the groups / term kinds it is used for (see the module docstring)
USES = {
    "ballbar": ("squareness", "scale", "straightness_p2", "reversal", "location"),
    "sphere": ("location",),
    "artifact": ("linear", "squareness"),
    "interferometer": ("linear",),
    "distances": ("all",),
    "deviations": ("all",),
}


def _linear_axes(model) -> list:
    """``[(axis, index of its direction)]`` of the linear axes (X ~ 0, Y ~ 1, Z ~ 2)."""
    out = []
    for a in model.axes:
        if a in model.rotary_axes:
            continue
        out.append((a, int(np.argmax(np.abs(model.layout.axes[a].direction)))))
    return out


def _names(model, use: str) -> list:
    params = model.parameters
    axis_of = model.parameter_axis
    squareness = set(model.layout.squareness)
    if use == "all":
        return list(params)
    if use == "squareness":
        return [p for p in params if p in squareness]
    if use == "location":
        return [p for p in params if axis_of.get(p) is None and p not in squareness]
    if use == "linear":
        return [p for p in params if axis_of.get(p) is not None
                and axis_of[p] not in model.rotary_axes]
    if use == "scale":
        comps = [along_component(model.layout, a) for a, _ in _linear_axes(model)]
        return [f"{p}@slope" for p in comps if p in params]
    if use == "straightness_p2":
        out = []
        for a, i in _linear_axes(model):
            out += [f"E{'XYZ'[j]}{a}@P2" for j in range(3)
                    if j != i and f"E{'XYZ'[j]}{a}" in params]
        return out
    if use == "reversal":
        return [f"RV_{a}" for a, _ in _linear_axes(model)
                if along_component(model.layout, a) in params]
    raise ValueError(use)


def default_parameters(model, kinds, moving=None) -> list[str]:
    """The parameter request (names as ``--parameters`` accepts: parameter names, terms such as
    ``EXX@slope`` / ``EYX@P2``, reversals ``RV_X``) each instrument kind in ``kinds`` is used
    for, the union for several kinds; ordered as the model's parameters, the reversals last.
    Unknown kinds count as ``deviations`` (every parameter).  ``moving``: the axes the
    campaign moves (None: all); a ballbar's location errors of a rotary axis it never turns
    are left out (circles with the rotary axes fixed are not used for them)."""
    wanted: list = []
    for kind in dict.fromkeys(kinds):
        for use in USES.get(kind, ("all",)):
            names = _names(model, use)
            if kind == "ballbar" and use == "location" and moving is not None:
                names = [p for p in names if p[-1] in moving]
            wanted += names
    wanted = list(dict.fromkeys(wanted))
    whole = {w for w in wanted if "@" not in w}
    # a term of a parameter fitted whole is already in the request
    wanted = [w for w in wanted if "@" not in w or w.split("@")[0] not in whole]
    order = {p: i for i, p in enumerate(model.parameters)}
    return sorted(wanted, key=lambda w: (w.startswith("RV_"), order.get(w.split("@")[0], 0)))
