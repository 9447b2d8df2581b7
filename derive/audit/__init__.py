"""The audit of printed equations: every equation, number and code listing of the source
documents (Pahk 1995, the NTNU thesis and its papers) against the derivation of
:mod:`volerr.derive`, each difference named as an erratum with its evidence and a category.

This room uses the derivation engine (``volerr.derive.kinematics``, ``volumetric``,
``inverse``, ``three_point``, ``probe``); the engine never imports it.  The verdict, the
category rule and the term-by-term comparison are in :mod:`volerr.derive.audit.framework`;
every other module is a *provider* that audits one source document.  A provider has

* ``DATA_FILE``: the name of its data file in ``data/`` beside this module (the printed
  equations, kept exactly as printed), or ``None``;
* ``audit(printed: dict, layouts: list[str] | None) -> list[Verdict]``: ``printed`` is the
  parsed data file (the command reads it; providers do no file I/O), ``layouts`` restricts the
  audit to those layouts (``None``: all);
* optionally ``LAYOUTS``: the layout names it covers (for validating command-line names).

A new printed source is one provider module here, its data file in ``data/`` and its name in
:data:`PROVIDERS`.  Importing this package does not import sympy (the runtime reads the data
files' location through it); :func:`providers` does.
"""

from __future__ import annotations

import importlib

#: provider modules, in the order ``volerr audit`` runs them
PROVIDERS = ("volerr.derive.audit.pahk", "volerr.derive.audit.tracker",
             "volerr.derive.audit.dmu50", "volerr.derive.audit.rotary",
             "volerr.derive.audit.htm", "volerr.derive.audit.ch2",
             "volerr.derive.audit.metrology", "volerr.derive.audit.listings",
             "volerr.derive.audit.squareness", "volerr.derive.audit.scripts",
             "volerr.derive.audit.probe", "volerr.derive.audit.numbers",
             "volerr.derive.audit.results")

#: the package's folder of printed material (``<DATA_FILE>`` of each provider)
DATA_DIR = "data"


def providers() -> list:
    """The provider modules, in :data:`PROVIDERS` order (imports sympy)."""
    return [importlib.import_module(name) for name in PROVIDERS]
