"""Transfer rules: errors measured at an offset, transferred back, give the direct model.

The 'measurement' is simulated with the independent exact numpy chain: the translational
error of one axis is read at a probe point with a lever arm ``o`` from the axis' reference
point, with only that axis' errors present (as a laser measurement isolates one axis).
"""

import numpy as np
import pytest

import volerr
from helpers.reference_chain import first_order_by_differences

CMMS = ["MB1", "MB2", "FB1", "FB2", "MH1", "MH2", "FH1", "FH2", "CX", "CY"]


def _lever_arm(layout, axis, q, probe):
    """Nominal vector from the axis' error frame to the probe tip: positions of everything
    after it in the tool-relative chain, plus the probe offset (CMMs: no nominal rotations)."""
    chain = list(reversed(layout.workpiece_chain)) + list(layout.tool_chain)
    after = chain[chain.index(axis) + 1:]
    o = np.array(probe, dtype=float)
    for a in after:
        o = o + q[a] * np.asarray(layout.axes[a].direction)
    return o


@pytest.mark.parametrize("name", CMMS)
def test_translational_transfer_recovers_reference_values(name):
    model = volerr.load(name)
    rng = np.random.default_rng(len(name) * 31 + ord(name[-1]))
    for axis in model.axes:
        true = {f"E{t}{axis}": rng.normal() * 5e-3 for t in "XYZ"}
        true.update({f"E{r}{axis}": rng.normal() * 3e-5 for r in "ABC"})
        q = {a: rng.uniform(*model.travel[a]) for a in model.axes}
        probe = rng.normal(size=3) * 100
        measured_vec = first_order_by_differences(model.layout, q, true, probe)
        measured = {f"E{t}{axis}": measured_vec[i] for i, t in enumerate("XYZ")}
        o = _lever_arm(model.layout, axis, q, probe)
        angular = {k: v for k, v in true.items() if k[1] in "ABC"}
        back = model.transfer(measured, o, angular=angular)
        for k, v in back.items():
            assert v == pytest.approx(true[k], abs=1e-9), (axis, k)


@pytest.mark.parametrize("name", ["MB1", "MH2", "FB1", "CY"])
def test_transferred_errors_give_the_direct_volumetric_error(name):
    """Measure every axis at its own offset, transfer, evaluate the model at other points:
    identical to the model with the true parameters."""
    model = volerr.load(name)
    rng = np.random.default_rng(99)
    true = {p: rng.normal() * (3e-5 if p[1] in "ABC" else 5e-3) for p in model.parameters
            if "0" not in p}
    transferred = {}
    for axis in model.axes:
        q = {a: rng.uniform(*model.travel[a]) for a in model.axes}
        probe = rng.normal(size=3) * 100
        own = {k: v for k, v in true.items() if k.endswith(axis)}
        vec = first_order_by_differences(model.layout, q, own, probe)
        meas = {f"E{t}{axis}": vec[i] for i, t in enumerate("XYZ")}
        transferred.update(model.transfer(meas, _lever_arm(model.layout, axis, q, probe),
                                          angular={k: v for k, v in own.items() if k[1] in "ABC"}))
        transferred.update({k: v for k, v in own.items() if k[1] in "ABC"})
    pos = np.column_stack([rng.uniform(*model.travel[a], size=50) for a in model.axes])
    np.testing.assert_allclose(model.volumetric_error(pos, transferred, (10, -20, 30)),
                               model.volumetric_error(pos, true, (10, -20, 30)), atol=1e-9)


@pytest.mark.parametrize("name", ["MB1", "MH2", "FH1", "CX"])
def test_squareness_transfer_from_straightness_reference_lines(name):
    """Apparent squareness = angle between straightness reference lines fitted to simulated
    measurements at a location where other axes have constant angular errors."""
    model = volerr.load(name)
    rng = np.random.default_rng(5)
    angular = {f"E{r}{a}": rng.normal() * 3e-5 for a in "XYZ" for r in "ABC"}
    for sq, (first, second) in {"EC0Y": "XY", "EB0Z": "XZ", "EA0Z": "YZ"}.items():
        true = {sq: 4e-5, **angular}
        loc = {a: rng.uniform(*model.travel[a]) for a in model.axes}
        idx = {"X": 0, "Y": 1, "Z": 2}

        def slope(moving, component):
            t = np.linspace(0, 200, 5)
            vals = []
            for s in t:
                q = dict(loc)
                q[moving] = loc[moving] + s
                vals.append(first_order_by_differences(model.layout, q, true, (0, 0, 0)))
            return np.polyfit(t, np.array(vals)[:, idx[component]], 1)[0]

        s_sum = slope(second, first) + slope(first, second)
        apparent = {"EC0Y": -s_sum, "EB0Z": s_sum, "EA0Z": -s_sum}[sq]
        back = model.transfer({sq: apparent}, [loc["X"], loc["Y"], loc["Z"]], angular=angular)
        assert back[sq] == pytest.approx(4e-5, abs=1e-11), sq
