"""One figure style for every plot of volerr, and the rules that go with it.

* :data:`STYLE`: the matplotlib style file shipped in the package (``volerr/data/
  volerr.mplstyle``); :func:`styled` applies it to a plotting function (a decorator), so a
  new plot adopts it with one line.
* Size: a figure is at most :data:`PAGE_WIDTH_IN` wide at :data:`DPI` (1000 px); every HTML
  page of volerr shows a figure at its own pixel width (:func:`img_tag` writes the ``width``
  attribute), so text of the style's smallest size (9 pt = 12.5 px) stays above 9 px on the
  page.  :func:`png` saves without cropping ("tight" boxes change the pixel width).
* Units, written one way on every axis and table header: ``quantity / unit`` with ``mm``,
  ``deg``, ``µm``, ``µrad``, ``°C`` (:func:`label`, :func:`unit`).
* Captions state the coverage factor of every band or bar (``k = 2``, ``± 2 s``).
"""

from __future__ import annotations

import functools
import io
from importlib import resources

#: the style file shipped in the package
STYLE = resources.files("volerr") / "data" / "volerr.mplstyle"
#: resolution of every PNG, dots per inch
DPI = 100
#: the widest figure, inches (PAGE_WIDTH_IN * DPI = the pixel width the pages show at most)
PAGE_WIDTH_IN = 10.0
PAGE_WIDTH_PX = int(PAGE_WIDTH_IN * DPI)
#: the smallest text a figure may carry, points (9 pt at 100 dpi = 12.5 px)
MIN_FONT_PT = 9.0

#: unit spellings -> the one notation of volerr's figures and tables
_UNITS = {"um": "µm", "µm": "µm", "urad": "µrad", "µrad": "µrad", "mm": "mm", "deg": "deg",
          "degC": "°C", "°C": "°C", "C": "°C", "K": "K", "s": "s", "min": "min", "h": "h",
          "rad": "rad", "1": "1", "ppm": "ppm"}


def unit(text: str) -> str:
    """``"um"`` -> ``"µm"``, ``"urad"`` -> ``"µrad"``, ``"degC"`` -> ``"°C"`` (others kept); a
    compound unit part by part (``"um/mm"`` -> ``"µm/mm"``)."""
    if "/" in text:
        return "/".join(_UNITS.get(part, part) for part in text.split("/"))
    return _UNITS.get(text, text)


def label(quantity: str, unit_text: str | None = None) -> str:
    """An axis label or table header: ``"X / mm"``, ``"EXX / µm"``; no unit: the quantity."""
    if not unit_text or unit_text == "1":
        return quantity
    return f"{quantity} / {unit(unit_text)}"


