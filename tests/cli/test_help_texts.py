"""The long help texts of the commands live in ``volerr/data/help/`` (one mechanism:
``_common.command_parser``): every option block there is an option of its command and is the
help that command shows; no text file is read another way."""

from __future__ import annotations

import argparse
from importlib.resources import files

from volerr.cli import build_parser

FOLDER = files("volerr") / "data" / "help"


def _parsers(parser=None, path=()):
    """``{"controller-export": parser, ...}``: every (sub)command by its text name."""
    parser = parser or build_parser()
    out = {"-".join(path): parser} if path else {}
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            for name, child in action.choices.items():
                out.update(_parsers(child, path + (name,)))
    return out


def _blocks(text: str) -> dict:
    """``{key: help}`` read from the file here, not by the code under test: blocks separated
    by one blank line, the key on the first line, the help's words on the next ones."""
    blocks = text.strip("\n").split("\n\n")
    return {b.splitlines()[0]: " ".join(b.splitlines()[1:]).split() for b in blocks}


def _help_of(parser, key):
    """The help of option ``key`` of ``parser``, else of its sub-commands' (a text file of
    ``history`` serves ``history add`` and ``history show``)."""
    for action in parser._actions:
        if key in action.option_strings or (not action.option_strings and action.dest == key):
            return action.help
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            for child in action.choices.values():
                if (shown := _help_of(child, key)) is not None:
                    return shown
    return None


def test_every_option_block_is_shown_by_its_command():
    parsers = _parsers()
    checked = 0
    for path in sorted(FOLDER.iterdir(), key=lambda p: p.name):
        name = path.name.removesuffix(".options.txt")
        if not path.name.endswith(".options.txt") or name not in parsers:
            continue     # e.g. texts of shared option helpers
        for key, words in _blocks(path.read_text(encoding="utf-8")).items():
            shown = _help_of(parsers[name], key)
            if shown is None and " " in key:
                continue     # not an option: e.g. a group's title ("instrument files")
            assert shown is not None, f"{path.name}: {key} is no option of volerr {name}"
            if "{" not in " ".join(words):     # a template the command fills in
                # the whole help, or what a shared helper puts in its frame ("write ... (JSON)")
                assert " ".join(words) in " ".join(shown.split()), \
                    f"{path.name}: {key} is not the help shown"
            checked += 1
    assert checked >= 40   # compensate, controller export, map ... hold that many alone


def test_descriptions_read_one_way_only():
    names = [p.name for p in FOLDER.iterdir()]
    assert not [n for n in names if n.endswith("-description.txt")]
    parsers = _parsers()
    for name in ("compensate", "examples", "controller", "map", "derive", "layouts"):
        first = (FOLDER / f"{name}.description.txt").read_text(encoding="utf-8").split("\n")[0]
        top = build_parser()
        sub = next(a for a in top._actions if isinstance(a, argparse._SubParsersAction))
        listed = {c.dest: c.help for c in sub._choices_actions}
        assert listed[name] == first
        assert parsers[name].description, name
