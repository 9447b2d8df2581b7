"""What a training in a held room cannot decide (issue 44 item 3,
:func:`volerr.loop.drift.basis.room_undecided`), and the prediction interval carrying it
(:func:`volerr.loop.drift.interval.widen_for_room`).

The machine is tests/loop/test_drift_held_out.py's (the same runs, seed 1): six runs train in
a room held within 0.15 K, two are held out in a room swinging 2.5 K; the drift follows the
structure's absolute temperature.  With six training runs every sensor enters as its rise over
``T_room``; the training cannot tell that reading from the absolute one, the held-out room
can.  Measured here (seed 1; seeds 2 and 3 in the commit): the room's change 0.845 K peak to
peak in training, 9.53 K held out (11.3 x); ``T_bearing`` changes 12.1 K in training (room
share 0.070: named), ``T_casting`` 4.17 K (share 0.203, above 0.2: not named).  The loop
reports the regularised fit (held-out MAE 2.06 um, unchanged); its 95 % interval held 59.0 %
of the held-out readings (median half-width 1.886 um) and, widened by the difference to the
same family fitted on the sensors' absolute reading (median 0.77, max 6.17 um), 99.9 %
(median 2.618 um).

The variant: the last training run in the varying room (the room then changes as much in
training as held out): the rule does not fire and nothing of the report carries it.

The lag family's alternative (the same terms read absolute, refitted) is checked against
the simulator's own lag filter and numpy's lstsq; the rule's thresholds and ties on a small
series made here.

Checked to fail without the change: without ``room_undecided`` the key, the console line and
the page's line are missing (5 of the then 6 tests fail, the sixth is the variant's); with
the rule firing always (share 1, ratio 0) the variant's and two threshold cases fail; with
the widening left out (``widen_for_room`` given no alternative) the coverage is the 59.0 %
above; with the terms left in their rise the alternative is off by up to 5.5 um.  Two loop
runs (module fixtures), about 2 s of CPU.
"""

from __future__ import annotations

import numpy as np
import pytest

import test_drift_held_out as H
from volerr.loop.drift import basis
from volerr.loop.drift import interval as band
from volerr.loop.drift.run import loop_drift
from volerr.loop.drift.series import DriftSeries


def _loop(folder, varying_train: bool):
    """The held-out machine's campaign (seed ``H.SEED``); ``varying_train``: its last
    training run in the varying room."""
    rng = np.random.default_rng(H.SEED)
    train = [(n, p, h, "constant") for n, p, h in H.TRAIN]
    if varying_train:
        train[-1] = train[-1][:3] + ("varying",)
    for name, programme, hour, env in train + [(n, p, h, "varying") for n, p, h in H.HELD]:
        H._write(folder / f"{name}.csv", H._run(programme, env, hour, rng), env)
    paths = [folder / f"{n}.csv" for n, *_ in H.TRAIN + H.HELD]
    return loop_drift("DMU50", paths, files=[folder / f"{n}.csv" for n, *_ in H.HELD])


@pytest.fixture(scope="module")
def held_room(tmp_path_factory):
    return _loop(tmp_path_factory.mktemp("held_room"), False)


@pytest.fixture(scope="module")
def varying_run(tmp_path_factory):
    return _loop(tmp_path_factory.mktemp("varying_run"), True)


def _ptp_change(s, k, mask) -> float:
    """Peak to peak of the input's change since its run's first reading, recomputed here."""
    v = np.asarray(s.inputs[k], float)
    first = {r: v[np.flatnonzero(s.run == r)[0]] for r in np.unique(s.run)}
    d = v - np.array([first[r] for r in s.run])
    return float(d[mask].max() - d[mask].min())


def test_the_rule_fires_and_names_the_heat_proxies(held_room, tmp_path):
    s, u = held_room.series, held_room["room_undecided"]
    a, b = _ptp_change(s, "T_room", s.train), _ptp_change(s, "T_room", s.test)
    assert b > 10 * a                                     # 9.53 K against 0.845 K
    assert u["room"] == "T_room" and u["train_room_ptp_K"] == pytest.approx(a, rel=1e-12)
    assert u["held_out_room_ptp_K"] == pytest.approx(b, rel=1e-12)
    assert (u["reading"], u["alternative"]) == ("rise over the room", "absolute")
    # named: the sensors whose own training change is at least 5 x the room's
    want = [k for k in ("T_bearing", "T_casting") if a <= 0.2 * _ptp_change(s, k, s.train)]
    assert want == ["T_bearing"]
    assert [e["sensor"] for e in u["sensors"]] == want
    lines = [ln for ln in held_room.summary_lines() if "the training runs hold the room" in ln]
    assert len(lines) == 1 and lines[0].startswith("  warning: ") and "T_bearing acts by its " \
        "absolute change (a structure temperature) or by its rise over the room (a heat " \
        "proxy) is not decided by these data" in lines[0]
    assert "a training run in a varying room decides it" in lines[0]
    html = held_room.write_html(tmp_path / "page.html").read_text(encoding="utf-8")
    assert "the training runs hold the room" in html


