"""What every result of the Python API shares, and the callable capability packages.

A result (``volerr.calibrate(...)``, ``volerr.plan(...)``, ``volerr.loop(...)`` ...) is an
object you can read, after statsmodels' ``RegressionResults`` and scipy's ``OptimizeResult``:

* its values as attributes (and ``result["key"]``, the keys of the command's JSON);
* ``to_dict()``: the command's ``--json`` document, as :func:`json.loads` reads it back;
* ``write_json(path)``, ``write_html(path)``, ``write_pdf(path)``: the command's ``--json``,
  ``--html`` and ``--pdf`` files;
* ``summary()``: the text the command prints;
* ``table()``: one row per reported value: name, value, standard uncertainty (k = 1), unit
  and the coverage factor ``k`` of the uncertainty column (always 1: a standard
  uncertainty; an expanded one is ``k * u``); a :class:`pandas.DataFrame` where pandas is
  installed, a list of :class:`Row` otherwise;
* ``figures()``: the figures as :class:`matplotlib.figure.Figure` objects;
* a ``repr`` of one line (the first line of the summary, or the result's headline);
* results are built once: their values are computed before construction, never written
  back into ``data`` afterwards.

The callable packages: ``volerr.calibrate`` is both a sub-package (``volerr.calibrate.run``,
``volerr.calibrate.terms`` ...) and the function of the command.  Python binds the attribute
``volerr.calibrate`` to the sub-package's module object as soon as anything imports it, so a
function of that name in ``volerr/__init__.py`` would be replaced by the module after
``import volerr.calibrate.run``.  Instead the package module itself is made callable
(:func:`callable_package`: its ``__class__`` becomes :class:`CallableModule`, whose
``__call__`` calls the package's own API function), so ``volerr.calibrate(...)`` works
whatever was imported before, and ``volerr.calibrate.run`` keeps working.
"""

from __future__ import annotations

import json
import sys
import types
from typing import NamedTuple


class Row(NamedTuple):
    """One row of :meth:`ResultMixin.table`: a reported value with its standard uncertainty
    ``std`` (k = 1; the expanded uncertainty is ``k * std``), both in ``unit``."""

    name: str
    value: float
    std: float | None
    unit: str
    k: float = 1.0


def _plain(o):
    """numpy scalars and arrays as JSON values (as the commands write them)."""
    import numpy as np

    if isinstance(o, (np.floating, np.integer, np.bool_)):
        return o.item()
    if isinstance(o, np.ndarray):
        return o.tolist()
    raise TypeError(f"not JSON serialisable: {type(o).__name__}")


def rows_of(parameters: dict) -> list:
    """Rows of a ``{name: {"value", "std", "unit"}}`` mapping (the commands' JSON form)."""
    return [Row(n, v.get("value"), v.get("std"), v.get("unit", ""), 1.0)
            for n, v in (parameters or {}).items() if isinstance(v, dict) and "value" in v]


def as_table(rows: list):
    """``rows`` as a :class:`pandas.DataFrame` (columns name, value, std, unit, k) where
    pandas is installed, else the list itself."""
    try:
        import pandas as pd
    except ImportError:
        return list(rows)
    return pd.DataFrame([r._asdict() for r in rows], columns=list(Row._fields))


def html_page(title: str, summary: str, rows: list) -> str:
    """A plain HTML page: ``title``, the console text ``summary`` and the table ``rows``
    (:class:`Row`), every text escaped."""
    from html import escape

    def cell(v):
        return "" if v is None else escape(f"{v:.6g}" if isinstance(v, float) else str(v))

    from .report.fmt import unit
    from .report.page import document

    body = "".join(f"<tr><td>{cell(r.name)}</td><td>{cell(r.value)}</td><td>{cell(r.std)}"
                   f"</td><td>{cell(unit(r.unit))}</td><td>{cell(r.k)}</td></tr>\n"
                   for r in (Row(*r) for r in rows))
    head = "".join(f"<th>{h}</th>" for h in ("quantity", "value", "standard uncertainty u",
                                              "unit", "k of u"))
    return document(title, f"<h1>{escape(title)}</h1>\n<pre>{escape(summary)}</pre>\n"
                           f"<table>\n<tr>{head}</tr>\n{body}</table>\n")


