"""Import names of volerr's former flat layout (``volerr.tables``, ``volerr.commands.map`` ...).

The runtime was reorganised into capability packages; scripts that import a module by its old
name still get the module that now holds its code (the same module object, not a copy).
Packages that took over an old module's name (``volerr.tables``, ``volerr.identify``,
``volerr.probe``, ``volerr.fiveaxis``, ``volerr.loop``) forward the old names themselves.
"""

from __future__ import annotations

import importlib
import importlib.abc
import importlib.util
import sys

#: former module name below ``volerr`` -> module that holds its code now
MOVED = {
    "layout": "machine.layout", "basis": "machine.expressions", "model": "machine.model",
    "errorfit": "tables.errorfit", "controller_tables": "tables.controller",
    "examples": "cmm.examples", "volmap": "cmm.volmap", "diagonals": "cmm.diagonals",
    "squareness": "cmm.squareness", "tracker_io": "identify.tracker_io",
    "plots_identify": "identify.plots", "probe_plans": "probe.plans", "plots_probe": "probe.plots",
    "gcode": "fiveaxis.gcode", "compensate": "fiveaxis.compensate",
    "fiveaxis_example": "fiveaxis.example", "plots_fiveaxis": "fiveaxis.plots",
    "candidates": "loop.candidates", "fit": "estimate.design", "simulate": "loop.simulate",
    "loop.fit": "estimate.design", "loop.blocks": "estimate.blocks",
    "ballbar.simulate": "instruments.ballbar",
    "loop_report": "loop.report", "audit_numeric": "audit.numeric", "commands": "cli",
}


def _moved(old: str):
    """(moved name, rest) for the longest moved name that ``old`` starts with, else None."""
    parts = old.split(".")
    for k in range(len(parts), 0, -1):
        head = ".".join(parts[:k])
        if head in MOVED:
            return head, ".".join(parts[k:])
    return None


class _Alias(importlib.abc.MetaPathFinder, importlib.abc.Loader):
    def find_spec(self, fullname, path=None, target=None):
        if not fullname.startswith("volerr."):
            return None
        return (importlib.util.spec_from_loader(fullname, self)
                if _moved(fullname[len("volerr."):]) else None)

    def create_module(self, spec):
        head, tail = _moved(spec.name[len("volerr."):])
        return importlib.import_module("volerr." + MOVED[head] + ("." + tail if tail else ""))

    def exec_module(self, module):
        pass


def install() -> None:
    """Register the alias finder once (called by ``volerr/__init__``)."""
    if not any(isinstance(f, _Alias) for f in sys.meta_path):
        sys.meta_path.insert(0, _Alias())
