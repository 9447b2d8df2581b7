"""Argument helpers shared by several commands (argparse only, no algorithms)."""

from __future__ import annotations

from pathlib import Path

from volerr.cmm import volmap
from volerr.errors import InputError, require
from volerr.tables.table import METHODS, ErrorFunctions


def add_error_arguments(parser, required: bool = True) -> None:
    """Add ``--errors DIR --method --degree --extrapolate`` to an argparse parser."""
    parser.add_argument("--errors", metavar="DIR", required=required,
                        help="error directory: X.csv, Y.csv, ... (one table per axis) and "
                             "optionally constants.csv")
    parser.add_argument("--method", choices=METHODS, default="linear",
                        help="error functions from the tables: linear or cubic interpolation, "
                             "or least-squares polynomial (default linear)")
    parser.add_argument("--degree", type=int, default=None,
                        help="polynomial degree for --method poly (default: chosen by "
                             "leave-one-out cross-validation)")
    parser.add_argument("--extrapolate", action="store_true",
                        help="evaluate beyond the measured range of a table (default: refuse)")


def error_functions_from_args(args, model) -> ErrorFunctions:
    """:class:`ErrorFunctions` from the arguments added by :func:`add_error_arguments`."""
    return ErrorFunctions.from_dir(args.errors, model, method=args.method, degree=args.degree,
                                   extrapolate=args.extrapolate)


def add_common(p) -> None:
    """Arguments shared with ``volerr diagonals``."""
    p.add_argument("layout", help="layout name (volerr layouts) or layout file")
    add_error_arguments(p)
    p.add_argument("--probe", nargs=3, type=float, metavar=("XP", "YP", "ZP"), default=(0.0, 0.0, 0.0),
                   help="probe / tool offset, mm (default 0 0 0)")
    p.add_argument("--at", action="append", default=[], metavar="AXIS=DEG",
                   help="position of a rotary axis during the test, repeatable (default 0 deg)")
    p.add_argument("--volume", choices=("travel", "measured"), default="travel",
                   help="box of the linear axes: the layout's travel (default) or the part of "
                        "it the error tables cover (no extrapolation either way)")


def parse_at(items) -> dict:
    out = {}
    for item in items or []:
        name, sep, value = item.partition("=")
        require(sep == "=" and name, f"--at expects AXIS=VALUE, got {item!r}")
        try:
            out[name.strip()] = float(value)
        except ValueError:
            raise InputError(f"--at {item!r}: {value!r} is not a number") from None
    return out


def inputs_of(args, model=None) -> list:
    """Files that must never be overwritten: the error tables and a layout file (shipped
    layouts are package files, protected by :class:`volerr.fileio.Outputs` anyway)."""
    files = volmap.error_dir_inputs(args.errors)
    files.extend(layout_inputs(args.layout))
    return files


def layout_inputs(layout) -> list:
    """``[path]`` when LAYOUT names an existing file, else ``[]`` (a shipped name)."""
    p = Path(str(layout))
    return [p] if p.is_file() else []


def progress(iterable, total=None, **kw):
    """``tqdm`` progress on stderr when stderr is a terminal; the plain iterable otherwise."""
    import sys

    if not sys.stderr.isatty():
        return iterable
    try:
        from tqdm import tqdm
    except ImportError:  # pragma: no cover
        return iterable
    return tqdm(iterable, total=total, file=sys.stderr, leave=False, **kw)