def test_a_varying_room_run_in_training_decides_it(varying_run, tmp_path):
    assert "room_undecided" not in varying_run.data
    assert not any("hold the room" in ln for ln in varying_run.summary_lines())
    for c in varying_run["channels"].values():
        assert "room_undecided" not in c["interval"]
    html = varying_run.write_html(tmp_path / "page.html").read_text(encoding="utf-8")
    assert "the training runs hold the room" not in html


def test_the_widened_interval_covers_the_held_out_room(held_room):
    c, p, s = held_room["channels"]["x"], held_room.pred["x"], held_room.series
    iv = c["interval"]
    r = iv["room_undecided"]
    y, te = s.channels["x"], s.test
    # the prediction is the chosen family's, untouched; its held-out MAE too
    assert c["family"] == "regularised"
    np.testing.assert_array_equal(p["after"], p["regularised"])
    assert c["mae_after_um"] == c["regularised"]["mae_um"]
    # the half-width: the unwidened band plus abs(chosen - alternative), held out only
    unwidened = band.interval(p["cv_resid"], y, p["after"], basis.folds(s)[0], te,
                              p["leverage"])["per_reading"]
    d = np.abs(p["after"] - p["alternative"])
    # and the kept-out inputs' widening after it (interval.widen_for_kept_out)
    # (the bias abs(b x) added, 2 u x in quadrature with the room-widened band)
    bias, var = np.zeros(len(y)), np.zeros(len(y))
    ref = basis.reference(s)
    for e, w in zip(held_room["kept_out"], iv["kept_out_widening"]["inputs"]):
        v = basis.entered(s, e["sensor"], ref)
        x = np.abs(v - s.zero(v))
        bias += abs(w["coef_um_per_unit"]) * x
        var += (2 * w["u"] * x) ** 2
    np.testing.assert_allclose(p["half_width"][te],
                               bias[te] + np.sqrt((unwidened[te] + d[te]) ** 2 + var[te]),
                               rtol=1e-12)
    np.testing.assert_array_equal(p["half_width"][~te], unwidened[~te])
    assert r["difference_um"] == [pytest.approx(np.median(d[te])), pytest.approx(d[te].max())]
    # coverage at the stated level where before it was not (59.0 % -> 99.9 %)
    inside = np.mean(np.abs(y - p["after"])[te] <= p["half_width"][te])
    assert iv["coverage_test"] == pytest.approx(inside)
    assert r["coverage_test_unwidened"] < 0.7 and iv["coverage_test"] >= iv["level"]


def _series(train_room, test_room, sensor):
    """Two training runs and one held-out run of three readings each: the room's and a
    sensor's readings (degC) per run as given."""
    n = 3
    room = np.concatenate(train_room + [test_room])
    run = np.repeat(np.arange(3), n)
    s = DriftSeries(t_s=np.tile(np.arange(n) * 60.0, 3), run=run,
                    runs=[("a.csv", ""), ("b.csv", ""), ("c.csv", "")],
                    inputs={"T_room": room, "T_a": np.concatenate(sensor)},
                    channels={"x": np.zeros(3 * n)})
    s.test = run == 2
    return s


