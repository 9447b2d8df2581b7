"""Code generation: sympy expressions -> a plain, vectorised numpy module.

Expressions are printed by sympy's :class:`NumPyPrinter` (plain float literals) after
common-subexpression elimination (``sympy.cse``); jinja2 only lays out the module around them
(header with the layout hash, constants, signatures, docstrings).  Output is deterministic: the
same layout text gives the same bytes.
"""

from __future__ import annotations

import hashlib
from contextlib import contextmanager
from dataclasses import dataclass, field
from importlib import resources
from pathlib import Path

import jinja2
import sympy as sp
from sympy.printing.numpy import NumPyPrinter

from .linewrap import wrap_statement, wrap_text
from .seal import GENERATED_TAG, seal

_DERIVE = Path(__file__).resolve().parent
#: sources that shape every generated module: this printer, the wrapper and the template
PRINTER_SOURCES = ("derive/codegen.py", "derive/linewrap.py", "derive/seal.py",
                   "derive/templates/model.py.j2")
#: units paragraph of a layout's error-model module
MODEL_UNITS = ("Linear positions and probe offsets mm, rotary positions rad (the runtime "
               "converts from deg), translational errors mm, angular errors rad. Errors are "
               "actual minus nominal position of the probe tip / tool centre point in the "
               "workpiece frame, first order unless named exact.")


class _Printer(NumPyPrinter):
    """NumPy printer with plain float literals (no ``numpy.float64(...)`` noise)."""

    def __init__(self):
        super().__init__({"fully_qualified_modules": True, "inline": True,
                          "allow_unknown_functions": False})

    def _print_Float(self, expr):
        return repr(float(expr))

    def _handle_UnevaluatedExpr(self, expr):
        # sympy rewrites re(UnevaluatedExpr(x)); without any re(...) that is the identity
        return super()._handle_UnevaluatedExpr(expr) if expr.has(sp.re) else expr


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
    signature: list = field(default_factory=list)
    doc_lines: list = field(default_factory=list)
    result_lines: list = field(default_factory=list)
    keywords: list = field(default_factory=list)    # e.g. "lags=None" (derive/lags.py)
    prelude: list = field(default_factory=list)     # statements before the expressions


@contextmanager
def _counted_nodes():
    """sympy's canonical ordering (``ordered``, used by ``cse(order="canonical")`` for every
    Add and Mul it rebuilds) sorts by node count, then by ``default_sort_key`` within ties, and
    recounts the nodes from scratch at every level of the tree.  Here the same stable sort is
    done with each sub-expression's count remembered for the duration: the same order, so the
    same generated text (a test compares the orders)."""
    from sympy.core import sorting
    from sympy.simplify import cse_main

    plain_count, plain_ordered = sorting._node_count, cse_main.ordered
    memo = {}

    def counted(e):
        if not e.args:
            return 0.5 if e.is_Float else 1
        n = memo.get(e)
        if n is None:
            n = memo[e] = 1 + sum(map(counted, e.args))
        return n

    sorting._node_count = counted
    cse_main.ordered = canonical_order
    try:
        yield
    finally:
        sorting._node_count, cse_main.ordered = plain_count, plain_ordered


def canonical_order(seq, keys=None, default=True, warn=False):
    """``sympy.ordered`` with its default keys, as one stable sort (other calls: sympy's)."""
    from sympy.core import sorting

    if keys is not None or not default:
        return sorting.ordered(seq, keys, default, warn)
    seq = list(seq)
    if len(seq) < 2:
        return iter(seq)
    nodes = [sorting._nodes(a) for a in seq]
    idx = range(len(seq))
    if len(set(nodes)) == len(nodes):
        return iter([seq[i] for i in sorted(idx, key=nodes.__getitem__)])
    dsk = sorting.default_sort_key
    return iter([seq[i] for i in sorted(idx, key=lambda i: (nodes[i], dsk(seq[i])))])


#: prepared functions of the current :func:`shared_preparation` block (None outside one)
_PREPARED: dict | None = None


