"""``volerr examples --out DIR``: example input files for every command
(:func:`volerr.example_files.write_examples`); see ``volerr examples --help``."""

from __future__ import annotations

from ._common import add_force, command_parser


def register(sub) -> None:
    p, H = command_parser(sub, "examples")
    p.add_argument("--out", required=True, metavar="DIR", help=H["--out"])
    add_force(p)
    p.set_defaults(func=run)


def run(args) -> int:
    from ..example_files import known_files, write_examples
    from ..fileio import Outputs

    # the names known in advance are checked before writing; those inside the example
    # folders (error tables) when everything is put in place
    outs = Outputs(force=args.force).folder("--out", args.out, files=known_files()).check()
    with outs:
        names = write_examples(outs.path("--out"))
    print(f"wrote {len(names)} example files to {args.out} (README.txt: a command for each)")
    return 0
