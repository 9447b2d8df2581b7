"""Candidates that fit the data identically are chosen by their order, not by rounding.

On a CMM a translational component along z of X that depends on Y (``EZX(X, Y)``) and one of
Y that depends on X (``EZY(Y, X)``) add the same columns to the design: the data cannot tell
them apart.  The loop must name one deterministically (the first candidate: ``EZX`` depending
on ``Y``) and list the other as indistinguishable, whatever the seed."""

import pytest

import volerr
from volerr.loop.run import run_loop
from volerr.loop.simulate import demo_probes, simulate


@pytest.mark.parametrize("layout,seed", [("MB1", 21), ("MB1", 22), ("FB1", 23)])
def test_identical_coupling_candidates_named_deterministically(layout, seed):
    model = volerr.load(layout)
    camp = simulate(layout, n_points=400, seed=seed, probes=demo_probes(model),
                    effects=[{"kind": "coupling", "component": "EZX", "axis": "Y", "um": 5.0}],
                    noise_um=0.3)
    rep = run_loop(layout, camp, seed=seed, progress=False, families=("coupling",))
    e = rep["effects"][0]
    assert e["name"] == "coupling_EZX_Y", e["name"]
    assert "coupling_EZY_X" in e["evidence"]["indistinguishable_from"]
    assert abs(abs(e["parameters"]["CP_EZX_Y_11"]) - 5.0) < 0.5
