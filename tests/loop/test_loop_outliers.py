"""The loop report agrees with itself (issue 23): on clean simulated data (Gaussian noise, no
gross error) the points reported as outliers -- off the final fit by more than 5 of its robust
standard deviations -- are a handful, with or without an undeclared effect that the loop then
finds; the error-map panels span the data."""

from __future__ import annotations


import numpy as np
import pytest

import volerr
from volerr.loop.run import run_loop
from volerr.loop.simulate import demo_probes, simulate

THERMAL = {"kind": "thermal", "axis": "X", "ppm_per_K": 11.5}


# At 100 000 points only: the 30 000-point runs (same seed, effect and checks) were the
# weaker copy.  False outliers grow with n (0.5 expected at 30 000, 1.5 at 100 000 against
# the bar of 10), so a threshold or scale set too low shows 3.3 times more at 100 000; the
# robust sigma's sampling error (median of the 3-D length: 0.56 / sqrt(n) relative) is 0.3 %
# at 30 000 and 0.2 % at 100 000, both far inside the 5 % checked.
@pytest.mark.slow
@pytest.mark.parametrize("n", [100_000])
@pytest.mark.parametrize("effect", [True, False])
def test_outliers_on_clean_data_are_a_handful(n, effect):
    camp = simulate("MB1", n_points=n, seed=5, probes=demo_probes(volerr.load("MB1")),
                    effects=[THERMAL] if effect else [], noise_um=0.3)
    rep = run_loop("MB1", camp, progress=False, degree=4, families=("thermal",))
    assert [e["kind"] for e in rep["effects"]] == (["thermal"] if effect else [])
    o = rep["outliers"]
    # 3-D residual of N(0, 0.3 um) per coordinate: beyond 5 sigma with probability
    # P(chi2_3 > 25) = 1.5e-5, i.e. ~0.5 (30 000) and ~1.5 (100 000) expected points
    assert o["count"] < 0.005 * n
    assert o["count"] <= 10
    assert o["robust_sigma_um"] == pytest.approx(0.3, rel=0.05)
    assert o["threshold_um"] == pytest.approx(5 * o["robust_sigma_um"], rel=1e-3)
    # the held-out maximum after augmentation cannot lie far beyond the outlier threshold
    # when no outlier is held out
    assert rep["inliers"]["n_test"] >= rep["n_test"] - o["count"]


def test_error_map_panels_span_the_data(monkeypatch):
    from volerr.loop import report as rp

    camp = simulate("MB1", n_points=600, seed=2, probes=demo_probes(volerr.load("MB1")),
                    effects=[THERMAL], noise_um=0.3)
    rep = run_loop("MB1", camp, progress=False, degree=3, families=("thermal",))
    figs = []
    monkeypatch.setattr(rp, "png", lambda fig: figs.append(fig) or b"\x89PNG\r\n\x1a\n"
                        + b"\0" * 8 + (100).to_bytes(4, "big") * 2)
    rp.fig_maps(rep.plot_data)
    (fig,) = figs
    fig.canvas.draw()
    x, y = (np.asarray(camp.columns()[a], float) for a in ("X", "Y"))
    panels = [ax for ax in fig.axes if ax.get_label() != "<colorbar>"]
    assert len(panels) == 2
    for ax in panels:
        (x0, x1), (y0, y1) = ax.get_xlim(), ax.get_ylim()
        assert x0 <= x.min() and x1 >= x.max() and y0 <= y.min() and y1 >= y.max()
        # and not much more than the data: at most 10 % margin
        assert (x1 - x0) <= 1.1 * np.ptp(x) and (y1 - y0) <= 1.1 * np.ptp(y)
    import matplotlib.pyplot as plt
    plt.close(fig)
