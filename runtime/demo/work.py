"""What the demo's sections share: the models loaded once and the outputs kept until the end.

A section computes through the Python API and hands its pages, figures and JSON documents to
:class:`Work` (:meth:`Work.later`, :meth:`Work.figure`, :meth:`Work.text`); they are written
by :meth:`Work.flush` after the last section, into the staged folder that the demo puts in
place all or nothing.  Only the data files the next step reads (example error tables,
simulated measurements, identified tables, plan files) are written as the sections go.
"""

from __future__ import annotations

from pathlib import Path


class Work:
    """The demo's shared state.  ``out``: the (staged) output folder, relative paths inside it
    as the pages name them."""

    def __init__(self, out: Path):
        self.out = Path(out)
        self._models: dict = {}
        self._later: list = []

    def model(self, layout: str):
        """The :class:`volerr.Model` of ``layout``, loaded once per run."""
        if layout not in self._models:
            from ..machine.model import load

            self._models[layout] = load(layout)
        return self._models[layout]

    def later(self, name: str, write) -> None:
        """Write ``name`` (relative to :attr:`out`) at the end: ``write(path)``."""
        self._later.append((name, write))

    @staticmethod
    def once(make):
        """``make()`` computed at the first call of the function returned, then kept: a
        figure's PNG drawn once at the end for its file and for the page that embeds it."""
        kept = []

        def get():
            if not kept:
                kept.append(make())
            return kept[0]
        return get

    def text(self, name: str, text: str) -> None:
        """The text file ``name`` (UTF-8), written at the end."""
        from ..fileio import write_text

        self.later(name, lambda path: write_text(path, text))

    def figure(self, name: str, fig) -> None:
        """The matplotlib figure ``fig`` as the PNG ``name`` (:func:`volerr.plotstyle.save`),
        kept in memory and written at the end."""
        from ..plotstyle import save

        self.later(name, lambda path: save(fig, path))

    def flush(self) -> None:
        """Write every kept output, in the order the sections gave them, with the plot
        style of the figures (:func:`volerr.plotstyle.styled`)."""
        from ..plotstyle import styled

        @styled
        def write_all():
            for name, write in self._later:
                write(self.out / name)

        write_all()
        self._later = []
