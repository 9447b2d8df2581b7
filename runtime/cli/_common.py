"""Argument helpers shared by several commands (argparse only, no algorithms)."""

from __future__ import annotations

from functools import lru_cache

from .. import __version__
from ..choices import INTERPOLATION as METHODS
from ..errors import InputError
from ..progress import progress_bar  # noqa: F401  (one rule: volerr.progress)
from ..units import parse_at, parse_vector  # noqa: F401  (the parsing: units)


def add_error_arguments(parser, required: bool = True) -> None:
    """``--errors DIR --method --degree --extrapolate --accept-implausible``."""
    a = parser.add_argument
    a("--errors", metavar="DIR", required=required, help=_C("--errors"))
    a("--method", choices=METHODS, default="linear", help=_C("--method"))
    a("--degree", type=int, default=None, help=_C("--degree"))
    a("--extrapolate", action="store_true", help=_C("--extrapolate"))
    add_accept_implausible(parser)


def add_accept_implausible(parser) -> None:
    """``--accept-implausible`` (:mod:`volerr.tables.plausible`), once (not twice)."""
    if "--accept-implausible" not in parser._option_string_actions:
        parser.add_argument("--accept-implausible", action="store_true", help=_C(
            "--accept-implausible"))


def add_common(p) -> None:
    """Arguments shared with ``volerr diagonals``."""
    p.add_argument("layout", help="layout name (volerr layouts) or layout file")
    add_error_arguments(p)
    add_vector(p, "--probe", default=(0.0, 0.0, 0.0), help=_C("--probe"))
    p.add_argument("--at", action="append", default=[], metavar="AXIS=DEG", help=_C("--at"))
    p.add_argument("--volume", choices=("travel", "measured"), default="travel",
                   help=_C("--volume"))


def add_vector(parser, flag: str, help: str, default=None, required: bool = False,
               append: bool = False, metavar: str = "X Y Z") -> None:
    """A 3-vector option, ``X Y Z`` or ``X,Y,Z`` (a bad value: exit 2 and one line)."""
    import argparse

    class _Vector(argparse.Action):
        vector = True

        def __call__(self, p, namespace, values, option_string=None):
            try:
                v = parse_vector(values, option_string)
            except InputError as exc:
                p.error(str(exc))
            if append:
                v = [*(getattr(namespace, self.dest) or []), v]
            setattr(namespace, self.dest, v)

    parser.add_argument(flag, nargs="+", action=_Vector, default=default, required=required,
                        metavar=metavar, help=help)


# ---------------------------------------------------------------------------------------------
# the same option for the same thing in every command
def add_json(parser, what: str = "the results") -> None:
    """``--json F``: optional everywhere."""
    parser.add_argument("--json", metavar="F", help=f"write {what} (JSON)")


def add_plot(parser, what: str = "the plot", *aliases: str, required: bool = False) -> None:
    """``--plot F.png`` (old spellings in ``aliases`` keep working)."""
    parser.add_argument("--plot", *aliases, dest="plot", metavar="F.png", required=required,
                        help=f"write {what} (PNG)")


def add_html(parser, what: str = "a one-page report with the figures") -> None:
    """``--html F.html``: optional everywhere."""
    parser.add_argument("--html", metavar="F.html", help=f"write {what} (HTML, figures "
                                                         f"embedded, no network needed)")


def add_errors_out(parser, what: str, *aliases: str, required: bool = False) -> None:
    """``--errors-out DIR``, an error directory written (``aliases``: former spellings)."""
    parser.add_argument("--errors-out", *aliases, dest="errors_out", metavar="DIR",
                        required=required, help=_C("--errors-out").format(what))


def add_force(parser) -> None:
    """``--force``: a folder output may replace files that were there before the run."""
    parser.add_argument("--force", action="store_true", help=_C("--force"))


def add_accept_residual(parser) -> None:
    """``--accept-residual``: write a fit of too large a residual (:mod:`volerr.fit_quality`)."""
    parser.add_argument("--accept-residual", action="store_true", help=_C("--accept-residual"))


