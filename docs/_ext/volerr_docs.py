"""Sphinx directives of the volerr manual, generated from the code (never retyped):

* ``.. volerr-commands::`` -- one section per command and sub-command with its ``--help``,
  read from the parser :func:`volerr.cli.build_parser` builds (a command added to
  ``volerr.cli.COMMANDS`` appears here without any change to the manual);
* ``.. volerr-layouts::`` -- a table of the shipped layouts: kind, axes, tool chain and
  workpiece chain from the base, read from the layout files.
"""

from __future__ import annotations

import argparse
import os

from docutils import nodes
from docutils.parsers.rst import Directive


def _subcommands(parser, prefix):
    """(prog words, parser) of every leaf command under ``parser``, in the --help order."""
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            for name, child in action.choices.items():
                words = prefix + [name]
                subs = [a for a in child._actions if isinstance(a, argparse._SubParsersAction)]
                if subs:
                    yield words, child
                    yield from _subcommands(child, words)
                else:
                    yield words, child


class CommandsDirective(Directive):
    has_content = False

    def run(self):
        from volerr.cli import build_parser

        os.environ.setdefault("COLUMNS", "92")
        parser = build_parser()
        out = []
        seen = set()
        for words, child in _subcommands(parser, []):
            title = "volerr " + " ".join(words)
            if title in seen:      # aliases of a command
                continue
            seen.add(title)
            sec = nodes.section(ids=[nodes.make_id(title)], names=[nodes.fully_normalize_name(title)])
            sec += nodes.title(text=title)
            text = child.format_help()
            sec += nodes.literal_block(text, text)
            self.state.document.note_implicit_target(sec)
            out.append(sec)
        return out


class LayoutsDirective(Directive):
    has_content = False

    def run(self):
        from volerr.machine.layout import layout_names, read_layout

        rows = [("layout", "kind", "axes", "tool chain (base -> tool)",
                 "workpiece chain (base -> workpiece)")]
        for name in layout_names():
            lay = read_layout(name)
            rows.append((name, str(getattr(lay, "kind", "")), " ".join(lay.axis_names),
                         " -> ".join(lay.tool_chain) or "-",
                         " -> ".join(lay.workpiece_chain) or "-"))
        table = nodes.table()
        group = nodes.tgroup(cols=len(rows[0]))
        table += group
        for _ in rows[0]:
            group += nodes.colspec(colwidth=1)
        head, body = nodes.thead(), nodes.tbody()
        for i, row in enumerate(rows):
            r = nodes.row()
            for cell in row:
                entry = nodes.entry()
                entry += nodes.paragraph(text=cell)
                r += entry
            (head if i == 0 else body).append(r)
        group += head
        group += body
        return [table]


def setup(app):
    app.add_directive("volerr-commands", CommandsDirective)
    app.add_directive("volerr-layouts", LayoutsDirective)
    return {"parallel_read_safe": True, "version": "1"}
