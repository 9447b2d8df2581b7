"""The closing loop on every shipped layout family (issue 21), on data of the independent exact
simulator (tests/helpers/family_sim.py on tests/helpers/instrument_sim.py: its own chain from
the parsed layout, never volerr's generated code).

Per family one undeclared effect of its own kind, in the family's natural instrument (3-D
deviations of a CMM against a reference, R-test / sphere probing on a five-axis machine):

* a stylus that grows with the probe's temperature (MB1, six styli of two lengths) and a tool
  that grows with the spindle's (DMU50): effects on the probe / tool offset, proportional to
  each offset's own length;
* bridge twist (MB2: the yaw of the bridge X depends on where the carriage Y stands), ram
  growth (MH1: the horizontal arm X; CY: the vertical ram Z, each about its own fixed point),
  table-side against tool-side thermal (FB1: the table Y with T_table, T_bridge also logged;
  FH2: the arm X with T_arm, T_table also logged; TH_BC: the C table's location with T_table,
  T_head also logged), rotary axis locations that drift (TT_AC: the trunnion height h of the
  layout, HH_BC: the head's pivot distance L, DMU50: the height d of the swivelling table's
  axes, all layout parameters: "d grows 2 um/K with T_spindle");

and the same campaign without the effect (clean control).  Every campaign also logs the room
temperature or a second channel and the time, has static squareness / location / component
errors (polynomials) and an unknown instrument set-up.

Checked: the single accepted effect names the planted parameter (or symbol) and covariate, its
value agrees with the planted one within 3 reported standard uncertainties (+2 %), its
description speaks the layout's words; the held-out RMS is at most 1.15 x the floor -- the
held-out RMS of the true model (planted parameters + set-ups) fitted by weighted least squares
on the loop's own split (the JSON's test_rows) -- and not below floor / 1.15; on clean data no
effect is found and the RMS is at the floor too."""

from __future__ import annotations

import numpy as np
import pytest
from threadpoolctl import threadpool_limits

from helpers import family_sim as F
from helpers import instrument_sim as S

FLOOR_FACTOR = 1.15
PROBES = [(0, 0, -120), (90, 0, -120), (-90, 0, -120), (0, 90, -120), (0, -90, -120)]


def _time(rng, n):
    return np.sort(rng.uniform(0.05, 6.0, n))


def deviations(layout, n, seed, channels, terms, values, probes=PROBES, u_um=0.5):
    """A CMM campaign: n random points over the travel, random styli, time-ordered channels."""
    m = F.Machine(layout)
    rng = np.random.default_rng(seed)
    t_h = _time(rng, n)
    cov = {**F.channels(t_h, rng, channels), "t_s": 3600.0 * t_h}
    b = S.deviations_block(m, f"{layout}.csv", n, rng, probes=probes, u_um=u_um, cov=cov)
    setup = F.placement(rng, [b])
    return m, [b], terms(m), values, setup


def sphere(layout, seed, tilt, tilts, centres, channels, terms, values, tool=(0, 0, 0),
           states=5, u_um=0.5):
    """An R-test campaign: the tool sent to three sphere placements at every pose of a tilt x C
    grid, repeated at ``states`` thermal states over six hours."""
    m = F.Machine(layout)
    rng = np.random.default_rng(seed)
    grid = [{tilt: t, "C": c} for t in tilts for c in np.arange(0.0, 360.0, 45.0)]
    t_h = np.linspace(0.3, 6.0, states)
    chans = F.channels(t_h, rng, channels)
    blocks = []
    for i in range(states):
        cov = {c: (lambda pi, gi, v=chans[c][i]: v + rng.normal(0.0, 0.02)) for c in channels}
        cov["t_s"] = lambda pi, gi, t=t_h[i]: 3600.0 * t + 15.0 * (pi * len(grid) + gi)
        blocks.append(S.sphere_block(m, f"{layout}_rtest.csv", centres, grid, probe=tool,
                                     u_um=u_um, cov=cov))
    b = S.concat(blocks)
    setup = F.placement(rng, [b])
    locs = [n for a in m.rotary for n in m.layout.axes[a].location_errors]
    vals = {n: float(v) for n, v in zip(locs, rng.normal(0.0, 15.0, len(locs)))}
    return m, [b], [S.constant(n) for n in locs] + terms(m), {**vals, **values}, setup


def _cmm_statics(m):
    tr = m.travel
    return [S.constant("EC0Y"), S.constant("EB0Z"), S.constant("EA0Z"),
            S.series("EXX", 1, *tr["X"]), F.legendre_term("EYX", 2, *tr["X"]),
            F.legendre_term("EZY", 2, *tr["Y"]), S.series("EYY", 1, *tr["Y"]),
            F.legendre_term("EBX", 2, *tr["X"]), F.legendre_term("ECY", 1, *tr["Y"]),
            F.legendre_term("EAZ", 1, *tr["Z"])]


