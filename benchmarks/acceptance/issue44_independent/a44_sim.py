"""Independent simulators for the issue-44 acceptance scenarios (written from the issue's
words and docs/formats.md only; nothing of the developers' simulators or tests read).

Units: time s, drift um, temperatures degC, speed rpm.  Sign convention: a drift reading is
the tool side relative to the workpiece side, positive as the (undirected, `?`) channel reads.

The lag is the first-order thermal response with the input held constant over each reading
interval (t_{k-1}, t_k] at its value x_k:  y_k = a y_{k-1} + (1 - a) x_k,  a = exp(-dt/tau),
started in equilibrium with the first reading (y_0 = x_0), as the loop's docs state.
"""
import csv
import json
import os
import subprocess
import sys
import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
# the repository: this folder is benchmarks/acceptance/issue44_independent
ROOT = os.path.dirname(os.path.dirname(os.path.dirname(HERE)))
VOLERR_CMD = [sys.executable, "-m", "volerr"]   # the CLI of the interpreter running this
OUT = os.environ.get("ACCEPT44_OUT", os.path.join(HERE, "out"))


def lag(x, tau_s, dt_s):
    """First-order lag of x (any unit) with time constant tau_s (s) at step dt_s (s)."""
    a = np.exp(-dt_s / tau_s)
    y = np.empty_like(x, dtype=float)
    y[0] = x[0]
    for k in range(1, len(x)):
        y[k] = a * y[k - 1] + (1.0 - a) * x[k]
    return y


def spindle_programme(rng, hours, dt_s, speeds=(0, 1500, 3000, 4500, 6000),
                      step_h=(0.5, 3.0)):
    """Spindle speed (rpm) as steps of random speeds and random durations, first step off."""
    n = int(round(hours * 3600 / dt_s)) + 1
    s = np.zeros(n)
    k = int(round(1800 / dt_s))  # 30 min off at the start
    last = 0
    while k < n:
        dur = rng.uniform(*step_h)
        m = max(1, int(round(dur * 3600 / dt_s)))
        choice = [v for v in speeds if v != last]
        last = choice[rng.integers(len(choice))]
        s[k:k + m] = last
        k += m
    return s


def write_drift(path, t_s, channels, inputs, extra_cols=None, header_lines=()):
    """Write a drift file: t_s, inputs (dict name -> array), channels (dict label -> um)."""
    cols = ["t_s"] + list(inputs) + ["d_%s_um" % c for c in channels]
    if extra_cols:
        cols = list(extra_cols) + cols
    with open(path, "w", newline="") as f:
        for h in header_lines:
            f.write(h + "\n")
        w = csv.writer(f)
        w.writerow(cols)
        n = len(t_s)
        for i in range(n):
            row = []
            if extra_cols:
                row += [extra_cols[c][i] for c in extra_cols]
            row.append("%g" % t_s[i])
            for name, v in inputs.items():
                row.append("%.0f" % v[i] if name == "S_rpm" else "%.2f" % v[i])
            for c, v in channels.items():
                row.append("%.4f" % v[i])
            w.writerow(row)


def run_loop(files, json_path, pred_path=None, extra=(), layout="DMU50", timeout=900):
    """Run `volerr loop` as a user would; return (rc, stdout, stderr, json dict or None)."""
    cmd = VOLERR_CMD + ["loop", layout] + ["drift:" + f for f in files] + ["--json", json_path]
    if pred_path:
        cmd += ["--predictions-out", pred_path]
    cmd += list(extra)
    p = subprocess.run(cmd, capture_output=True, text=True, timeout=timeout)
    data = None
    if p.returncode == 0 and os.path.exists(json_path):
        with open(json_path) as f:
            data = json.load(f)
    return p.returncode, p.stdout, p.stderr, data, cmd


def read_predictions(path):
    """Predictions CSV rows as a list of dicts (floats where numeric)."""
    rows = []
    with open(path) as f:
        for r in csv.DictReader(f):
            rows.append(r)
    return rows


def coverage(pred_rows, channel):
    """Share of held-out readings of `channel` whose measured value lies within after +- half_width."""
    inside = n = 0
    for r in pred_rows:
        if r["split"] != "test" or r["channel"] != channel:
            continue
        if "half_width_um" not in r or r["half_width_um"] in ("", None):
            return None
        n += 1
        if abs(float(r["measured_um"]) - float(r["after_um"])) <= float(r["half_width_um"]):
            inside += 1
    return inside / n if n else None


def floor_fit(cols_train, y_train, cols_test, y_test, run_train=None, run_test=None,
              zero_test=None):
    """The true model refitted on the training readings: least squares of y on the true
    columns with a free constant per training run; held-out readings predicted from the
    fitted coefficients plus the constant (one run) or, for held-out runs, the run's first
    reading (zero_test: index arrays of each held-out run).  Returns (rms, mae) um."""
    Xtr = np.column_stack(cols_train) if cols_train else np.zeros((len(y_train), 0))
    if run_train is None:
        run_train = np.zeros(len(y_train), int)
    runs = np.unique(run_train)
    D = np.column_stack([(run_train == r).astype(float) for r in runs])
    A = np.column_stack([Xtr, D])
    coef, *_ = np.linalg.lstsq(A, y_train, rcond=None)
    b = coef[:Xtr.shape[1]]
    Xte = np.column_stack(cols_test) if cols_test else np.zeros((len(y_test), 0))
    if run_test is None:
        pred = Xte @ b + coef[Xtr.shape[1]]
    else:
        pred = np.empty(len(y_test))
        for r in np.unique(run_test):
            m = run_test == r
            i0 = np.where(m)[0][0]
            pred[m] = y_test[i0] + (Xte[m] - Xte[i0]) @ b
    e = y_test - pred
    return float(np.sqrt(np.mean(e ** 2))), float(np.mean(np.abs(e)))


def summarise(data, pred_rows, channel):
    """Per-channel figures from the loop's JSON and predictions."""
    ch = data["channels"][channel]
    base = ch.get("baselines", {})
    out = {
        "family": ch.get("family"),
        "mae": ch.get("mae_after_um"), "rms": ch.get("rms_after_um"),
        "static_mae": base.get("static", {}).get("mae_um"),
        "static_rms": base.get("static", {}).get("rms_um"),
        "const_mae": base.get("constant", {}).get("mae_um"),
        "const_rms": base.get("constant", {}).get("rms_um"),
        "interval": ch.get("interval"),
        "coverage_json": (ch.get("interval") or {}).get("coverage_test"),
        "coverage_csv": coverage(pred_rows, channel) if pred_rows else None,
        "lag_terms_named": ch.get("lag_terms_named"),
        "verdict": ch.get("verdict"),
    }
    return out


def effects_of(data, channel):
    """The named effects acting on `channel`: list of (covariates, lag_s, lag_std, terms)."""
    res = []
    for e in data.get("effects", []):
        chans = e.get("channels") or [e.get("channel")]
        if channel in chans or e.get("channel") == channel:
            res.append(e)
    return res
