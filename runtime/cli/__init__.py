"""The ``volerr`` command line: one module per command (``register(subparsers)`` adds its
parser and sets ``func``; ``func(args)`` returns the exit code, or the API's result, whose
``summary()`` is printed); :class:`volerr.errors.InputError` becomes one line on stderr, exit 2.
"""

from __future__ import annotations

import argparse
import difflib
import importlib
import math
import re
import sys

from ..errors import InputError

__all__ = ["InputError"]

#: command modules, in the order shown by ``volerr --help``
COMMANDS = ("layouts", "derive", "audit", "map", "diagonals", "identify", "squareness",
            "probe_cal", "compensate", "tcpmap", "controller", "calibrate", "ballbar", "loop",
            "simulate", "plan", "check", "history", "iso230_2", "iso230_3", "drift",
            "uncertainty", "iso10360", "demo", "examples", "formats")

#: closes every ``--help``
EPILOG = ("File formats: 'volerr formats' lists them, 'volerr formats NAME' prints one\n"
          "(the same text as docs/formats.md).  Bad input: exit 2 and one line on stderr.")


class _HelpFormatter(argparse.RawDescriptionHelpFormatter):
    """Plain text (no Sphinx markup) and the default of every option that has one."""

    @staticmethod
    def _plain(text: str) -> str:
        text = re.sub(r":(?:mod|func|class|meth|attr|data):`~?([^`]+)`", r"\1", text)
        return text.replace("``", "")

    def _format_text(self, text):
        return super()._format_text(self._plain(text)) if text else ""

    def _format_args(self, action, default_metavar):
        if getattr(action, "vector", False):  # a 3-vector: X Y Z or X,Y,Z
            return action.metavar
        return super()._format_args(action, default_metavar)

    def _get_help_string(self, action):
        text = self._plain(action.help or "")
        default = action.default
        if (default is None or default is False or default is argparse.SUPPRESS
                or not action.option_strings or default == [] or "%(default)" in text):
            return text
        shown = " ".join(f"{v:g}" if isinstance(v, float) else str(v) for v in (
            default if isinstance(default, (list, tuple)) else [default]))
        if "default" in text.lower() and shown in text:
            return text  # the help states it already
        return f"{text} (default: {shown.replace('%', '%%')})"


class _Parser(argparse.ArgumentParser):
    """Usage errors as one line on stderr (exit 2), like every other bad input; every help
    ends with the pointer to the file formats."""

    def __init__(self, *args, **kwargs):
        kwargs.setdefault("formatter_class", _HelpFormatter)
        epilog = kwargs.get("epilog")
        kwargs["epilog"] = EPILOG if not epilog else (
            epilog if "volerr formats" in epilog else f"{epilog}\n\n{EPILOG}")
        if kwargs.get("description"):
            kwargs["description"] = _HelpFormatter._plain(kwargs["description"])
        super().__init__(*args, **kwargs)

    def error(self, message):
        message = _did_you_mean(message)
        if message.startswith("the following arguments are required"):
            # a mistyped option is the likelier cause of a missing one: name it first
            known = set(self._option_string_actions)
            for token in _ARGV:
                name = token.split("=", 1)[0]
                close = _closest(self, name) if name.startswith("--") and not any(
                    k.startswith(name) for k in known) else ""
                if close:
                    message = f"unrecognized option {token}{close}"
                    break
        self.exit(2, f"{self.prog}: error: {message} (see '{self.prog} --help')\n")

    def parse_args(self, args=None, namespace=None):
        """As argparse, but an unknown option is named by the (sub)command it was given to,
        with the closest option of that command ("did you mean --json?")."""
        _ARGV[:] = [str(a) for a in (sys.argv[1:] if args is None else args)]
        ns, extras = self.parse_known_args(args, namespace)
        leaf = getattr(ns, "_parser", None) or self
        _refuse_empty(leaf, _ARGV)
        _refuse_nonfinite(leaf, ns)
        bad = next((e for e in extras if e.startswith("-")), None)
        if bad:
            leaf.error(f"unrecognized option {bad}{_closest(leaf, bad.split('=', 1)[0])}")
        if extras:
            leaf.error(f"unrecognized arguments: {' '.join(extras)}")
        return ns


_ARGV: list = []   # the arguments being parsed (for the messages of a subcommand's parser)


