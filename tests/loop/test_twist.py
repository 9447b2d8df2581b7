"""The instrument placement (rigid twist of the workpiece frame) and the tool-end twist used by
the loop come from the generated ``setup_sensitivity``: checked here against finite rigid
motions of the nominal tool point (central differences, independent of the derivation)."""

import numpy as np
import pytest

import volerr
from volerr.estimate.design import TWIST, Data, twist_sensitivity


def _rot(v):
    """Exact rotation matrix of the rotation vector v (Rodrigues)."""
    a = np.linalg.norm(v)
    if a == 0:
        return np.eye(3)
    k = np.asarray(v) / a
    K = np.array([[0, -k[2], k[1]], [k[2], 0, -k[0]], [-k[1], k[0], 0]])
    return np.eye(3) + np.sin(a) * K + (1 - np.cos(a)) * K @ K


@pytest.mark.parametrize("layout", ["MB1", "FB1", "TT_AC"])
def test_twist_columns_are_rigid_motions(layout):
    model = volerr.load(layout)
    rng = np.random.default_rng(7)
    n = 25
    pos = {a: rng.uniform(*model.travel[a], n) for a in model.axes}
    probe = rng.uniform(-80, 80, (n, 3))
    got = twist_sensitivity(model, Data(pos, probe, np.zeros((n, 3))))
    nominal = model.nominal_position(pos, probe)
    h = 1e-6
    for j, k in enumerate(("dx", "dy", "dz", "ex", "ey", "ez")):
        e = np.eye(3)[j % 3]
        if k[0] == "d":        # translation of the workpiece frame / of the tool end
            work = np.broadcast_to(e, (n, 3))
            ends = [model.nominal_position(pos, probe + s * h * e) for s in (1, -1)]
        else:                  # rotation about the frame origin / the tool-end origin
            ends_w = [nominal @ _rot(s * h * e).T for s in (1, -1)]
            work = (ends_w[0] - ends_w[1]) / (2 * h)
            ends = [model.nominal_position(pos, probe @ _rot(s * h * e).T) for s in (1, -1)]
        tool = (ends[0] - ends[1]) / (2 * h)
        np.testing.assert_allclose(got[:, :, TWIST[f"work.{k}"]], work, atol=1e-6)
        np.testing.assert_allclose(got[:, :, TWIST[f"tool.{k}"]], tool, atol=1e-6)