def pyplot():
    """``matplotlib.pyplot`` on the Agg backend (no display needed)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def styled(func):
    """Decorator: run a plotting function with the volerr style (figures, texts and the
    saving inside it take their sizes from :data:`STYLE`)."""
    @functools.wraps(func)
    def wrapper(*args, **kwargs):
        plt = pyplot()
        with plt.style.context(str(STYLE)):
            return func(*args, **kwargs)
    return wrapper


def figure(nrows: int = 1, ncols: int = 1, *, width: float = PAGE_WIDTH_IN,
           height: float = 4.5, **kwargs):
    """``plt.subplots`` at most :data:`PAGE_WIDTH_IN` wide, constrained layout (nothing cut
    off, nothing overlapping) unless ``layout`` is given."""
    plt = pyplot()
    kwargs.setdefault("layout", "constrained")
    return plt.subplots(nrows, ncols, figsize=(min(width, PAGE_WIDTH_IN), height), **kwargs)


#: zlib level of every PNG: 1 (fastest) encodes a figure about 4x faster than PIL's default
#: 6, for files about a third larger; the pixels are the same (PNG is lossless)
PNG_COMPRESS_LEVEL = 1


def png(fig) -> bytes:
    """PNG bytes of ``fig`` at :data:`DPI`, its full size (no cropping), then closed.

    The figure is drawn once: matplotlib's ``savefig`` of a figure with a layout engine
    (``constrained``) draws it twice, once with the drawing switched off to run the layout and
    once to paint; here the layout runs first (:func:`_layout_once`) and the figure is then
    painted with the engine set aside, the same pixels at about two thirds of the cost.
    Zlib level :data:`PNG_COMPRESS_LEVEL`."""
    plt = pyplot()
    w = fig.get_figwidth()
    if w > PAGE_WIDTH_IN + 1e-9:  # wider figures would be shrunk on the page
        fig.set_size_inches(PAGE_WIDTH_IN, fig.get_figheight() * PAGE_WIDTH_IN / w)
    buf = io.BytesIO()
    try:
        engine = _layout_once(fig)
        try:
            fig.savefig(buf, format="png", dpi=DPI,
                        pil_kwargs={"compress_level": PNG_COMPRESS_LEVEL})
        finally:
            if engine is not None:
                fig.set_layout_engine(engine)
    finally:
        plt.close(fig)
    return buf.getvalue()


def _layout_once(fig):
    """Run ``fig``'s layout engine now, as ``savefig`` would in its first (unpainted) draw, and
    set the engine aside so that ``savefig`` paints once; return the engine (to be put back),
    or None where the figure is left as it is (no engine, no axes, not an Agg canvas, another
    resolution than :data:`DPI`, or rcParams that would replace a missing engine)."""
    import matplotlib
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    engine = fig.get_layout_engine()
    rc = matplotlib.rcParams
    if (engine is None or not fig.axes or not isinstance(fig.canvas, FigureCanvasAgg)
            or fig.dpi != DPI or rc["figure.autolayout"] or rc["figure.constrained_layout.use"]
            or rc["savefig.bbox"] == "tight"):
        return None
    for ax in fig.axes:   # what Figure.draw does before its layout (_get_draw_artists)
        locator = ax.get_axes_locator()
        ax.apply_aspect(locator(ax, fig.canvas.get_renderer()) if locator else None)
    try:
        engine.execute(fig)
    except ValueError:    # as Figure.draw: the layout is then left as it was
        pass
    fig.set_layout_engine(None)   # with the rcParams above: no engine at all
    return engine


def save(fig, path, inputs=()) -> bytes:
    """Write :func:`png` of ``fig`` to ``path`` (atomically; never over an input)."""
    from .fileio import write_bytes

    data = png(fig)
    write_bytes(path, data, inputs)
    return data


def png_size(data: bytes) -> tuple[int, int]:
    """(width, height) in pixels of PNG bytes (from the IHDR chunk)."""
    import struct

    if data[:8] != b"\x89PNG\r\n\x1a\n":
        raise ValueError("not a PNG")
    return struct.unpack(">II", data[16:24])


def img_tag(src: str, alt: str, png_bytes: bytes | None = None, width: int | None = None,
            link: str | None = None) -> str:
    """``<img>`` with the pixel width the page shows the figure at: its own width, at most
    :data:`PAGE_WIDTH_PX` (CSS ``max-width: 100%`` lets a narrow window shrink it).  ``src``:
    a file name or a data URI; ``png_bytes``: the image (for its width) when ``width`` is not
    given.  ``link``: wrap it in a link (e.g. to the full-size file)."""
    from html import escape

    if width is None:
        width = png_size(png_bytes)[0] if png_bytes is not None else PAGE_WIDTH_PX
    width = min(int(width), PAGE_WIDTH_PX)
    tag = (f'<img src="{escape(src)}" alt="{escape(alt)}" width="{width}" '
           f'style="max-width:100%;height:auto">')
    return f'<a href="{escape(link)}">{tag}</a>' if link else tag


def data_uri(png_bytes: bytes) -> str:
    """``data:image/png;base64,...`` of PNG bytes (figures embedded in one-page reports)."""
    import base64

    return "data:image/png;base64," + base64.b64encode(png_bytes).decode("ascii")


def embedded_img(png_bytes: bytes, alt: str) -> str:
    """:func:`img_tag` of an embedded PNG."""
    return img_tag(data_uri(png_bytes), alt, png_bytes)