def _refuse_nonfinite(parser, ns) -> None:
    """Every number option is finite (``nan``, ``inf`` parse as floats but are never a
    tolerance, radius or limit), and a ``--seed`` is an integer 0 .. 2^32 - 1 (numpy's
    seeds)."""
    for action in parser._actions:
        if action.type not in (float, int) or not action.option_strings:
            continue
        value = getattr(ns, action.dest, None)
        for v in value if isinstance(value, (list, tuple)) else [value]:
            if isinstance(v, float) and not math.isfinite(v):
                parser.error(f"{action.option_strings[-1]}: {v} is not a finite number")
    seed = getattr(ns, "seed", None)
    if isinstance(seed, int) and not 0 <= seed < 2 ** 32:
        parser.error(f"--seed: {seed} is not an integer from 0 to {2 ** 32 - 1}")


def _refuse_empty(parser, argv) -> None:
    """An empty or blank argument (``--tolerance ''``, ``--json=``, a file name ``''``) is a
    mistake, never "option not given": one line naming it."""
    for i, token in enumerate(argv):
        name, eq, value = token.partition("=")
        if token.startswith("--") and eq and not value.strip():
            parser.error(f"{name}: empty value")
        if not token.strip():
            before = argv[i - 1] if i else ""
            parser.error(f"{before}: empty value" if before.startswith("-") else
                         "empty argument ('')")


def _closest(parser, name: str) -> str:
    """`` (did you mean --json?)``: the visible option of ``parser`` closest to ``name``."""
    options = [s for a in parser._actions if a.help is not argparse.SUPPRESS
               for s in a.option_strings]
    close = difflib.get_close_matches(name, options, n=1, cutoff=0.6)
    return f" (did you mean {close[0]}?)" if close else ""


def _did_you_mean(message: str) -> str:
    """argparse's "invalid choice: 'mapp' (choose from ...)" with the closest choice."""
    m = re.search(r"invalid choice: '?([^' ]+)'? \(choose from (.*)\)", message)
    if not m or "did you mean" in message:
        return message
    choices = re.findall(r"'([^']+)'", m.group(2)) or [c.strip() for c in
                                                        m.group(2).split(",")]
    close = difflib.get_close_matches(m.group(1), choices, n=1, cutoff=0.5)
    return message + (f" (did you mean '{close[0]}'?)" if close else "")


def _mark_leaves(parser) -> None:
    """Every (sub)parser records itself in the namespace, for the messages above."""
    parser.set_defaults(_parser=parser)
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            for child in action.choices.values():
                _mark_leaves(child)


def build_parser(command: str | None = None) -> argparse.ArgumentParser:
    """The ``volerr`` parser with every command's sub-parser; ``command`` (a command's name as
    typed, e.g. ``probe-cal``): only that command's, the other command modules not imported
    (:func:`main` does this when its first argument names a command: the parse, the help and
    every message of that command are the same, the start-up cheaper)."""
    from .. import __version__

    parser = _Parser(prog="volerr", description="Derived, audited volumetric error models of "
                                                "CMMs and five-axis machines.")
    parser.add_argument("--version", action="version", version=f"volerr {__version__}",
                        help="print the version of volerr and exit")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")
    sub.required = True
    module_name = (command or "").replace("-", "_")
    only = command is not None and "_" not in command and module_name in COMMANDS
    for name in (module_name,) if only else COMMANDS:
        importlib.import_module(f"volerr.cli.{name}").register(sub)
    _mark_leaves(parser)
    return parser


def main(argv=None) -> int:
    from ._memory import keep_freed_blocks

    keep_freed_blocks()
    first = (sys.argv[1:] if argv is None else list(argv))[:1]
    parser = build_parser(str(first[0]) if first else None)
    try:
        args = parser.parse_args(argv)
    except SystemExit as exc:  # argparse prints its own one-line usage error
        return int(exc.code or 0)
    try:
        result = args.func(args)
        if hasattr(result, "summary"):   # a command's result (the API's): print its summary
            print(result.summary())
            result = 0
    except InputError as exc:
        print(f"volerr {args.command}: error: {exc}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:  # pragma: no cover
        return 130
    except BrokenPipeError:  # output piped into e.g. `head`
        sys.stderr.close()
        return 0
    except OSError as exc:  # a file the checks could not foresee (full disk, I/O error)
        where = f"{exc.filename}: " if getattr(exc, "filename", None) else ""
        print(f"volerr {args.command}: error: {where}{exc.strerror or exc}", file=sys.stderr)
        return 2
    return int(result or 0)


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
