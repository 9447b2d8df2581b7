"""The machine: its layout file (axes, frames, chains, effects), the expressions a layout may
hold, and the generated error model loaded from it (:class:`Model`, :func:`load`).

The derivation is reached through one door, :func:`volerr.machine.derivation.generate_source`.
"""

from .layout import Layout, layout_names, read_layout
from .model import Model, load

__all__ = ["Layout", "Model", "layout_names", "load", "read_layout"]