CMM_VALUES = {"EC0Y": 15.0, "EB0Z": -10.0, "EA0Z": 8.0, "EXX@slope": 0.006, "EYX@P2": 3.0,
              "EZY@P2": -2.5, "EYY@slope": -0.004, "EBX@P2": 4.0, "ECY@P1": 3.0,
              "EAZ@P1": -3.0}


def _cmm(layout, seed, channels, name, term, value, probes=PROBES, n=450):
    """CMM statics plus the effect ``term(machine)`` whose parameter ``name`` is ``value``."""
    return deviations(layout, n, seed, channels, lambda m: _cmm_statics(m) + [term(m)],
                      {**CMM_VALUES, name: value}, probes)


# ---- the cases -----------------------------------------------------------------------------
def stylus(value):
    styli = [(60, 0, 0), (-60, 0, 0), (0, 60, 0), (0, -60, 0), (0, 0, -60), (0, 0, -150)]
    return _cmm("MB1", 11, ["T_C", "T_probe"], "KL",
                lambda m: F.Growth("KL", "probe.length", lambda b: b.cov["T_probe"] - 20.0),
                value, styli)


def bridge_twist(value):
    return _cmm("MB2", 12, ["T_C"], "CP", lambda m: F.coupling("ECX", "Y", m.travel, "CP"),
                value)


def table_thermal(value):
    return _cmm("FB1", 13, ["T_table", "T_bridge"], "KT",
                lambda m: F.scale("EYY", "T_table", "KT"), value)


def arm_growth(value):
    return _cmm("MH1", 14, ["T_C", "T_ram"], "KT",
                lambda m: F.scale("EXX", "T_ram", "KT", fixed_point=-250.0), value)


def arm_thermal(value):
    return _cmm("FH2", 15, ["T_arm", "T_table"], "KT",
                lambda m: F.scale("EXX", "T_arm", "KT", fixed_point=-150.0), value)


def ram_growth(value):
    return _cmm("CY", 16, ["T_C", "T_ram"], "KT",
                lambda m: F.scale("EZZ", "T_ram", "KT", fixed_point=550.0), value)


def tool_growth(value):
    return sphere("DMU50", 21, "B", [0, 45, 90],
                  {"P1": (80, 0, 30), "P2": (-60, 60, 90), "P3": (0, -70, 130)},
                  ["T_C", "T_spindle"],
                  lambda m: [F.Growth("KL", "probe.length", lambda b: b.cov["T_spindle"] - 20.0)],
                  {"KL": value}, tool=(0, 0, -100.0))


def swivel_height(value):
    return sphere("DMU50", 25, "B", [0, 45, 90],
                  {"P1": (80, 0, 30), "P2": (-60, 60, 90), "P3": (0, -70, 130)},
                  ["T_C", "T_spindle"],
                  lambda m: [F.Growth("KD", "param.d", lambda b: b.cov["T_spindle"] - 20.0)],
                  {"KD": value}, tool=(0, 0, -100.0))


def trunnion_height(value):
    return sphere("TT_AC", 22, "A", [-30, 0, 30, 45],
                  {"P1": (80, 0, 30), "P2": (-60, 60, 90), "P3": (0, -70, 130)},
                  ["T_table", "T_C"],
                  lambda m: [F.Growth("KH", "param.h", lambda b: b.cov["T_table"] - 20.0)],
                  {"KH": value})


def head_pivot(value):
    return sphere("HH_BC", 23, "B", [-60, -30, 0, 30, 60],
                  {"P1": (1000, 700, 200), "P2": (600, 400, 350), "P3": (1400, 900, 250)},
                  ["T_head", "T_C"],
                  lambda m: [F.Growth("KL", "param.L", lambda b: b.cov["T_head"] - 20.0)],
                  {"KL": value})


def table_location(value):
    return sphere("TH_BC", 24, "B", [-45, 0, 45],
                  {"P1": (80, 0, 80), "P2": (-60, 70, 150), "P3": (0, -90, 250)},
                  ["T_table", "T_head"],
                  lambda m: [F.drift("EY0C", "T_table", "KY")], {"KY": value})


