"""Instrument files of a layout's model with planted errors (``volerr simulate --instrument``).

What a user needs to try a calibration before the machine time is spent: a sphere / R-test
file (``volerr formats sphere``) and a ballbar file (``volerr formats ballbar``) of the
layout's first-order model (:func:`volerr.instruments.sphere.simulate`,
:func:`volerr.instruments.ballbar.simulate`) with the errors planted by name, so that
``volerr calibrate LAYOUT FILE`` can be compared with the truth.

Planted errors (:func:`planted_functions`): ``NAME=VALUE`` pairs in the units ``calibrate``
reports -- a constant (``EC0Y`` urad, ``EX0C`` um, ``EA0C`` urad) or the slope of a
component error (``EXX@slope`` um/mm, ``EAX@slope`` urad/mm, zero at the middle of the
axis' travel) -- or an error directory.  Defaults per instrument: :data:`DEFAULT_PLANTED`.

Geometry (workpiece frame, mm):

* sphere: spheres at :func:`default_centres` (or given), the rotary axes over their travel
  (at most 320 deg) in ``steps`` equal steps each, every combination; a probe of ``tool``
  (default 0, 0, -120 mm: a 120 mm probe below the reference point, docs/conventions.md);
  poses outside the travel are left out; every placement's true
  centre is off its nominal one by a few um (seeded), as a real sphere's is;
* ballbar: three ISO 230-4 circles (XY, YZ, ZX) about the nominal tool point at the middle
  of the travel (rotary axes at 0), both directions, 180 readings per direction, in one file
  whose ``placement`` column names the circle.
"""

from __future__ import annotations

import numpy as np

from ..errors import InputError, require

# the planted errors when none are given (um, urad, um/mm) and the instruments: stated
# in volerr.choices, which --help reads without importing numpy
from ..choices import SIMULATED_INSTRUMENTS as INSTRUMENTS  # noqa: E402  (stated once, light)
from ..choices import SIMULATED_PLANTED as DEFAULT_PLANTED  # noqa: E402
#: the tool offset of simulated sphere files, mm: a 120 mm probe hanging below the reference
#: point (tool frame, +z towards the spindle: docs/conventions.md)
PROBE = (0.0, 0.0, -120.0)
#: readings per direction of a simulated ballbar circle
BALLBAR_POINTS = 180


def parse_planted(text: str, model) -> dict:
    """``"EX0B=12,EXX@slope=0.01"`` -> {name: value} (report units), names of the layout."""
    out = {}
    for part in [p.strip() for p in text.replace(";", ",").split(",") if p.strip()]:
        name, eq, value = part.partition("=")
        name = name.strip()
        require(eq == "=" and name, f"--plant {text!r}: write NAME=VALUE pairs, e.g. "
                                    f"EX0C=15,EXX@slope=0.01")
        base, _, term = name.partition("@")
        require(base in model.parameters, f"--plant: {base!r} is not an error parameter of "
                                          f"{model.name}")
        require(term in ("", "slope"), f"--plant: {name!r}: only constants and @slope terms "
                                       f"can be planted")
        require((term == "slope") == (model.parameter_axis[base] is not None),
                f"--plant: {name!r}: " + ("a component error is planted as NAME@slope" if
                                          not term else "a constant has no slope"))
        require(name not in out, f"--plant: {name} given twice")
        try:
            v = float(value)
        except ValueError:
            raise InputError(f"--plant: {name} = {value.strip()!r} is not a number") from None
        require(np.isfinite(v) and abs(v) <= 1e4,
                f"--plant: {name} = {value.strip()} must be a finite number of at most 1e4")
        out[name] = v
    require(out, "--plant: no error given")
    return out


def planted_functions(model, planted: dict):
    """:class:`volerr.tables.ErrorFunctions` of planted errors {name: value in report units}:
    constants as constants, ``@slope`` terms as straight lines through zero at mid-travel."""
    from ..tables.functions import ErrorFunctions
    from ..tables.table import ErrorTable

    columns: dict = {}
    constants = {}
    for name, v in planted.items():
        base = name.split("@")[0]
        scale = 1e-6 if base[1] in "ABC" else 1e-3           # urad -> rad, um -> mm
        axis = model.parameter_axis[base]
        if axis is None:
            constants[base] = v * scale
            continue
        lo, hi = model.travel[axis]
        q = np.linspace(lo, hi, 11)
        columns.setdefault(axis, {})[base] = v * scale * (q - 0.5 * (lo + hi))
    tables = {a: ErrorTable(a, np.linspace(*model.travel[a], 11), cols)
              for a, cols in columns.items()}
    return ErrorFunctions(tables, constants, model)


