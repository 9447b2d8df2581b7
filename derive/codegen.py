"""Code generation: sympy expressions -> a plain, vectorised numpy module.

Expressions are printed by sympy's :class:`NumPyPrinter` after common-subexpression
elimination (``sympy.cse``); jinja2 only lays out the module around them (header with the
layout hash, constants, signatures, docstrings).  Output is deterministic: the same layout
text gives the same bytes.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from importlib import resources

import jinja2
import sympy as sp
from sympy.printing.numpy import NumPyPrinter


class _Printer(NumPyPrinter):
    """NumPy printer with plain float literals (no ``numpy.float64(...)`` noise)."""

    def __init__(self):
        super().__init__({"fully_qualified_modules": True, "inline": True,
                          "allow_unknown_functions": False})

    def _print_Float(self, expr):
        return repr(float(expr))


_PRINTER = _Printer()


def print_expr(expr) -> str:
    """One expression as numpy source text."""
    return _PRINTER.doprint(expr)


@dataclass
class Function:
    """A generated function.

    ``outputs`` is a list of expressions.  With ``shape`` set (e.g. ``(3, 21)``) the function
    returns one array of ``shape + broadcast(args)`` filled from the flattened outputs, zero
    entries skipped; otherwise it returns a tuple of arrays."""

    name: str
    args: list
    outputs: list
    doc: str
    shape: tuple | None = None
    output_names: list | None = None
    body: list = field(default_factory=list)
    result: str = ""


def _prepare(f: Function) -> Function:
    nonzero = [(i, e) for i, e in enumerate(f.outputs) if e != 0] if f.shape else \
        list(enumerate(f.outputs))
    exprs = [e for _, e in nonzero]
    temps, reduced = sp.cse(exprs, symbols=sp.numbered_symbols("_t"), order="canonical")
    body = [f"{print_expr(s)} = {print_expr(e)}" for s, e in temps]
    if f.shape:
        body.append(f"_out = numpy.zeros({tuple(f.shape)!r} + _shape)")
        for (i, _), r in zip(nonzero, reduced):
            idx = ", ".join(str(k) for k in _unravel(i, f.shape))
            body.append(f"_out[{idx}] = {print_expr(r)}")
        f.result = "_out"
    elif f.output_names:
        body.extend(f"_o{i} = numpy.broadcast_to({print_expr(r)}, _shape)"
                    for i, r in enumerate(reduced))
        pairs = ", ".join(f"{n!r}: _o{i}" for i, n in enumerate(f.output_names))
        f.result = "{" + pairs + "}"
    else:
        body.extend(f"_o{i} = numpy.broadcast_to({print_expr(r)}, _shape)"
                    for i, r in enumerate(reduced))
        f.result = ", ".join(f"_o{i}" for i in range(len(reduced))) + ("," if len(reduced) == 1
                                                                        else "")
    f.body = body
    return f


def _unravel(i: int, shape: tuple) -> tuple:
    out = []
    for n in reversed(shape):
        out.append(i % n)
        i //= n
    return tuple(reversed(out))


def render_module(header: dict, constants: dict, functions: list[Function]) -> str:
    """Module source text: ``header`` (layout, file, sha256, ...), module-level ``constants``
    (name -> Python literal) and the generated ``functions``."""
    env = jinja2.Environment(
        loader=jinja2.FileSystemLoader(str(resources.files("volerr.derive") / "templates")),
        keep_trailing_newline=True, trim_blocks=True, lstrip_blocks=True,
        undefined=jinja2.StrictUndefined)
    template = env.get_template("model.py.j2")
    return template.render(header=header, constants=constants,
                           functions=[_prepare(f) for f in functions])