@contextmanager
def shared_preparation():
    """Within this block a function equal to one already prepared (same name, arguments,
    output expressions, shape, names and docstring: several layouts share a tool axis or a
    nominal position) reuses that preparation instead of running ``cse`` and the printer
    again: the same input gives the same text.  Used by ``derive --all``; the memo lives only
    as long as the block."""
    global _PREPARED
    outer, _PREPARED = _PREPARED, ({} if _PREPARED is None else _PREPARED)
    try:
        yield
    finally:
        _PREPARED = outer


def _prepare(f: Function) -> Function:
    if _PREPARED is None:
        return _prepare_new(f)
    key = (f.name, tuple(f.args), tuple(f.outputs), f.shape, tuple(f.output_names or ()), f.doc,
           tuple(f.keywords), tuple(f.prelude))
    done = _PREPARED.get(key)
    if done is None:
        done = _PREPARED[key] = _prepare_new(f)
    elif done is not f:
        for name in ("body", "result", "signature", "doc_lines", "result_lines"):
            setattr(f, name, list(getattr(done, name)) if name != "result" else done.result)
    return f


def _prepare_new(f: Function) -> Function:
    nonzero = [(i, e) for i, e in enumerate(f.outputs) if e != 0] if f.shape else \
        list(enumerate(f.outputs))
    exprs = [e for _, e in nonzero]
    with _counted_nodes():
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
    f.signature = wrap_statement(f"def {f.name}({', '.join(f.args + f.keywords)}):", hang=8)
    shapes = ", ".join(f"numpy.shape({a})" for a in f.args)
    body.insert(0, f"_shape = numpy.broadcast_shapes({shapes})")
    body[:0] = f.prelude
    f.body = [line for stmt in body for line in wrap_statement(stmt, indent="    ")]
    f.doc_lines = wrap_text(f.doc, indent="    ")
    f.result_lines = wrap_statement(f"return {f.result}", indent="    ")
    return f


def _unravel(i: int, shape: tuple) -> tuple:
    out = []
    for n in reversed(shape):
        out.append(i % n)
        i //= n
    return tuple(reversed(out))


def source_path(name: str) -> Path:
    """Path of a derivation source named relative to the repository (``derive/htm.py``,
    ``runtime/machine/layout.py``), resolved in the installed packages."""
    top, _, rest = name.partition("/")
    if top == "derive":
        return _DERIVE / rest
    if top == "runtime":
        return Path(str(resources.files("volerr"))) / rest
    raise ValueError(f"unknown source {name!r}")


def sources_sha256(names) -> str:
    """sha256 over the named source files (name and bytes of each, in the given order)."""
    h = hashlib.sha256()
    for name in names:
        h.update(name.encode() + b"\0" + source_path(name).read_bytes() + b"\0")
    return h.hexdigest()


def render_module(header: dict, constants: dict, functions: list[Function],
                  helpers=()) -> str:
    """Module source text.

    ``header``: ``title``, ``layout`` (the ``volerr derive`` argument), ``layout_file`` and its
    ``sha256``, ``sources`` (derivation sources relative to the repository; the printer's are
    added) and optionally ``units`` (the module's Units paragraph, default: error-model units).
    ``constants``: name -> Python literal.  The header records the sympy version and the
    sha256 over the derivation sources next to the input's sha256.  ``helpers``: source lines
    of module-level helper functions (printed after the constants).  The last line is the
    sha256 of the text above it (:func:`volerr.derive.seal.seal`): ``volerr derive``
    replaces a file only while it is as written (else ``--force``)."""
    sources = tuple(header.get("sources", ())) + PRINTER_SOURCES
    header = {**header, "sympy_version": sp.__version__,
              "sources_sha256": sources_sha256(sources),
              "sources_lines": wrap_text(", ".join(sources), width=95),
              "units_lines": wrap_text(header.get("units", MODEL_UNITS))}
    consts = {k: wrap_statement(f"{k} = {v}") for k, v in constants.items()}
    env = jinja2.Environment(
        loader=jinja2.FileSystemLoader(str(resources.files("volerr.derive") / "templates")),
        keep_trailing_newline=True, trim_blocks=True, lstrip_blocks=True,
        undefined=jinja2.StrictUndefined)
    template = env.get_template("model.py.j2")
    text = template.render(header=header, constants=consts, helpers=list(helpers),
                           functions=[_prepare(f) for f in functions])
    return seal(text, GENERATED_TAG)    # the last line: what volerr derive may replace
