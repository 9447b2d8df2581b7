"""The named effects judged on the held-out readings (issue 44: a diagnosis judged by the
data it never saw; :func:`volerr.loop.drift.family.held_out_verdict`).

The loop names the lag model's terms wherever its blocked CV beats both baselines, whatever
family predicts.  Here they fail on the held-out runs, the acceptance set's seed 3 by
environment in small (``T_bed_lower - T_room`` at -2.71 um/K, held-out MAE 2.70 um against
the static regression's 1.23): a simulated machine (tests/helpers/spindle_machine_sim.py's
spindle) trained in a constant room and judged in a varying one.

* The structure ``T_casting`` follows the room through 4 h and the spindle's heat through
  2 h; the bearing sensor reads the structure plus the bearings' heat (10 min).
* The drift: the spindle's two lags (20 min, 3 h, opposite signs; no logged sensor follows
  them exactly) plus ``B_STRUCT`` um/K of the structure's change.
* Six runs train in a room held within 0.15 K (the room is constant); two are held out in a
  room swinging ``SWING_K`` with the day.

With six training runs or more every sensor enters the lag model as its rise over the room.
In the constant room the bearing's rise is the spindle's heat and the structure's share, and
the lag model beats both baselines run by run.  In the varying room the structure's share is
the room's too, and ``T_bearing - T_room`` swings with the room.  The static regression on
the plain temperatures carries the structure's coefficient over.  The lag model's held-out
MAE is 5.9-6.9x the static regression's (seeds 1, 2, 3: 6.91 / 6.78 / 6.69 um against
1.00 / 1.15 / 1.00 um): far past the bar, whatever the noise.  (The model the loop reports
there, the regularised fit over the lag bank, is not judged here: 2.06 / 5.75 / 5.62 um.)
One loop run (module fixture), about a second of CPU.
"""

from __future__ import annotations

import copy

import numpy as np
import pytest

from helpers import spindle_machine_sim as M
from volerr.loop.drift import family
from volerr.loop.drift.report import DriftReport
from volerr.loop.drift.run import _judge_held_out, loop_drift

SEED = 1
SAMPLE_S = 60.0
B_STRUCT = 3.0                  # um/K of the structure's change
SWING_K = 2.5                   # the varying room's daily amplitude, K
STRUCT_ROOM_TAU_S = 4 * 3600.0  # the structure following the room
#: (file, programme, the hour of day it starts): trained in the constant room
TRAIN = (("c1", "run1", 6.0), ("c2", "run2", 14.0), ("c3", "run3", 22.0),
         ("c4", "run4", 10.0), ("c5", "run2", 3.0), ("c6", "run1", 17.0))
#: held out, in the varying room
HELD = (("v1", "run4", 8.0), ("v2", "run2", 20.0))
COLS = ("t_s", "S_rpm", "d_x_um", "T_room", "T_bearing", "T_casting")


def _run(programme: str, env: str, hour: float, rng) -> dict:
    steps, _ = M.PROGRAMMES[programme]
    h = SAMPLE_S
    t = np.arange(0.0, M.RUN_H * 3600.0 + h / 2, h)
    S = M.speed(t, steps)
    q = (S / M.S_REF) ** M.HEAT_P
    amp = 0.15 if env == "constant" else SWING_K
    room = M.ROOM_MEAN + amp * np.sin(2 * np.pi * (t + hour * 3600.0) / M.DAY_S)
    struct = (M.lag_linear(room, STRUCT_ROOM_TAU_S, h)
              + M.K_CASTING * M.lag_hold(q, M.TAU_CASTING, h))
    drift = (M.A_FAST * M.lag_hold(q, M.TAU_FAST, h) + M.A_SLOW * M.lag_hold(q, M.TAU_SLOW, h)
             + B_STRUCT * (struct - struct[0]))
    true = {"T_room": room, "T_casting": struct,
            "T_bearing": struct + M.K_BEARING * M.lag_hold(q, M.TAU_BEARING, h)}
    out = {"t_s": t, "S_rpm": S,
           "d_x_um": rng.uniform(-5, 5) + drift + rng.normal(0.0, M.D_NOISE_UM, len(t))}
    for k, v in true.items():
        out[k] = v + rng.normal(0.0, M.T_NOISE_K, len(t))
    return out


def _write(path, run: dict, env: str) -> None:
    M.write_run(path, run, env, COLS, direction="?")