class ResultMixin:
    """The shared methods of the API's results (see the module docstring).  A result keeps
    its JSON document in ``data`` (a dict, or a method returning it) and may override
    :meth:`_rows` and :meth:`figures`."""

    def _document(self) -> dict:
        d = self.data
        return d() if callable(d) else d

    def to_dict(self) -> dict:
        """The command's ``--json`` document (a fresh copy of plain JSON values)."""
        return json.loads(json.dumps(self._document(), default=_plain))

    def write_json(self, path, inputs=()):
        """Write :meth:`to_dict` as the command's ``--json`` file; returns its path.
        ``inputs``: files the output must not overwrite."""
        from .fileio import json_text, write_text

        return write_text(path, json_text(self._document(), default=_plain),
                          inputs=list(inputs))

    def write_pdf(self, path, inputs=(), identification=None, title=None):
        """Write the PDF certificate (A4: identification, conditions, results with U and k,
        verdicts and decision rule, budgets, figures; :mod:`volerr.report`); returns its
        path.  ``identification``: a :class:`volerr.certificate.Identification` (default:
        the one in the JSON document)."""
        from .report.stamp import write_pdf

        return write_pdf(path, self, identification, inputs=list(inputs), title=title)

    def summary(self) -> str:
        """The text the command prints on stdout (by default its ``lines``)."""
        return "\n".join(self.lines)

    def _rows(self) -> list:
        return rows_of(self._document().get("parameters"))

    def table(self):
        """Value, standard uncertainty (k = 1), unit and k of every reported value: a
        :class:`pandas.DataFrame` where pandas is installed, else a list of :class:`Row`."""
        return as_table(self._rows())

    def figures(self) -> dict:
        """The result's figures, ``{name: matplotlib.figure.Figure}`` (none by default)."""
        return {}

    def write_html(self, path, inputs=()):
        """Write an HTML page of the result (the command's ``--html`` where it has one; by
        default :meth:`summary` and :meth:`table`); returns its path."""
        from .fileio import write_text

        return write_text(path, html_page(type(self).__name__, self.summary(), self._rows()),
                          inputs=list(inputs))

    def write_plot(self, path, inputs=()):
        """Write the result's main figure as the command's ``--plot`` PNG; returns its path
        (a result with a plot overrides :meth:`png`)."""
        from .fileio import write_bytes

        return write_bytes(path, self.png(), inputs=list(inputs))

    def write_outputs(self, outs, options: dict, ident, inputs=(), title: str | None = None,
                      roles=("plot", "json", "html")) -> None:
        """A command's outputs, inside ``with outs:`` (:class:`volerr.fileio.Outputs`, declared
        by :func:`volerr.fileio.planned_outputs`): the result's own (:meth:`_write_own`),
        then each of ``roles`` that ``options`` (the run's options, a plain dict) gives, by
        ``write_ROLE`` (the plot first: it may record its scale in the JSON), then the
        identification ``ident`` stamped into ``--json`` and ``--html`` and ``--pdf``
        written (:func:`volerr.report.stamp.finish`; ``title``: the PDF's)."""
        from .report import stamp

        self._write_own(outs, options, list(inputs))
        self.write_files(outs, options, inputs, roles)
        stamp.finish(outs, self, ident, inputs=list(inputs), title=title)

    def write_files(self, outs, options: dict, inputs=(), roles=("json", "html", "plot")):
        """Inside ``with outs:``: each output of ``roles`` that ``options`` gives, by the
        result's ``write_ROLE`` (no identification)."""
        for role in roles:
            if options.get(role):
                getattr(self, f"write_{role}")(outs.path("--" + role), inputs=inputs)

    def write_errors_out(self, outs, options: dict, inputs=()) -> None:
        """Inside ``with outs:``: a fit's ``--errors-out DIR`` when ``options`` gives it, by
        the result's ``write_error_tables`` (``accept_implausible`` from ``options``)."""
        if options.get("errors_out"):
            self.write_error_tables(outs.path("--errors-out"), inputs=list(inputs),
                                    shown=options["errors_out"],
                                    accept_implausible=options.get("accept_implausible", False))

    def _write_own(self, outs, options: dict, inputs: list) -> None:
        """The outputs of the command that only this kind of result writes (error tables,
        maps ...), before the report's; by default a fit's ``--predictions-out`` (by
        ``write_predictions``) and ``--errors-out`` (:meth:`write_errors_out`), when
        ``options`` gives them."""
        if options.get("predictions_out"):
            self.write_predictions(outs.path("--predictions-out"), inputs=inputs)
        self.write_errors_out(outs, options, inputs)

    def png(self) -> bytes:
        """The command's ``--plot`` figure as PNG bytes (a result without one: refused)."""
        from .errors import InputError

        raise InputError(f"{type(self).__name__} has no plot")

    def _headline(self) -> str:
        """The line :func:`repr` shows: the first line of :meth:`summary`."""
        text = self.summary().splitlines()
        return text[0] if text else ""

    def __getattr__(self, name):
        # the JSON document's keys as attributes (cal.parameters, plan.files ...)
        if name.startswith("_") or name in ("data",):
            raise AttributeError(name)
        doc = self._document()
        if isinstance(doc, dict) and name in doc:
            return doc[name]
        raise AttributeError(f"{type(self).__name__!r} object has no attribute {name!r}")

    def __repr__(self) -> str:
        first = self._headline()
        if len(first) > 110:
            first = first[:107] + "..."
        return f"<volerr {type(self).__name__}: {first}>"


