"""``volerr loop`` on instrument files (issue 19, fourth "Done when" item): the residual
tracing names a planted effect from ballbar traces alone (the X scale growing with T_C,
circles at several temperatures) and from sphere data alone (a rotary-axis location error
drifting with T_C), the held-out residual reaches the floor, and clean data gives no effect.

Data from the independent exact simulator (tests/helpers/instrument_sim.py).  The floor is
the held-out RMS of the TRUE model (planted static parameters + the planted effect + all
set-up unknowns) fitted by weighted least squares: on the program's own split when the JSON
reports it per file ("test_rows"), otherwise the median over random splits of the same held-out
fraction (0.25).  Sphere residuals: RMS of the length of the 3-D residual vector."""

import numpy as np
import pytest

from helpers import instrument_sim as S
from instruments._common import (FLOOR_FACTOR, Campaign, expected_floor, floor_fit,
                                 random_setup, run_json, true_design)

# module-scoped simulated data: keep the module on one xdist worker
pytestmark = pytest.mark.xdist_group("test_loop_instruments")

TEMPS = [20.2, 23.1, 21.0, 24.8, 22.0, 25.3]


def ballbar_campaign(thermal: bool):
    """MB1, two pivots mounted through the warm-up (placements "low" at z = 100 mm and "high"
    at z = 300 mm: at one height the X scale could not be told from a pitch of X growing
    with T_C, EBX x Z), XY circles R 100 at six temperatures, heights alternating, both
    directions at each height; static squareness and scale errors; the X scale grows
    11.5 um/m/K with T_C - 20 when ``thermal``."""
    m = S.Machine("MB1")
    rng = np.random.default_rng(31)
    blocks = []
    for i, T in enumerate(TEMPS):
        z, label = (100.0, "low") if i % 2 == 0 else (300.0, "high")
        b = S.ballbar_circle(m, "warm.csv", "XY", (450.0, 290.0, z), 100.0, 120,
                             1 if (i // 2) % 2 == 0 else -1, label, start_deg=3.0 * i,
                             u_um=0.3, cov={"T_C": T + rng.normal(0, 0.02, 120)})
        blocks.append(b)
    b = S.concat(blocks)
    terms = [S.constant("EC0Y"), S.series("EXX", 1, 350.0, 550.0),
             S.series("EYY", 1, 190.0, 390.0),
             S.covariate_scale("EXX", "T_C", 20.0, name="KT_X")]
    values = {"EC0Y": 18.0, "EXX@slope": 0.008, "EYY@slope": -0.006,
              "KT_X": 11.5 if thermal else 0.0}
    setup = random_setup([b], np.random.default_rng(32))
    return Campaign(m, [b], terms, values, setup, seed=33)


def sphere_campaign(drift: bool):
    """TT_AC R-test: three placements, tilt x C grid repeated at four temperatures (the order
    of the temperatures is not monotonic); EY0C = -9 um + 2.5 um/K (T_C - 20) when ``drift``.
    (Not EX0C: on TT_AC an offset of the C axis along x acts exactly like an offset of the X
    axis -- A turns about x -- so its drift could be named either way.)"""
    m = S.Machine("TT_AC")
    rng = np.random.default_rng(41)
    temps = [20.5, 24.0, 22.0, 25.5]
    grid = [{"A": a, "C": c} for a in (-30, 0, 30) for c in np.arange(0.0, 360.0, 45.0)]
    cen = {"P1": (80, 0, 30), "P2": (-60, 60, 90), "P3": (0, -70, 130)}
    blocks = [S.sphere_block(m, "rtest.csv", cen, grid, u_um=0.5,
                             cov={"T_C": lambda pi, gi, T=T: T + rng.normal(0, 0.02)})
              for T in temps]
    b = S.concat(blocks)
    loc = [n for a in m.rotary for n in m.layout.axes[a].location_errors]
    terms = [S.constant(n) for n in loc] + [S.covariate_constant("EY0C", "T_C", 20.0,
                                                                  name="KT_EY0C")]
    values = {"EY0A": -8.0, "EB0A": 20.0, "EC0A": -15.0, "EX0C": 12.0, "EY0C": -9.0,
              "EA0C": 25.0, "EB0C": -30.0, "KT_EY0C": 2.5 if drift else 0.0}
    setup = random_setup([b], np.random.default_rng(42))
    return Campaign(m, [b], terms, values, setup, seed=43)


CASES = {"ballbar-thermal": (ballbar_campaign, True, "MB1", ("EXX", "T_C")),
         "ballbar-clean": (ballbar_campaign, False, "MB1", None),
         "sphere-drift": (sphere_campaign, True, "TT_AC", ("EY0C", "T_C")),
         "sphere-clean": (sphere_campaign, False, "TT_AC", None)}


@pytest.fixture(scope="module", params=sorted(CASES))
def run(request, tmp_path_factory):
    build, planted, layout, expect = CASES[request.param]
    camp = build(planted)
    folder = tmp_path_factory.mktemp(request.param)
    files = camp.write(folder)
    r, doc = run_json(["loop", layout, *files, "--seed", "0"], folder / "loop.json")
    return dict(case=request.param, camp=camp, r=r, doc=doc, expect=expect)


def _doc(run):
    assert run["r"].returncode == 0, run["r"].stderr[-3000:]
    return run["doc"]


def test_effect_named_or_none(run):
    doc = _doc(run)
    effects = doc["effects"]
    if run["expect"] is None:
        assert effects == [], [(e.get("kind"), e.get("parameter"), e.get("covariate"))
                               for e in effects]
        return
    assert effects, "no effect found"
    first = effects[0]
    assert (first["parameter"], first["covariate"]) == run["expect"], first
    assert first["kind"] == "thermal", first
    # further effects only as the same cause seen another way
    assert len(effects) == 1 or all(e.get("evidence", {}).get("same_cause_as")
                                    for e in effects[1:]), effects


def test_floor_reached(run):
    """Held-out RMS after the loop <= 1.15 x the floor of the true model, per file, in the
    instrument's unit; and not below the floor / 1.15 (a unit or convention slip)."""
    doc = _doc(run)
    camp = run["camp"]
    (b,) = camp.blocks
    (e,) = doc["instruments"]
    assert e["file"] == b.name and e["n"] == b.n and e["unit"] == "um", e
    assert e["kind"] == b.kind, e
    if "test_rows" in e:
        floor = floor_fit(camp, {b.name: e["test_rows"]}, design=true_design(camp))[b.name]
    else:
        floor = expected_floor(camp)[b.name]
    assert e["rms_after_um"] <= FLOOR_FACTOR * floor, (e, floor)
    assert e["rms_after_um"] >= floor / FLOOR_FACTOR, (e, floor)
    if run["expect"] is not None:
        # the effect is large: the declared model alone stays well above the floor
        assert e["rms_before_um"] > 2 * FLOOR_FACTOR * floor, (e, floor)
