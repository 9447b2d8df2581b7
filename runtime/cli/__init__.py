"""The ``volerr`` command line.

Each command lives in its own module under ``volerr.cli`` with ``register(subparsers)``
that adds its parser and sets ``func``.  Bad input raises :class:`volerr.errors.InputError`,
which becomes one line on stderr and exit code 2.
"""

from __future__ import annotations

import argparse
import importlib
import sys

from volerr.errors import InputError

__all__ = ["InputError"]

#: command modules, in the order shown by ``volerr --help``
COMMANDS = ("layouts", "derive", "audit", "map", "diagonals", "identify", "squareness",
            "probe_cal", "compensate", "tcpmap", "controller", "loop", "simulate", "iso230_2",
            "uncertainty", "iso10360", "demo")


class _Parser(argparse.ArgumentParser):
    """Usage errors as one line on stderr (exit 2), like every other bad input."""

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