def run_command(options: dict, inputs, call, *, first: dict | None = None, ident_files=None,
                conditions: dict | None = None, title: str | None = None,
                roles=("plot", "json", "html"), **outputs):
    """A command's run, all or nothing, its refusals in this order: its outputs declared and
    checked (:func:`volerr.fileio.planned_outputs` of ``options``, the run's options as a
    plain dict: ``first``, the report outputs, ``outputs``), its identification
    (:func:`volerr.certificate.from_options` of ``ident_files``, default ``inputs``, and
    ``conditions``), then inside ``with outs:`` ``call(outs, identification)`` (the API
    call; ``outs.path(ROLE)``: where an output it streams goes) and the result's outputs
    (:meth:`ResultMixin.write_outputs`, ``title``, ``roles``); returns the result."""
    from .certificate import from_options
    from .fileio import planned_outputs

    outs = planned_outputs(options, inputs, first=first, **outputs)
    ident = from_options(options, inputs if ident_files is None else ident_files, conditions)
    with outs:
        result = call(outs, ident)
        result.write_outputs(outs, options, ident, inputs, title, roles)
    return result


def file_list(files) -> list:
    """``files`` as a list of file names: one ``str`` or path-like is one file (not the
    characters of its name); a list, tuple or other iterable is taken as it is."""
    import os

    if isinstance(files, (str, bytes, os.PathLike)):
        return [files]
    return list(files)


class CallableModule(types.ModuleType):
    """A package module that can be called: ``volerr.calibrate(...)`` is
    ``volerr.calibrate.__api__(...)``, the package's API function.  ``inspect.signature``
    and ``help`` of the module show that function's keywords and defaults
    (``__signature__``)."""

    def __call__(self, *args, **kwargs):
        return self.__api__(*args, **kwargs)

    @property
    def __signature__(self):
        import inspect

        return inspect.signature(self.__api__)


def callable_package(name: str, function) -> None:
    """Make the (already imported) package module ``name`` callable as ``function``."""
    module = sys.modules[name]
    module.__api__ = function
    module.__class__ = CallableModule


def former_module(package: str, module: str):
    """The module ``__getattr__`` of a package that was once the flat module ``package``:
    the names of its submodule ``module`` stay importable from the package
    (``__getattr__ = former_module(__name__, "solve")``)."""
    def __getattr__(name):
        import importlib

        try:
            return getattr(importlib.import_module(f"{package}.{module}"), name)
        except AttributeError:
            raise AttributeError(f"module {package!r} has no attribute {name!r}") from None
    return __getattr__