def add_max_change(parser, reference: bool) -> None:
    """(``reference``: ``--reference CAL.json``) ``--max-change``, ``--accept-change``
    (the KinematicsOpt maxModification rule, :mod:`volerr.fit_quality`)."""
    if reference:
        parser.add_argument("--reference", metavar="CAL.json", help=_C("--reference"))
    parser.add_argument("--max-change", metavar="LIMITS", help=_C("--max-change"))
    parser.add_argument("--accept-change", action="store_true", help=_C("--accept-change"))


#: the identification's fields, in the order of their options
_IDENT_FIELDS = ("machine", "operator", "date", "customer", "instrument")


def add_identification_arguments(parser, instrument: str = "the measuring instrument") -> None:
    """``--identification F``, its fields' options (:mod:`volerr.certificate`), ``--pdf F``;
    an option the command has with its own meaning keeps it (the field: from the file)."""
    g = parser.add_argument_group(_C("identification"))
    have = parser._option_string_actions
    g.add_argument("--identification", metavar="F.toml", help=_C("--identification"))
    own = []
    for dest in _IDENT_FIELDS:
        if f"--{dest}" not in have:
            g.add_argument(f"--{dest}", dest=dest, help=_C(f"--{dest}").format(instrument),
                           metavar="YYYY-MM-DD" if dest == "date" else "TEXT")
            own.append(dest)
    if "--pdf" not in have:
        g.add_argument("--pdf", metavar="F.pdf", help=_C("--pdf"))
    parser.set_defaults(_ident_own=tuple(own), _ident_prog=parser.prog,
                        _ident_version=__version__)


def help_text(command: str) -> str:
    """The text file ``volerr/data/help/COMMAND.txt`` (e.g. the epilog of ``--help``)."""
    from importlib.resources import files

    return (files("volerr") / "data" / "help" / f"{command}.txt").read_text(encoding="utf-8")


# ---------------------------------------------------------------------------------------------
def command_parser(sub, name: str, text: str | None = None, **kw) -> tuple:
    """``(parser, helps)``: ``sub.add_parser(name)``, its texts from ``volerr/data/help/TEXT``
    (default ``name``): ``.description.txt`` (line 1: its help in the command list; the rest:
    its description), ``.txt`` its epilog, ``.options.txt`` the ``helps`` (:func:`option_help`)."""
    from importlib.resources import files

    folder, text = files("volerr") / "data" / "help", text or name
    short, _, about = help_text(f"{text}.description").rstrip("\n").partition("\n")
    kw.setdefault("description", about or None)
    if (folder / f"{text}.txt").is_file():
        kw.setdefault("epilog", help_text(text))
    known = (folder / f"{text}.options.txt").is_file()
    return sub.add_parser(name, help=short, **kw), option_help(text) if known else {}


@lru_cache(maxsize=None)
def option_help(name: str) -> dict:
    """``{option: help}`` of ``volerr/data/help/NAME.options.txt``: blocks separated by a blank
    line, the option (or argument) on the first line, its help on the next."""
    blocks = help_text(f"{name}.options").strip("\n").split("\n\n")
    return {b.split("\n", 1)[0]: " ".join(b.split("\n")[1:]) for b in blocks}


def _C(option: str) -> str:
    """The help of a shared option (its text in ``volerr/data/help/common.options.txt``)."""
    return option_help("common")[option]


def add_report_options(parser, json: str, html: str, instrument: str | None = None) -> None:
    """``--json`` (of ``json``), ``--html`` (``html``), :func:`add_identification_arguments`."""
    add_json(parser, json)
    add_html(parser, html)
    add_identification_arguments(parser, *([instrument] if instrument else []))


def add_fit_switches(parser, implausible: bool = True) -> None:
    """``--force``, ``--accept-residual``, (``implausible``) ``--accept-implausible``."""
    add_force(parser)
    add_accept_residual(parser)
    if implausible:
        add_accept_implausible(parser)


def options_of(args, names: str, **more) -> dict:
    """The options ``names`` (dests, space separated) as the API's keywords, and ``more``."""
    return {**{name: getattr(args, name) for name in names.split()}, **more}
