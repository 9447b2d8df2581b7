"""``volerr examples --out DIR``: example input files for every command.

Parses arguments and calls :func:`volerr.example_files.write_examples`; the folder goes through
the common output checks (created when its parent exists; an existing file is never replaced
without --force)."""

from __future__ import annotations


def register(sub) -> None:
    from ._common import add_force

    p = sub.add_parser("examples", help="write example input files for every command",
                       description="Write example input files into DIR: the files shipped "
                                   "in the package (laser-tracker runs, a sphere probing "
                                   "cycle, a ballbar circle) and the built-in campaigns of "
                                   "'volerr demo' (error tables, a five-axis program, "
                                   "instrument files, a positioning run, an uncertainty "
                                   "task), with DIR/README.txt naming a command for each.")
    p.add_argument("--out", required=True, metavar="DIR",
                   help="folder to write (created when missing, its parent must exist)")
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