def default_planted(model, instrument: str) -> dict:
    """The default planted errors of ``instrument`` that the layout has."""
    return {k: v for k, v in DEFAULT_PLANTED[instrument].items()
            if k.split("@")[0] in model.parameters}


def _middle(model) -> np.ndarray:
    """Axis positions (1, n_axes) at the middle of the linear travel, rotary axes at 0."""
    q = [0.0 if a in model.rotary_axes else 0.5 * sum(model.travel[a]) for a in model.axes]
    return np.array([q])


def default_centres(model) -> list:
    """Two sphere centres (workpiece frame, mm): the nominal tool point at the middle of the
    travel with the tool offset (0, 0, -120) mm (a 120 mm probe below the reference point,
    docs/conventions.md), and one 20 % of the travel away in X and Y (sphere test
    plans use two or more placements: one alone cannot tell a location error from the
    sphere's own position)."""
    mid = model.nominal_position(_middle(model), PROBE)[0]
    span = [model.travel[a][1] - model.travel[a][0] for a in model.axes[:2]]
    return [tuple(mid), (mid[0] + 0.2 * span[0], mid[1] + 0.2 * span[1], mid[2])]


def sphere_columns(model, funcs, centres=None, steps: int = 9, tool=PROBE,
                   noise_um: float = 0.3, seed: int = 0) -> dict:
    """Columns of a sphere file (frame work) of the model with the errors ``funcs``."""
    from . import sphere

    require(model.rotary_axes, f"{model.name} has no rotary axis: a sphere / R-test file "
                               f"calibrates rotary axes (use --instrument deviations or "
                               f"ballbar)")
    require(2 <= steps <= 1000, "--steps must be between 2 and 1000")
    centres = default_centres(model) if centres is None else centres
    rotary = {a: np.linspace(model.travel[a][0], min(model.travel[a][1],
                                                     model.travel[a][0] + 320.0), steps)
              for a in model.rotary_axes}
    poses = sphere.plan(model, centres, rotary, tool)
    q = np.column_stack([poses["positions"][a] for a in model.axes])
    values = {k: np.broadcast_to(np.asarray(v, float), (len(q),))
              for k, v in funcs(q).items()}
    values.update(funcs.constants)
    rng = np.random.default_rng(seed)
    offsets = {str(k + 1): rng.normal(0.0, 0.004, 3) for k in range(len(centres))}
    return sphere.simulate(model, values, poses, tool, offsets, noise_um, seed)


def ballbar_columns(model, funcs, radius: float | None = None, noise_um: float = 0.3,
                    seed: int = 0) -> dict:
    """Columns of a ballbar file of three circles (XY, YZ, ZX; ``placement``) about the
    nominal tool point at the middle of the travel; ``radius`` mm (default: 100 mm, at most
    40 % of the shortest linear travel)."""
    from . import ballbar

    lin = [a for a in model.axes if a not in model.rotary_axes]
    shortest = min(model.travel[a][1] - model.travel[a][0] for a in lin)
    radius = min(100.0, 0.4 * shortest) if radius is None else float(radius)
    require(0 < radius <= 0.5 * shortest, f"--radius must be positive and at most half the "
                                          f"shortest travel ({0.5 * shortest:g} mm)")
    centre = model.nominal_position(_middle(model), (0.0, 0.0, 0.0))[0]
    rotary = {a: 0.0 for a in model.rotary_axes} or None
    cols: dict = {}
    for k, plane in enumerate(("XY", "YZ", "ZX")):
        part = ballbar.simulate(model, funcs, plane, radius, centre, (0.0, 0.0, 0.0), rotary,
                                BALLBAR_POINTS, noise_um, "both", seed=seed + 2 * k)
        part["placement"] = np.array([plane] * len(part["dr_um"]), dtype=object)
        for key, v in part.items():
            cols[key] = np.concatenate([cols[key], v]) if key in cols else v
    return cols


