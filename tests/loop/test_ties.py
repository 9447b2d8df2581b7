"""The rule for explanations the data cannot tell apart (``volerr formats loop-lags``, "Ties"):
BIC changes equal within ``TIE_REL |dBIC| + TIE_ABS`` are one fit, and the candidate listed
first by ``candidates.build`` is named.  Nothing may depend on the last bits of a BLAS: the
choice must survive noise far above those bits, in either direction."""

from __future__ import annotations

import itertools
import math
from types import SimpleNamespace

import pytest

from volerr.estimate.blocks import BlockBase
from volerr.loop import fitting, select


def _s(name, dbic):
    return SimpleNamespace(dbic=dbic, cand=SimpleNamespace(name=name))


@pytest.mark.parametrize("signs", list(itertools.product((-1, 1), repeat=3)))
def test_ties_go_to_the_candidate_listed_first(signs):
    order = {"probe_length": 0, "EZB": 1, "Tdz": 2, "EZZ": 3}
    d = -1159.63
    # one fit, computed three ways: differences of a few ulps to 1e-9 relative
    scored = [_s("Tdz", d * (1 + signs[0] * 1e-10)), _s("EZB", d * (1 + signs[1] * 3e-12)),
              _s("probe_length", d * (1 + signs[2] * 1e-9)), _s("EZZ", d + 4.78)]
    fitting.rank(scored, order)
    assert [x.cand.name for x in scored] == ["probe_length", "EZB", "Tdz", "EZZ"]


def test_a_real_difference_is_not_a_tie():
    order = {"a": 0, "b": 1}
    scored = [_s("a", -100.0), _s("b", -100.01)]       # 1e-4 relative: the data tell them apart
    fitting.rank(scored, order)
    assert [x.cand.name for x in scored] == ["b", "a"]
    assert fitting.tied(-100.0, -100.0 * (1 + 0.5 * fitting.TIE_REL))
    assert not fitting.tied(-100.0, -100.0 * (1 + 2 * fitting.TIE_REL))


@pytest.mark.slow
@pytest.mark.parametrize("sign", [-1, 1])
def test_tool_growth_named_by_the_rule_whatever_the_rounding(sign, tmp_path, monkeypatch):
    """The DMU50 tool-growth case (a growing tool, EZB and a tool-end Z shift give the same
    columns at one tool length): every BIC change the selection computes is perturbed by
    +-1e-10 relative, alternating call by call (far above BLAS differences, far below what
    data separate); the named effect is the rule's, the others are listed at delta BIC 0."""
    from loop.test_loop_families import _run_case

    calls = itertools.count()

    def noisy(dbic):
        def f(self, gain, m_eff):
            k = next(calls)
            return dbic(self, gain, m_eff) * (1 + sign * (-1) ** k * 1e-10)
        return f

    monkeypatch.setattr(select.Base, "dbic", noisy(select.Base.dbic))
    monkeypatch.setattr(BlockBase, "dbic", noisy(BlockBase.dbic))
    rep, _, _ = _run_case("tool_growth-DMU50", tmp_path)["planted"]
    (e,) = rep["effects"]
    assert e["parameter"] == "probe.length", e["name"]
    tied = [a["parameter"] for a in e["alternatives"] if math.isclose(a["delta_bic"], 0.0)]
    assert {"EZB", "tool.dz"} <= set(tied), e["alternatives"]