CASES = {
    # name: (builder, planted value, layout, (parameter, covariate), kind, words)
    "stylus-MB1": (stylus, 23.0, "MB1", ("probe.length", "T_probe"), "thermal",
                   "stylus length grows"),
    "bridge_twist-MB2": (bridge_twist, 20.0, "MB2", ("ECX", "Y"), "coupling", "ECX"),
    "table_thermal-FB1": (table_thermal, 9.0, "FB1", ("EYY", "T_table"), "thermal", "EYY"),
    "arm_growth-MH1": (arm_growth, 12.0, "MH1", ("EXX", "T_ram"), "thermal", "EXX"),
    "arm_thermal-FH2": (arm_thermal, 10.0, "FH2", ("EXX", "T_arm"), "thermal", "EXX"),
    "ram_growth-CY": (ram_growth, 11.0, "CY", ("EZZ", "T_ram"), "thermal", "EZZ"),
    "tool_growth-DMU50": (tool_growth, 11.5, "DMU50", ("probe.length", "T_spindle"),
                          "thermal", "tool length grows"),
    "swivel_height-DMU50": (swivel_height, 2.0, "DMU50", ("param.d", "T_spindle"), "thermal",
                            "d (point of axis B) grows"),
    "trunnion_height-TT_AC": (trunnion_height, 2.0, "TT_AC", ("param.h", "T_table"),
                              "thermal", "h (point of axis A) grows"),
    "head_pivot-HH_BC": (head_pivot, 1.5, "HH_BC", ("param.L", "T_head"), "thermal",
                         "L (point of axis B) grows"),
    "table_location-TH_BC": (table_location, 2.0, "TH_BC", ("EY0C", "T_table"), "thermal",
                             "EY0C"),
}


def _loop(camp, layout, folder):
    from volerr.loop.run import run_loop

    files = camp.write(folder)
    rep = run_loop(layout, files, seed=0, progress=False)
    rep.data["augmented_text"] = rep.augmented_text
    (inst,) = rep["instruments"]
    floor = camp.floor({camp.blocks[0].name: inst["test_rows"]})[camp.blocks[0].name]
    return rep, inst, floor


def _run_case(name, tmp_path):
    build, value, layout, expect, kind, words = CASES[name]
    out = {"name": name, "expect": expect, "kind": kind, "words": words, "value": value}
    with threadpool_limits(limits=1):
        for label, v in (("planted", value), ("clean", 0.0)):
            m, blocks, terms, values, setup = build(v)
            camp = F.Campaign(m, blocks, terms, values, setup, seed=len(name))
            folder = tmp_path / label
            folder.mkdir()
            out[label] = _loop(camp, layout, folder)
    return out


def check_named(case):
    """One accepted effect, the planted parameter (or symbol) and covariate, in the layout's
    words."""
    rep, inst, floor = case["planted"]
    effects = rep["effects"]
    assert len(effects) == 1, [(e["name"], e["parameter"], e["covariate"]) for e in effects]
    (e,) = effects
    assert (e["parameter"], e["covariate"]) == case["expect"], e
    assert e["kind"] == case["kind"], e
    assert case["words"] in e["description"] and case["expect"][1] in e["description"], e
    # the augmented layout carries it as an effect on that parameter or symbol
    from volerr.machine.layout import parse_layout

    (effect,) = parse_layout(rep["augmented_text"]).effects
    want = case["expect"][0]
    targets = {t.target for t in effect.terms}
    if want == "probe.length":     # the offset components the data hold, one parameter
        assert targets and targets <= {"probe.Xp", "probe.Yp", "probe.Zp"}, targets
        assert len(effect.parameters) == 1, effect
    else:
        assert targets == {want}, targets


def check_value(case):
    """The effect's value against the planted one (report units: ppm/K, um/K, um/m/K, urad)."""
    rep, _, _ = case["planted"]
    (e,) = rep["effects"]
    if case["kind"] == "coupling":
        # the planted term u_X * u_Y is the first of the three Legendre cross terms
        pn = next(p for p in e["parameters"] if p.endswith("_11"))
    else:
        pn = next(iter(e["parameters"]))
    v, sd = e["parameters"][pn], e["std"][pn]
    assert abs(v - case["value"]) <= 3 * sd + 0.02 * case["value"], (pn, v, sd, case["value"])


def check_floor(case):
    """Held-out RMS within [floor / 1.15, 1.15 floor] on planted and clean data; the planted
    effect is large (the declared model alone stays well above the floor)."""
    for label in ("planted", "clean"):
        rep, inst, floor = case[label]
        assert inst["rms_after_um"] <= FLOOR_FACTOR * floor, (label, inst, floor)
        assert inst["rms_after_um"] >= floor / FLOOR_FACTOR, (label, inst, floor)
    rep, inst, floor = case["planted"]
    assert inst["rms_before_um"] > 1.5 * FLOOR_FACTOR * floor, (inst, floor)


def check_clean(case):
    rep, inst, _ = case["clean"]
    assert rep["effects"] == [], [(e["name"], e["parameter"], e["covariate"])
                                  for e in rep["effects"]]
    assert inst["rms_after_um"] == inst["rms_before_um"]


SLOW = {"tool_growth-DMU50", "arm_growth-MH1"}


# one test per case (its two loop runs once; module fixtures are not shared reliably between
# the xdist workers here)
@pytest.mark.parametrize("name", [pytest.param(n, marks=pytest.mark.slow) if n in SLOW else n
                                  for n in sorted(CASES)])
def test_family(name, tmp_path):
    case = _run_case(name, tmp_path)
    check_named(case)
    check_value(case)
    check_floor(case)
    check_clean(case)
