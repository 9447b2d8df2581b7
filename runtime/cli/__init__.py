"""The ``volerr`` command line.

Each command lives in its own module under ``volerr.cli`` with ``register(subparsers)``
that adds its parser and sets ``func``.  Bad input raises :class:`volerr.errors.InputError`,
which becomes one line on stderr and exit code 2.
"""

from __future__ import annotations

import argparse
import importlib
import sys

from ..errors import InputError

__all__ = ["InputError"]

#: command modules, in the order shown by ``volerr --help``
COMMANDS = ("layouts", "derive", "audit", "map", "diagonals", "identify", "squareness",
            "probe_cal", "compensate", "tcpmap", "controller", "calibrate", "ballbar", "loop",
            "simulate", "iso230_2",
            "uncertainty", "iso10360", "demo", "formats")

#: closes every ``--help``
EPILOG = ("File formats: 'volerr formats' lists them, 'volerr formats NAME' prints one\n"
          "(the same text as docs/formats.md).  Bad input: exit 2 and one line on stderr.")


class _HelpFormatter(argparse.RawDescriptionHelpFormatter):
    """Plain text (no Sphinx markup) and the default of every option that has one."""

    @staticmethod
    def _plain(text: str) -> str:
        import re

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
        if isinstance(default, (list, tuple)):
            shown = " ".join(f"{v:g}" if isinstance(v, float) else str(v) for v in default)
        elif isinstance(default, float):
            shown = f"{default:g}"
        else:
            shown = str(default)
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
        self.exit(2, f"{self.prog}: error: {message} (see '{self.prog} --help')\n")


def build_parser() -> argparse.ArgumentParser:
    parser = _Parser(
        prog="volerr",
        description="Derived, audited volumetric error models of CMMs and five-axis machines.")
    sub = parser.add_subparsers(dest="command", metavar="COMMAND")
    sub.required = True
    for name in COMMANDS:
        try:
            module = importlib.import_module(f"volerr.cli.{name}")
        except ModuleNotFoundError as exc:
            if exc.name == f"volerr.cli.{name}":
                continue  # command not built yet
            raise
        module.register(sub)
    return parser


def main(argv=None) -> int:
    from ._memory import keep_freed_blocks

    keep_freed_blocks()
    parser = build_parser()
    try:
        args = parser.parse_args(argv)
    except SystemExit as exc:  # argparse prints its own one-line usage error
        return int(exc.code or 0)
    try:
        result = args.func(args)
    except InputError as exc:
        print(f"volerr {args.command}: error: {exc}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:  # pragma: no cover
        return 130
    except BrokenPipeError:  # output piped into e.g. `head`
        sys.stderr.close()
        return 0
    return int(result or 0)


if __name__ == "__main__":  # pragma: no cover
    sys.exit(main())
