"""Nominal symbols of a chain: a change of their values as error factors inserted in the chain
(sympy); the sensitivity of the tool point to each of them is
:func:`volerr.derive.volumetric.symbol_sensitivity`.

Besides its error parameters, a chain holds *nominal symbols*: the probe / tool offset
components ``Xp Yp Zp``, the axis positions, the layout's parameters (the DMU 50's ``d``) and
the translation components and angles of its fixed frames (names: :attr:`Layout.symbols`,
``probe.Zp``, ``axis.C``, ``param.d``, ``frame.F.x``, ``frame.F.angle``).  A small change
``ds`` of a symbol changes every nominal factor ``F`` that holds it to first order as
``F(s + ds) = F(s) (I + D ds)`` with the twist ``D = F^-1 dF/ds``; each factor carries that
twist per symbol (``Factor.variation``, built in :mod:`volerr.derive.kinematics`).  Inserting
the error factor ``I + D ds`` right after every such factor gives the chain with the changed
symbol: its first-order error is ``d(nominal tool point)/ds * ds``, the column the closing loop
uses for an effect on that symbol, and the same insertion is how an ``[effects.*]`` term
targeting the symbol enters an augmented layout's chain (:mod:`volerr.derive.effects`), so the
two agree by construction.

Units: a change of a length (offset, parameter, linear axis position, frame translation) in
mm, of an angle (rotary axis position, frame angle) in rad.  Sign: the error is the actual
minus the nominal tool point, the actual chain having the changed value.
"""

from __future__ import annotations

import sympy as sp

from .htm import Factor

#: twist coordinates of the probe / tool offset components (the tool-end translation)
PROBE_TWIST = {"probe.Xp": "dx", "probe.Yp": "dy", "probe.Zp": "dz"}


def insert_variations(factors: list, change: dict) -> list:
    """``factors`` with an error factor ``I + sum_s D_s change[s]`` inserted right after every
    nominal factor whose symbols ``s`` are changed (``change``: symbol name -> sympy
    expression, mm or rad).  Probe symbols are not handled here (a tool-end translation)."""
    out = []
    for f in factors:
        out.append(f)
        if f.is_error or not f.variation:
            continue
        args: dict = {}
        for s, tw in f.variation.items():
            if s in change:
                for k, v in tw.items():
                    args[k] = args.get(k, 0) + v * change[s]
        args = {k: sp.expand(v) for k, v in args.items()}
        args = {k: v for k, v in args.items() if v != 0}
        if args:
            out.append(Factor(twist_args=args, owner=f.owner, role="effect"))
    return out
