"""Derive every quantity of a layout and emit its numpy module text."""

from __future__ import annotations

import importlib

import sympy as sp

from volerr.machine.layout import Layout, layout_names, read_layout

from . import inverse, lags
from . import volumetric as vol
from .codegen import Function, render_module, shared_preparation
from .kinematics import PROBE, Chain


#: generated file name -> "module:function" returning that file's text (no arguments).
#: Layout-independent derivations (identification solves, probe frame) register here.
EXTRA_MODULES = {
    "three_point.py": "volerr.derive.three_point:generate_module",
    "probe.py": "volerr.derive.probe:generate_module",
    "instruments.py": "volerr.derive.observations:generate_module",
}


#: derivation sources of a layout's module (hashed into its header)
LAYOUT_SOURCES = ("runtime/machine/layout.py", "derive/htm.py", "derive/effects.py",
                  "derive/kinematics.py", "derive/volumetric.py", "derive/inverse.py",
                  "derive/symbols.py", "derive/generate.py")


def module_name(layout_name: str) -> str:
    """File/module name of a layout's generated module (``MB1`` -> ``mb1``)."""
    return layout_name.lower()


def _sigma(name: str) -> sp.Symbol:
    return sp.Symbol(f"s_{name}", real=True)


def derive_functions(layout: Layout) -> list[Function]:
    """All generated functions of one layout."""
    chain = Chain.from_layout(layout)
    pos = [str(s) for s in chain.positions]
    cov = list(layout.covariates)  # effect covariates (augmented layouts only)
    probe = [str(s) for s in PROBE]
    params = [str(s) for s in chain.parameters]
    error = vol.volumetric_error(chain)
    sens = vol.sensitivity(chain, error)
    sigmas = [_sigma(p) for p in params]
    rules = vol.transfer_rules(chain, error)
    transfer_args = sorted({str(s) for e in rules.shift.values() for s in e.free_symbols},
                           key=lambda n: (n not in ("Xo", "Yo", "Zo"), n))
    funcs = [
        Function("volumetric_error", pos + cov + probe + params,
                 # grouped by position and probe symbols: sums of errors share one product
                 [vol.collect_symbols(e, list(chain.positions) + list(PROBE)) for e in error],
                 "First-order volumetric error (dX, dY, dZ), mm."),
        Function("sensitivity", pos + cov + probe, list(sens),
                 "d(dX, dY, dZ)/d(parameter): array (3, n_parameters, *shape).",
                 shape=(3, len(params))),
        Function("exact_error", pos + cov + probe + params, list(vol.exact_error(chain)),
                 "Exact (non-linearised) error of the probe tip, mm: rotations not small."),
        Function("random_error_termwise", pos + cov + probe + [str(s) for s in sigmas],
                 list(vol.random_error_termwise(sens, sigmas)),
                 "Random error by Pahk's term-wise quadrature (eq. 5, 8), mm; arguments "
                 "s_<name> are standard deviations of the parameters."),
        Function("random_error_exact", pos + cov + probe + [str(s) for s in sigmas],
                 list(vol.random_error_exact(sens, sigmas)),
                 "Random error by first-order propagation for independent parameters, "
                 "sqrt(sum_p (d dk/d p)^2 s_p^2), mm; arguments s_<name> are standard "
                 "deviations of the parameters (fused: no sensitivity array)."),
        Function("nominal_jacobian", pos + probe, list(vol.nominal_jacobian(chain)),
                 "Exact d(tool tip x, y, z; tool axis i, j, k)/d(axis positions in AXES order): "
                 "array (6, n_axes, *shape), mm/mm, mm/rad, 1/mm (= 0) and 1/rad.",
                 shape=(6, len(pos))),
        Function("setup_sensitivity", pos + probe, list(vol.setup_sensitivity(chain)),
                 "d(dX, dY, dZ)/d(rigid twist dx, dy, dz, ex, ey, ez) of the workpiece frame "
                 "(columns 0-5, first in the chain: the instrument's placement) and of the tool "
                 "end (columns 6-11, tool frame): array (3, 12, *shape), mm/mm and mm/rad.",
                 shape=(3, 12)),
        Function("symbol_sensitivity", pos + probe, list(vol.symbol_sensitivity(chain)),
                 "d(nominal tool point x, y, z)/d(nominal symbol) in SYMBOLS order (probe "
                 "offset components, axis positions, layout parameters, frame offsets and "
                 "angles): array (3, n_symbols, *shape), mm/mm or mm/rad; the first-order "
                 "error of a change of the symbol's value.",
                 shape=(3, len(layout.symbols))),
        Function("nominal_position", pos + probe, list(vol.nominal_point(chain)),
                 "Nominal probe-tip / tool-tip position in the workpiece frame, mm."),
        Function("tool_axis", pos, list(vol.nominal_tool_axis(chain)),
                 "Nominal tool-axis direction (tool +z) in the workpiece frame, unit vector."),
        Function("work_rotation", pos, list(vol.work_rotation(chain)),
                 "Orientation of the workpiece frame in the base (linear-axis) frame: array "
                 "(3, 3, *shape), v_base = R @ v_work (identity without table axes).",
                 shape=(3, 3)),
        Function("orientation_error", pos + cov + params, list(vol.orientation_error(chain)),
                 "First-order error of the tool-axis direction (i, j, k), rad."),
    ]
    lags.attach(funcs, lags.layout_lags(layout), cov)
    if inverse.applies(layout):
        funcs.extend(inverse.inverse_functions(layout, chain))
    if rules.shift:
        funcs.append(Function(
            "transfer_shift", transfer_args, [rules.shift[k] for k in sorted(rules.shift)],
            "Transfer rules: measured value minus reference value of each parameter for a "
            "measurement at offset (Xo, Yo, Zo) mm, given the angular errors there (rad).",
            output_names=sorted(rules.shift)))
    return funcs