@pytest.mark.parametrize("held, own, fires", [
    (3.0, 5.0, False),     # the held-out room changes 3 x the training's: not more
    (3.5, 5.0, True),      # more than 3 x; the sensor's change 5 x the room's: named
    (3.5, 4.0, False),     # the sensor changes 4 x the room's: not named, nothing to say
])
def test_the_thresholds_and_their_ties(held, own, fires):
    """The rule's two ratios at and beside their thresholds (held-out room change > 3 x
    the training's, strictly; a sensor's own change >= 5 x the training room's)."""
    s = _series([np.array([20.0, 21.0, 20.5]), np.array([20.0, 20.5, 20.0])],
                np.array([20.0, 20.0 + held, 20.0]),
                [np.array([30.0, 30.0 + own, 31.0]), np.array([30.0, 31.0, 32.0]),
                 np.array([30.0, 30.0, 30.0])])
    got = basis.room_undecided(s)
    assert (got is not None) == fires
    if fires:
        assert got["sensors"] == [{"sensor": "T_a", "train_change_K": own,
                                   "room_share": 1.0 / own}]
        assert got["reading"] == "absolute"        # two runs: the sensors are taken plain


def test_the_lag_models_alternative_is_its_terms_read_absolute(held_room):
    """The lag family's alternative (not the family reported here, so judged directly): the
    same terms and time constants with every sensor's rise over the room read as its
    absolute change, refitted by least squares on the training readings with a zero per
    run, a held-out run predicted from its first reading.  Expected value computed another
    way: the simulator's own lag filter (linear between samples, at rest at each run's
    first reading) and numpy's lstsq."""
    from helpers import spindle_machine_sim as M
    from volerr.loop.drift import fit as core

    s, terms = held_room.series, held_room.pred["x"]["terms"]
    assert any(t["minus"] == "T_room" for t in terms)
    y, tr = s.channels["x"], s.train
    fold, rule = basis.folds(s)
    ch = core.Channel(s, y, s.indicators(), fold, rule)
    got = core._Alternative(s, False).predict(ch, {"choice": {"family": "lag"},
                                                   "terms": terms})
    h = float(np.median(np.diff(s.t_s)))
    cols = []
    for t in terms:
        u = (np.abs(s.inputs["S_rpm"]) / np.abs(s.inputs["S_rpm"][tr]).max()) ** t["p"] \
            if t["source"] == "heat" else s.inputs[t["source"]]      # the absolute reading
        col = np.empty(len(u))
        for r in range(len(s.runs)):
            m = s.run == r
            v = M.lag_linear(u[m], t["tau_s"], h) if t["tau_s"] > 0 else u[m]
            col[m] = v - v[0]
        cols.append(col)
    X = np.column_stack(cols)
    R = s.indicators()
    b = np.linalg.lstsq(np.column_stack([R, X])[tr], y[tr], rcond=None)[0]
    first = np.array([y[np.flatnonzero(s.run == r)[0]] for r in range(len(s.runs))])
    seen = np.array([np.any(tr & (s.run == r)) for r in range(len(s.runs))])
    zero = np.where(seen, b[:len(s.runs)], first)
    np.testing.assert_allclose(got, zero[s.run] + X @ b[len(s.runs):], atol=1e-6)


def test_the_static_regression_holding_the_room_is_one_model(held_room):
    """The static regression takes every temperature plain, the room among them: its fit on
    the rises spans the same columns (``b (T - T_room) + c T_room = b T + (c - b) T_room``),
    so it has no alternative and its interval is not widened (said so)."""
    from volerr.loop.drift import fit as core

    s = held_room.series
    y, te = s.channels["x"], s.test
    fold, rule = basis.folds(s)
    ch = core.Channel(s, y, s.indicators(), fold, rule)
    got = core._Alternative(s, False).predict(ch, {"choice": {"family": "static"}, "terms": []})
    assert got is None
    # the same columns: the static regression refitted on the rises predicts the same
    temps = ["T_room", "T_bearing", "T_casting"]
    col = {k: basis.series(s, k, 0.0) for k in temps}
    plain = np.column_stack([s.indicators()] + [col[k] for k in temps])
    rises = np.column_stack([s.indicators(), col["T_room"], col["T_bearing"] - col["T_room"],
                             col["T_casting"] - col["T_room"]])
    preds = [core.predict(s, D, core._fit(D, y, s.train), y) for D in (plain, rises)]
    np.testing.assert_allclose(preds[0], preds[1], atol=1e-8)
    iv = {"half_width_um": 1.0, "coverage_test": 0.5, "per_reading": np.ones(len(y)),
          "method": band.METHOD}
    band.widen_for_room(iv, y, preds[0], None, te, "absolute")
    assert iv["room_undecided"]["same_model"] and iv["room_undecided"]["difference_um"] == [0, 0]
    np.testing.assert_array_equal(iv["per_reading"], np.ones(len(y)))
    assert iv["method"] == band.METHOD
