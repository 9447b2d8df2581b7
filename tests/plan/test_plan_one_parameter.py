"""``volerr.plan`` of a single requested parameter (issue 43 follow-up).

``volerr.plan("MB1", "ballbar", 60, parameters="EC0Y")`` raised IndexError: the plan's
information matrix of one parameter is 1 x 1, and the distance of its lone column to the span
of "the others" (none) indexed an empty eigenvalue list
(``volerr.calibrate.estimability.distances``).  A lone non-zero column is at distance 1.

The prediction is checked against the closed form: an XY circle of radius R read at N angles
evenly spread over whole turns sees the squareness as ``dr = c (R/2) sin 2t`` (orthogonal to
the set-up's pivot offsets cos t, sin t and the length 1), so ``u(c) = u_r / R sqrt(8 / N)``
with the ballbar's default u_r = 0.5 um.
"""

from __future__ import annotations

import math

import pytest

import volerr

pytestmark = pytest.mark.xdist_group("plan_one_parameter")


def test_one_parameter_plan_predicts_the_closed_form():
    p = volerr.plan("MB1", "ballbar", 60, parameters="EC0Y")
    d = p.to_dict()
    assert list(d["parameters"]) == ["EC0Y"]
    setups = [s for f in d["files"] for s in f["setups"]]
    assert all(s["plane"] == "XY" for s in setups)
    radius = {s["length_mm"] for s in setups}
    assert len(radius) == 1
    n = sum(s["readings"] for s in setups)
    expected = 0.5 / radius.pop() * math.sqrt(8.0 / n) * 1e3          # um/mm -> urad
    assert d["parameters"]["EC0Y"]["predicted_std"] == pytest.approx(expected, rel=0.02)


def test_the_lone_column_is_estimable():
    import numpy as np

    from volerr.calibrate.estimability import distances, estimable

    assert distances(np.array([[4.0]])).tolist() == [1.0]
    assert distances(np.array([[0.0]])).tolist() == [0.0]
    assert estimable(np.array([[4.0]]))[0].tolist() == [True]
