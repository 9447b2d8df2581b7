"""The one residual rule and the one consent rule (:mod:`volerr.fit_quality`) on their own:
the verdicts against scipy's chi-square survival function computed here, the limit grammar
(units required, converted to um / urad), and the changes beyond a limit."""

import math

import pytest
from scipy.stats import chi2

from volerr import fit_quality as fq
from volerr.errors import InputError


@pytest.mark.parametrize("ratio,dof", [(1.0, 10), (1.2, 5000), (3.9, 10000), (4.2, 3),
                                       (4.5, 200), (9.0, 50), (30.0, 1)])
def test_refused_exactly_when_p_below_1e6_and_ratio_above_4(ratio, dof):
    q = fq.judge(ratio * dof, dof, "u test")
    p = chi2.sf(ratio * dof, dof)
    assert q.p_value == pytest.approx(p, rel=1e-9, abs=1e-300)
    assert q.far_above == (p < 1e-6 and ratio > 4.0)
    assert q.verdict == ("refused" if q.far_above else
                         "consistent" if (p >= 1e-3 or ratio <= 1.5) else "above")
    d = q.to_dict()
    assert {"chi2_per_dof", "dof", "p_value", "verdict"} <= set(d) and d["dof"] == dof


def test_a_large_campaign_slightly_above_is_written():
    # 10 % above u over 5000 dof: p tiny, but the ratio is 1.21 -> not refused
    q = fq.judge(1.21 * 5000, 5000, "u")
    assert q.p_value < 1e-6 and not q.far_above


def test_require_fit_refuses_and_marks():
    q = fq.judge(10.0 * 100, 100, "u declared")
    with pytest.raises(InputError) as e:
        fq.require_fit(q, False, "calibrate f.csv")
    msg = str(e.value)
    assert "\n" not in msg and "chi2/dof = 10" in msg and "p =" in msg and "--accept-residual" in msg
    forced = fq.require_fit(q, True, "calibrate f.csv")
    assert forced.verdict == "forced" and "FORCED" in fq.forced_note(forced)
    data = {}
    fq.gate(data, q, True, "x")
    assert data["fit"]["verdict"] == "forced" and "FORCED" in data["forced"]


def test_nonfinite_residual_is_refused():
    with pytest.raises(InputError):
        fq.judge(float("nan"), 10, "u")


@pytest.mark.parametrize("text,key,value", [
    ("EX0C=20 um", "EX0C", 20.0), ("EX0C=0.02 mm", "EX0C", 20.0),
    ("EX0C=500 nm", "EX0C", 0.5), ("EA0B=50 urad", "EA0B", 50.0),
    ("EA0B=0.05 mrad", "EA0B", 50.0), ("EA0B=1 arcsec", "EA0B", math.pi / 648000 * 1e6),
    ("20 um", "um", 20.0), ("50 urad", "urad", 50.0), ("EXX@slope=5 um/m", "EXX@slope", 5e-3),
])
def test_limits_in_their_units(text, key, value):
    lim = fq.parse_max_change(text)
    assert lim[key][0] == pytest.approx(value, rel=1e-12)


@pytest.mark.parametrize("text", ["EX0C=20", "20", "EX0C=20 inch", "EX0C=-1 um", "EX0C=x um",
                                  "EX0C=1 um,EX0C=2 um", ""])
def test_limits_need_units(text):
    with pytest.raises(InputError) as e:
        fq.parse_max_change(text)
    assert "--max-change" in str(e.value) and "\n" not in str(e.value)


def test_changes_beyond_their_limit():
    old = {"EX0C": {"value": 10.0, "unit": "um"}, "EA0B": {"value": 5.0, "unit": "urad"},
           "EY0C": {"value": 0.0, "unit": "um"}}
    new = {"EX0C": {"value": 31.0, "unit": "um"}, "EA0B": {"value": 60.0, "unit": "urad"},
           "EY0C": {"value": -19.0, "unit": "um"}}
    lim = fq.parse_max_change("20 um,EA0B=50 urad")
    out = fq.changes_beyond(old, new, lim)
    assert [(c["parameter"], c["change"]) for c in out] == [("EX0C", 21.0), ("EA0B", 55.0)]
    with pytest.raises(InputError) as e:
        fq.require_consent(out, False, "check f.csv")
    assert "EX0C" in str(e.value) and "10" in str(e.value) and "31" in str(e.value) \
        and "20 um" in str(e.value)
    assert fq.require_consent(out, True, "check f.csv") == out
    with pytest.raises(InputError):           # an angle bounded by a length
        fq.changes_beyond(old, new, fq.parse_max_change("EA0B=5 um"))
