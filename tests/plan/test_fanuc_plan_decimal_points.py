"""``volerr plan --dialect fanuc`` writes every axis and arc number with a decimal point: in
an O-number program ``Z400`` is 0.400 mm on a Fanuc whose parameter 3401#0 DPI is 0, and
``volerr compensate`` refuses such a word (acceptance run benchmarks/acceptance/nc_programs2).
Other dialects keep their numbers."""

import re

from volerr.nc import dialect
from volerr.plan._dialect import Fanuc, Iso, Op

OPS = [Op("start", {"Z": 400.0}), Op("rapid", {"X": 100.0, "Y": 250.0}),
       Op("line", {"Z": 20.0}, feed=500.0),
       Op("arc", {"X": 150.0, "Y": 300.0}, feed=500.0, normal="Z", ccw=True,
          centre={"X": 150.0, "Y": 250.0}),
       Op("end")]


def test_fanuc_axis_and_arc_numbers_carry_a_decimal_point():
    text = Fanuc(("X", "Y", "Z")).render(OPS, "p")
    words = re.findall(r"(?<![A-Z])([XYZIJK])(-?[\d.]+)", re.sub(r"\([^)]*\)", "", text))
    assert words and all("." in v for _, v in words), words
    assert "G53 G0 Z400." in text
    dialect.refuse_decimal_less(text.splitlines(keepends=True))    # compensate reads it


def test_iso_numbers_unchanged():
    assert "G53 G0 Z400\n" in Iso(("X", "Y", "Z")).render(OPS, "p")
