"""``plotstyle.png`` draws a figure once (its layout run before ``savefig``) and encodes it at
zlib level 1: the pixels must be those of matplotlib's own ``savefig`` (which draws twice),
for the kinds of figure volerr draws (constrained layout with a colorbar, a polar axes, an
equal-aspect axes, a legend outside, a suptitle), and the figure keeps its layout engine."""

from __future__ import annotations

import io

import numpy as np
import pytest

from volerr import plotstyle


def _figure(kind: str):
    plt = plotstyle.pyplot()
    rng = np.random.default_rng(3)
    if kind == "polar":
        fig = plt.figure(figsize=(6, 5), layout="constrained")
        ax = fig.add_subplot(projection="polar")
        t = np.linspace(0, 2 * np.pi, 200)
        ax.plot(t, 1 + 0.1 * np.sin(3 * t), label="trace")
        ax.legend(loc="upper left", bbox_to_anchor=(1.05, 1.0))
        return fig
    fig, axes = plotstyle.figure(1, 2, height=3.5)
    im = axes[0].imshow(rng.normal(size=(20, 30)), aspect="equal")
    fig.colorbar(im, ax=axes[0], label="EXX / µm")
    axes[1].plot(np.arange(10), rng.normal(size=10), "o-", label="a long legend entry")
    axes[1].legend(loc="center left", bbox_to_anchor=(1.0, 0.5))
    axes[1].set_xlabel(plotstyle.label("X", "mm"))
    fig.suptitle("two panels, a colorbar and a legend outside")
    return fig


def _pixels(data: bytes):
    from PIL import Image

    return np.asarray(Image.open(io.BytesIO(data)))


def _zlib_level(data: bytes) -> int:
    """The FLEVEL of the first IDAT's zlib header (0: fastest ... 3: slowest/maximum)."""
    pos = data.index(b"IDAT")
    return data[pos + 5] >> 6


@pytest.mark.parametrize("kind", ["panels", "polar"])
def test_png_same_pixels_as_savefig(kind):
    plt = plotstyle.pyplot()
    with plt.style.context(str(plotstyle.STYLE)):
        ref_fig = _figure(kind)
        buf = io.BytesIO()
        ref_fig.savefig(buf, format="png", dpi=plotstyle.DPI)   # matplotlib's two draws
        plt.close(ref_fig)
        fig = _figure(kind)
        engine = fig.get_layout_engine()
        data = plotstyle.png(fig)
    assert fig.get_layout_engine() is engine          # the engine put back
    ref, got = _pixels(buf.getvalue()), _pixels(data)
    assert ref.shape == got.shape
    assert np.array_equal(ref, got)
    assert _zlib_level(data) == 0                      # zlib level 1 is FLEVEL 0 (fastest)
    assert _zlib_level(buf.getvalue()) == 2            # PIL's default 6 is FLEVEL 2


def test_png_figure_without_layout_engine_unchanged():
    plt = plotstyle.pyplot()
    with plt.style.context(str(plotstyle.STYLE)):
        fig, ax = plotstyle.figure(layout="none")
        ax.plot([0, 1], [0, 2])
        assert fig.get_layout_engine() is None
        buf = io.BytesIO()
        fig.savefig(buf, format="png", dpi=plotstyle.DPI)
        data = plotstyle.png(fig)
    assert np.array_equal(_pixels(buf.getvalue()), _pixels(data))
