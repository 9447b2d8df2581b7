"""The set-up sheet's figure (issue 38 item 2, C57/C63): the title inside the figure, no two
set-up labels of a view overlapping, set-ups at one place labelled once."""

from __future__ import annotations

import pytest

from volerr import plotstyle
from volerr.plan import _sheet, plan

# the module fixtures once, on one xdist worker (not once per worker)
pytestmark = pytest.mark.xdist_group("plan_sheet")


@pytest.fixture(scope="module")
def fig():
    p = plan("MB1", ["ballbar:lengths=100,150,250"], 360)
    with plotstyle.pyplot().style.context(str(plotstyle.STYLE)):
        f = _sheet.views(p)
        f.canvas.draw()
        yield f
    plotstyle.pyplot().close(f)


def test_title_and_key_inside_the_figure(fig):
    r = fig.canvas.get_renderer()
    page = fig.bbox
    for artist in [fig._suptitle, *fig.legends]:
        box = artist.get_window_extent(r)
        assert box.x0 >= page.x0 - 0.5 and box.x1 <= page.x1 + 0.5, box
        assert box.y0 >= page.y0 - 0.5 and box.y1 <= page.y1 + 0.5, box


def test_set_up_labels_do_not_overlap(fig):
    r = fig.canvas.get_renderer()
    for ax in fig.axes:
        texts = [t for t in ax.texts if t.get_text()]
        boxes = [t.get_window_extent(r) for t in texts]
        for i in range(len(boxes)):
            for j in range(i + 1, len(boxes)):
                assert not boxes[i].overlaps(boxes[j]), (texts[i].get_text(),
                                                         texts[j].get_text())
        labels = [lab for t in texts for lab in t.get_text().split(", ")]
        assert len(labels) == len(set(labels))