def _constants(layout: Layout) -> dict:
    """The module constants of a layout (names -> Python literal text)."""
    constants = {
        "LAYOUT": repr(layout.name),
        "LAYOUT_SHA256": repr(layout.sha256),
        "AXES": repr(tuple(layout.axis_names)),
        "ROTARY_AXES": repr(tuple(a for a in layout.axis_names
                                  if layout.axes[a].kind == "rotary")),
        "PARAMETERS": repr(tuple(layout.parameter_names)),
        "PARAMETER_AXIS": repr(layout.parameter_axis),
        "PARAMETER_KIND": repr(layout.parameter_kind),
        "SYMBOLS": repr(tuple(layout.symbols)),
    }
    if layout.effects:
        constants["COVARIATES"] = repr(tuple(layout.covariates))
        constants["EFFECTS"] = repr({e.name: e.kind for e in layout.effects})
        if lags.layout_lags(layout):    # (canonical text, column, tau_s, time column)
            constants["LAGS"] = repr(tuple(x[1:] for x in lags.layout_lags(layout)))
    for k, v in sorted(layout.parameters.items()):
        constants[k] = repr(float(v))
    return constants


def _header(layout: Layout, title: str) -> dict:
    sources = LAYOUT_SOURCES + (lags.SOURCES if lags.layout_lags(layout) else ())
    return {"title": title, "layout": layout.name,
            "layout_file": layout.path or f"{layout.name}.toml", "sha256": layout.sha256,
            "sources": sources}


def _helpers(layout: Layout) -> list:
    """Module-level helper source lines (the lag filter, when the effects use one)."""
    return lags.helper_lines() if lags.layout_lags(layout) else []


def generate_module(layout: Layout) -> str:
    """The complete module text of one layout (deterministic)."""
    return render_module(_header(layout, f"Error model of layout {layout.name}."),
                         _constants(layout), derive_functions(layout), _helpers(layout))


def generate_fit_module(layout: Layout) -> str:
    """A reduced module of one layout for fitting: the constants of :func:`generate_module`
    and only ``sensitivity`` and ``setup_sensitivity`` (no exact or random error, inverse,
    Jacobian or transfer rules: a fraction of the derivation; used by ``volerr loop`` for its
    augmented model during the run)."""
    chain = Chain.from_layout(layout)
    pos = [str(q) for q in chain.positions]
    probe = [str(q) for q in PROBE]
    sens = vol.sensitivity(chain, vol.volumetric_error(chain))
    funcs = [Function("sensitivity", pos + list(layout.covariates) + probe, list(sens),
                      "d(dX, dY, dZ)/d(parameter): array (3, n_parameters, *shape).",
                      shape=(3, len(chain.parameters))),
             Function("setup_sensitivity", pos + probe, list(vol.setup_sensitivity(chain)),
                      "d(dX, dY, dZ)/d(rigid twist of the workpiece frame, then of the tool "
                      "end): array (3, 12, *shape), mm/mm and mm/rad.", shape=(3, 12))]
    lags.attach(funcs, lags.layout_lags(layout), layout.covariates)
    return render_module(_header(layout, f"Fitting functions of layout {layout.name} "
                                         f"(reduced module)."), _constants(layout), funcs,
                         _helpers(layout))


def all_generated(progress=None) -> dict:
    """File name -> text of every file of ``generated/``: one module per shipped layout plus
    the layout-independent modules of :data:`EXTRA_MODULES`.  ``progress``: optional wrapper
    of the layout-name iterable (e.g. a tqdm bar)."""
    names = layout_names()
    with shared_preparation():     # layouts share some functions: prepared once
        out = {f"{module_name(n)}.py": generate_module(read_layout(n))
               for n in (progress(names) if progress else names)}
        for filename, target in EXTRA_MODULES.items():
            mod_name, func = target.split(":")
            out[filename] = getattr(importlib.import_module(mod_name), func)()
    return out
