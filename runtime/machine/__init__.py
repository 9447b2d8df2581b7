"""The machine: its layout file (axes, frames, chains, effects), the expressions a layout may
hold, and the generated error model loaded from it (:class:`Model`, :func:`load`).

The derivation is reached through one door, :func:`volerr.machine.derivation.generate_source`.
"""

from .layout import Layout, layout_names, read_layout

__all__ = ["Layout", "Model", "layout_names", "load", "read_layout"]


def __getattr__(name):
    # ``Model`` and ``load`` when first named: the layout (and every ``--help``) needs no numpy
    if name in ("Model", "load"):
        from . import model

        return getattr(model, name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