def header_line(model, planted: dict | None, source: str) -> str:
    """The file's first line, a comment (skipped by every reader): what was planted."""
    if planted is None:
        return f"# volerr simulate: {model.name}, errors of {source}\n"
    text = ", ".join(f"{k}={v:g}" for k, v in planted.items())
    return f"# volerr simulate: {model.name}, planted (um, urad, um/mm): {text}\n"


def csv_text(cols: dict) -> str:
    """The columns as CSV (6 decimals mm / deg, 5 um; labels as text; no negative zero)."""
    from ..units import num

    names = list(cols)
    n = len(cols[names[0]])
    lines = [",".join(names)]
    for i in range(n):
        lines.append(",".join(
            str(cols[k][i]) if k == "placement" else
            num(cols[k][i], ".5f" if k.endswith("_um") else ".0f" if k == "direction"
                else ".6f") for k in names))
    return "\n".join(lines) + "\n"


#: options of ``volerr simulate`` that only the deviations campaign uses: (name, default)
DEVIATION_ONLY = (("probe", None), ("rounds", 1), ("effect", []), ("magnitude_um", 5.0))
#: options of the instrument files: (name, the instruments that use it)
INSTRUMENT_ONLY = (("plant", ("sphere", "ballbar")), ("errors", ("sphere", "ballbar")),
                   ("steps", ("sphere",)), ("radius", ("ballbar",)))


def refuse_unused(instrument: str, options: dict) -> None:
    """Refuse, one line, an option of ``volerr simulate`` (``options``: name -> value, as
    the command's attributes; None or the default: not given) that the file of
    ``instrument`` (deviations, sphere, ballbar) does not use: never silently ignored."""
    for name, default in () if instrument == "deviations" else DEVIATION_ONLY:
        require(options.get(name) in (default, None),
                f"--{name.replace('_', '-')} is for --instrument deviations")
    for name, users in INSTRUMENT_ONLY:
        require(options.get(name) is None or instrument in users,
                f"--{name} is for --instrument {' / '.join(users)}")


def instrument_file(layout, instrument: str, *, plant: str | None = None, errors=None,
                    steps: int | None = None, radius: float | None = None,
                    noise_um: float = 0.3, seed: int = 0,
                    accept_implausible: bool = False) -> tuple[str, str]:
    """``volerr simulate --instrument sphere|ballbar``: the file's text and the line the
    command prints (without its ``-> FILE`` tail).

    ``plant``: the planted errors as ``NAME=V,...`` in the units calibrate reports (um, urad,
    um/mm; default :func:`default_planted`); ``errors``: an error directory planted instead;
    ``steps``: sphere positions per rotary axis (default 9); ``radius``: ballbar circle
    radius, mm; ``noise_um``: reading noise (1 sigma); ``seed`` of the noise.
    """
    import math
    from pathlib import Path

    from ..machine.model import Model, load

    require(not (plant and errors), "give --plant or --errors, not both")
    require(math.isfinite(noise_um) and 0 <= noise_um <= 1e3,
            "--noise-um must be finite, between 0 and 1000 um")
    model = layout if isinstance(layout, Model) else load(layout)
    if errors:
        require(Path(errors).is_dir(), f"error directory not found: {errors}")
        from ..tables.functions import ErrorFunctions

        planted, funcs = None, ErrorFunctions.from_dir(errors, model,
                                                       accept_implausible=accept_implausible)
    else:
        planted = (parse_planted(plant, model) if plant is not None
                   else default_planted(model, instrument))
        funcs = planted_functions(model, planted)
    if instrument == "sphere":
        cols = sphere_columns(model, funcs, steps=steps or 9, noise_um=noise_um, seed=seed)
    else:
        cols = ballbar_columns(model, funcs, radius, noise_um, seed)
    text = header_line(model, planted, errors) + csv_text(cols)
    n = len(next(iter(cols.values())))
    what = ", ".join(f"{k}={v:g}" for k, v in planted.items()) if planted is not None \
        else f"the errors of {errors}"
    return text, (f"{n} {instrument} readings of {model.name} ({what}; noise "
                  f"{noise_um:g} um)")