@pytest.fixture(scope="module")
def rep(tmp_path_factory):
    folder = tmp_path_factory.mktemp("held_out")
    rng = np.random.default_rng(SEED)
    for runs, env in ((TRAIN, "constant"), (HELD, "varying")):
        for name, programme, hour in runs:
            _write(folder / f"{name}.csv", _run(programme, env, hour, rng), env)
    paths = [folder / f"{name}.csv" for name, *_ in TRAIN + HELD]
    return loop_drift("DMU50", paths, files=[folder / f"{name}.csv" for name, *_ in HELD])


def test_the_named_terms_fail_on_the_held_out_room(rep):
    c = rep["channels"]["x"]
    assert rep.effects, "the lag model's terms are named (it beats both baselines in CV)"
    assert any(t["minus"] == "T_room" for t in rep.pred["x"]["terms"])    # a rise over the room
    h = c["held_out"]
    static = c["baselines"]["static"]["mae_um"]
    assert h == {"lag_model_mae_um": c["lag_model"]["mae_um"], "baseline_mae_um": static,
                 "baseline": "static", "bound_um": family.HELD_OUT_REL * static
                 + family.HELD_OUT_ABS_UM, "confirmed": False}
    assert h["lag_model_mae_um"] > 3 * h["bound_um"], h          # far past the bar
    for e in rep.effects:
        assert e["held_out"] == {"channel": "x", **h}
    assert rep["held_out_rule"] == family.HELD_OUT_RULE


def test_the_console_and_the_page_say_so(rep, tmp_path):
    lines = rep.summary_lines()
    heads = [i for i, ln in enumerate(lines) if ln.startswith("  thermal ")]
    first = lines[heads[0] + 1]
    assert first.startswith("    not confirmed on the held-out readings: the lag model's "
                            "held-out MAE "), first
    assert "x the static regression's" in first and "not a transfer" in first
    # said in full once; every further effect of the channel points to it
    assert sum("not confirmed on the held-out readings:" in ln for ln in lines) == 1
    for i in heads[1:]:
        assert lines[i + 1] == (f"    not confirmed on the held-out readings (as "
                                f"{rep.effects[0]['name']} above: the same lag model)")
    html = rep.write_html(tmp_path / "page.html").read_text(encoding="utf-8")
    assert "<b>not confirmed</b>: lag model" in html


def _strip(x):
    """The JSON without the verdict's keys."""
    if isinstance(x, dict):
        return {k: _strip(v) for k, v in x.items() if k not in ("held_out", "held_out_rule", "held_out_reported")}
    return [_strip(v) for v in x] if isinstance(x, list) else x


def test_the_verdict_only_adds(rep):
    """Judged on a channel whose reported model is another family, and the verdict only adds
    its keys: judging the JSON without them again gives the same JSON, and nothing else in it
    moves (no choice, no figure)."""
    assert rep["channels"]["x"]["family"] != "lag"
    bare = _strip(rep.data)
    again = copy.deepcopy(bare)
    _judge_held_out(again, rep.pred)
    assert again == rep.data and _strip(again) == bare


def test_the_reported_model_judged_by_the_same_bar(rep):
    """The model the channel reports (here not the lag model) is held to the same bar and,
    on this machine, misses it too: the console says so under the channel's model."""
    c = rep["channels"]["x"]
    h = c["held_out_reported"]
    static = c["baselines"]["static"]["mae_um"]
    assert h == {"family": c["family"], "mae_um": c["mae_after_um"], "baseline_mae_um": static,
                 "baseline": "static", "bound_um": family.HELD_OUT_REL * static
                 + family.HELD_OUT_ABS_UM, "within": c["mae_after_um"] <= h["bound_um"]}
    assert not h["within"] and h["mae_um"] > 1.5 * h["bound_um"], h
    lines = rep.summary_lines()
    said = [ln for ln in lines if ln.startswith("    NOT HELD on the held-out readings:")]
    assert len(said) == 1 and f"{h['mae_um']:.2f} um > {h['bound_um']:.2f} um" in said[0]


def test_nothing_held_out_is_not_judged_and_said_once(rep):
    data = copy.deepcopy(rep.data)
    for c in data["channels"].values():
        c["n_test"] = 0
        assert family.held_out_verdict(c) is None and family.reported_held_out(c) is None
        c["held_out"] = None
    for e in data["effects"]:
        e["held_out"] = None
    lines = DriftReport(data, rep.series, rep.pred).summary_lines()
    said = [ln for ln in lines if "not judged on held-out readings" in ln]
    assert said == ["  the effects are not judged on held-out readings: none are held out"]
    assert not any("not confirmed" in ln for ln in lines)
