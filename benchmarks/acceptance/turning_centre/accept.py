#!/usr/bin/env python3
"""Acceptance harness for volerr's drift loop on a simulated turning centre (sim.py).

For each seed: simulate the campaign (sim.py), then for two splits
  * date: the first 2/3 of the days train, the later days are held out;
  * env:  constant-room runs train, varying-room runs are held out;
run `PY -m volerr loop TC_XZ drift:TRAIN... --holdout-files TEST... --json J --predictions-out P.csv`
and compute on the held-out readings the MAE per axis of
  loop       the loop's `after_um` (P.csv, split == test);
  static     multiple linear regression on all logged temperatures, fitted on the training runs
             (a free zero per run: within-run demeaned least squares);
  published  the same on four physically chosen sensors (spindle front bearing, headstock top,
             room air, bed front);
  constant   the run's first reading (the loop's `before`);
  floor      the simulator's noise-free truth: first reading + truth(t) - truth(t0).
Every model predicts a held-out run as its first measured reading plus the model of the inputs'
change since the first reading (the loop's convention: checked on P.csv, `before_um` of a held-out
run equals its first measured reading).  Plain python + numpy; nothing of volerr is imported.
"""
import argparse
import csv
import glob
import json
import os
import subprocess
import sys
import time

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
import sim  # noqa: E402

AXES = ("X", "Z")
TIE = 1e-3          # a loop MAE within 0.1 % of the best baseline is a tie (the loop chose it)


def read_drift(path):
    """Header lines, column names and a dict of columns (floats where numeric)."""
    with open(path) as f:
        lines = f.read().splitlines()
    head = [ln for ln in lines if ln.startswith("#")]
    rows = list(csv.reader([ln for ln in lines if ln and not ln.startswith("#")]))
    names = rows[0]
    cols = {}
    for i, n in enumerate(names):
        vals = [r[i] for r in rows[1:]]
        try:
            cols[n] = np.array(vals, dtype=float)
        except ValueError:
            cols[n] = np.array(vals)
    return head, names, cols


def decimate_campaign(src, dst, k):
    """Copy every k-th reading of every run (and truth) file from src to dst."""
    os.makedirs(dst, exist_ok=True)
    for path in sorted(glob.glob(os.path.join(src, "*.csv"))):
        name = os.path.basename(path)
        with open(path) as f:
            lines = f.read().splitlines()
        if name == "manifest.csv":
            keep = lines
        else:
            head = [ln for ln in lines if ln.startswith("#")]
            body = [ln for ln in lines if ln and not ln.startswith("#")]
            keep = head + body[:1] + body[1::k]
        with open(os.path.join(dst, name), "w") as f:
            f.write("\n".join(keep) + "\n")


def restrict_to_common(runs, dst):
    """The user's workaround for a day that lacks a sensor: drop that sensor from every run.

    Writes copies of the run files with only the columns every run has into dst and returns
    the runs with their paths (and columns) replaced.
    """
    os.makedirs(dst, exist_ok=True)
    common = [c for c in read_drift(runs[0]["path"])[1] if all(c in r["cols"] for r in runs)]
    out = []
    for r in runs:
        head, names, _ = read_drift(r["path"])
        with open(r["path"]) as f:
            rows = list(csv.reader([ln for ln in f.read().splitlines()
                                    if ln and not ln.startswith("#")]))
        keep = [names.index(c) for c in common]
        path = os.path.join(dst, os.path.basename(r["path"]))
        with open(path, "w", newline="") as f:
            f.write("\n".join(head) + "\n")
            w = csv.writer(f)
            for row in rows:
                w.writerow([row[k] for k in keep])
        out.append(dict(r, path=path, cols={c: r["cols"][c] for c in common}))
    return out


def load_campaign(folder):
    manifest = list(csv.DictReader(open(os.path.join(folder, "manifest.csv"))))
    runs = []
    for m in manifest:
        _, _, cols = read_drift(os.path.join(folder, m["file"]))
        _, _, truth = read_drift(os.path.join(folder, "truth" + m["file"][3:]))
        runs.append({"meta": m, "path": os.path.join(folder, m["file"]), "cols": cols,
                     "truth": truth})
    return runs


def fit_within(train, sensors, axis):
    """Least squares of d on the sensors with a free zero per run (within-run demeaned)."""
    xs, ys = [], []
    for r in train:
        x = np.column_stack([r["cols"][s] for s in sensors])
        y = r["cols"][f"d_{axis}_um"]
        xs.append(x - x.mean(axis=0))
        ys.append(y - y.mean())
    x, y = np.vstack(xs), np.concatenate(ys)
    coef, *_ = np.linalg.lstsq(x, y, rcond=None)
    return coef


def predict_from_first(r, sensors, coef, axis):
    x = np.column_stack([r["cols"][s] for s in sensors])
    return r["cols"][f"d_{axis}_um"][0] + (x - x[0]) @ coef


def own_models(train, test):
    """MAE per axis of static / published / constant / floor on the held-out runs."""
    common = [s for s in train[0]["cols"] if s.startswith("T_")
              and all(s in r["cols"] for r in train + test)]
    published = [s for s in sim.PUBLISHED if s in common]
    out = {}
    for name, sensors in (("static", common), ("published", published)):
        out[name] = {}
        for ax in AXES:
            coef = fit_within(train, sensors, ax)
            err = np.concatenate([predict_from_first(r, sensors, coef, ax) - r["cols"][f"d_{ax}_um"]
                                  for r in test])
            out[name][ax] = float(np.mean(np.abs(err)))
    out["constant"], out["floor"] = {}, {}
    for ax in AXES:
        meas = [r["cols"][f"d_{ax}_um"] for r in test]
        out["constant"][ax] = float(np.mean(np.abs(np.concatenate([m - m[0] for m in meas]))))
        fl = [r["cols"][f"d_{ax}_um"][0] + r["truth"][f"d_{ax}_um"] - r["truth"][f"d_{ax}_um"][0]
              - r["cols"][f"d_{ax}_um"] for r in test]
        out["floor"][ax] = float(np.mean(np.abs(np.concatenate(fl))))
    out["_sensors"] = {"static": len(common), "published": published}
    return out


def run_loop(python, train, test, work, tag):
    jpath = os.path.join(work, f"{tag}.json")
    ppath = os.path.join(work, f"{tag}_pred.csv")
    for p in (jpath, ppath):
        if os.path.exists(p):
            os.remove(p)
    cmd = [python, "-m", "volerr", "loop", "TC_XZ"] + ["drift:" + r["path"] for r in train]
    cmd += ["--holdout-files"] + [r["path"] for r in test]
    cmd += ["--json", jpath, "--predictions-out", ppath]
    t0 = time.time()
    proc = subprocess.run(cmd, capture_output=True, text=True)
    wall = time.time() - t0
    with open(os.path.join(work, f"{tag}.console.txt"), "w") as f:
        f.write(" ".join(cmd) + "\n\n" + proc.stdout + "\n--- stderr\n" + proc.stderr)
    if proc.returncode != 0:
        return {"error": (proc.stderr.strip().splitlines() or ["exit %d" % proc.returncode])[-1],
                "rc": proc.returncode, "wall_s": wall}
    return {"json": json.load(open(jpath)), "pred": ppath, "wall_s": wall}


def loop_mae(pred_path, test):
    """MAE per axis of after_um on split == test; check the zero convention of before_um."""
    _, _, p = read_drift(pred_path)
    test_paths = {os.path.abspath(r["path"]) for r in test}
    mask = p["split"] == "test"
    out, checks = {}, []
    for ax in AXES:
        m = mask & np.isin(p["channel"], [ax, f"d_{ax}", f"d_{ax}_um"])
        out[ax] = float(np.mean(np.abs(p["after_um"][m] - p["measured_um"][m])))
        out[f"n_{ax}"] = int(m.sum())
        for key in sorted(set(zip(p["file"][m], p["run"][m]))):
            k = m & (p["file"] == key[0]) & (p["run"] == key[1])
            t = p["t_s"][k]
            first = p["measured_um"][k][np.argmin(t)]
            checks.append(float(np.max(np.abs(p["before_um"][k] - first))))
    files = {os.path.abspath(f) for f in p["file"][mask]}
    out["zero_check_um"] = max(checks) if checks else float("nan")
    out["files_ok"] = files <= test_paths or len(files) == len(test_paths)
    return out


def effects_summary(js):
    lines = []
    for e in js.get("effects", []):
        terms = ", ".join(f"{t.get('basis')} = {t.get('value', 0):.3g}+-{2 * (t.get('std') or 0):.2g}"
                          for t in e.get("terms", []))
        lines.append(f"{','.join(e.get('channels', [e.get('channel', '?')]))}: {terms}")
    return lines


def held_out_text(ch):
    """The loop JSON's verdict on a channel's named effects (its "held_out": whether the lag
    model they come from holds on the held-out readings; absent: no effect named)."""
    if "held_out" not in ch:
        return "none named"
    h = ch["held_out"]
    if h is None:
        return "not judged"
    word = "confirmed" if h["confirmed"] else "NOT confirmed"
    return (f"{word} (lag {h['lag_model_mae_um']:.2f} vs {h['bound_um']:.2f} = 1.05 x "
            f"{h['baseline']} {h['baseline_mae_um']:.2f} + 0.2)")


def table(seed, split, ntrain, ntest, own, loop, fmt_md=True):
    rows = []
    head = f"seed {seed}, split {split}: {ntrain} training runs, {ntest} held-out runs"
    rows.append(f"### {head}\n")
    rows.append("| model | MAE X um | MAE Z um |")
    rows.append("| --- | ---: | ---: |")
    if "error" in loop:
        rows.append(f"| loop | refused: {loop['error']} | |")
    else:
        rows.append(f"| loop (after_um, P.csv) | {loop['mae']['X']:.2f} | {loop['mae']['Z']:.2f} |")
    for name in ("static", "published", "constant", "floor"):
        rows.append(f"| {name} | {own[name]['X']:.2f} | {own[name]['Z']:.2f} |")
    if "error" not in loop:
        ch = loop["json"].get("channels", {})
        js = {ax: ch.get(ax) or ch.get(f"d_{ax}") or {} for ax in AXES}
        rows.append("| loop JSON mae_after / mae_static | "
                    + " | ".join(f"{js[ax].get('mae_after_um', float('nan')):.2f} / "
                                 f"{js[ax].get('mae_static_um', float('nan')):.2f}" for ax in AXES) + " |")
        rows.append("| loop JSON family / lag model MAE / 95 % interval coverage | "
                    + " | ".join(f"{js[ax].get('family')} / "
                                 f"{(js[ax].get('lag_model') or {}).get('mae_um', float('nan')):.2f} / "
                                 f"{(js[ax].get('interval') or {}).get('coverage_test', float('nan')):.2f}"
                                 for ax in AXES) + " |")
        rows.append("| loop JSON named effects on the held-out readings | "
                    + " | ".join(held_out_text(js[ax]) for ax in AXES) + " |")
        verdict = []
        for ax in AXES:
            ref = min(own["static"][ax], own["published"][ax])
            ratio = loop["mae"][ax] / ref
            word = "PASS" if ratio <= 1.0 + TIE else "FAIL"
            verdict.append(f"{ax} {word} ({ratio:.3f}x best baseline, "
                           f"{loop['mae'][ax] / own['floor'][ax]:.2f}x floor)")
        rows.append("")
        rows.append("verdict (loop <= min(static, published), ties within 0.1 %): " + "; ".join(verdict))
        rows.append(f"loop wall {loop['wall_s']:.0f} s; zero convention check max |before - first "
                    f"reading| = {loop['mae']['zero_check_um']:.3g} um; held-out readings "
                    f"X {loop['mae']['n_X']}, Z {loop['mae']['n_Z']}; fold_rule "
                    f"{loop['json'].get('fold_rule')}; extrapolation "
                    f"{[e.get('input') for e in loop['json'].get('extrapolation', [])]}")
        eff = effects_summary(loop["json"])
        rows.append("effects: " + ("; ".join(eff) if eff else "none"))
    if loop.get("refused_first"):
        rows.append(f"first refused ({loop['refused_first']}); run again on the sensors every "
                    "day has (the user's workaround)")
    rows.append(f"published sensors: {', '.join(own['_sensors']['published'])}; static on "
                f"{own['_sensors']['static']} temperatures")
    rows.append("")
    return "\n".join(rows)


def record(seed, split, a, train, test, own, loop):
    """The figures of one table, for --json-out."""
    rec = {"seed": seed, "split": split, "hard": a.hard, "three_rooms": a.three_rooms,
           "decimate": a.decimate, "python": a.python, "n_train_runs": len(train),
           "n_test_runs": len(test), "mae_um": {k: own[k] for k in ("static", "published", "constant", "floor")}}
    if "error" in loop:
        rec["loop_error"] = loop["error"]
        return rec
    ch = loop["json"].get("channels", {})
    rec["mae_um"]["loop"] = {ax: loop["mae"][ax] for ax in AXES}
    rec["loop"] = {ax: {"family": (ch.get(ax) or {}).get("family"),
                        "coverage_95": ((ch.get(ax) or {}).get("interval") or {}).get("coverage_test"),
                        "lag_model_mae_um": ((ch.get(ax) or {}).get("lag_model") or {}).get("mae_um"),
                        "held_out": (ch.get(ax) or {}).get("held_out", "none named")}
                   for ax in AXES}
    rec["loop"].update({"wall_s": loop["wall_s"], "fold_rule": loop["json"].get("fold_rule"),
                        "refused_first": loop.get("refused_first"),
                        "effects": effects_summary(loop["json"])})
    rec["pass"] = {ax: loop["mae"][ax] <= (1 + TIE) * min(own["static"][ax], own["published"][ax])
                   for ax in AXES}
    return rec


def splits(runs):
    n_train = int(round(len(runs) * 2 / 3))
    date = (runs[:n_train], runs[n_train:])
    env = ([r for r in runs if r["meta"]["environment"] == "constant"],
           [r for r in runs if r["meta"]["environment"] != "constant"])
    return {"date": date, "env": env}


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seeds", type=int, nargs="+", default=[1])
    ap.add_argument("--python", default=sys.executable,
                    help="the interpreter whose volerr runs the loop")
    ap.add_argument("--decimate", type=int, default=2,
                    help="keep every K-th reading (default 2: 60-120 s, about 2 min a seed)")
    ap.add_argument("--runs", type=int, default=30)
    ap.add_argument("--hard", action="store_true", help="sim.py --hard")
    ap.add_argument("--three-rooms", action="store_true", help="sim.py --three-rooms")
    ap.add_argument("--splits", nargs="+", default=["date", "env"], choices=["date", "env"])
    ap.add_argument("--work", help="working folder (default /tmp/lathe_accept/<worktree of --python>)")
    ap.add_argument("--out", help="append the tables (markdown) to this file")
    ap.add_argument("--no-loop", action="store_true", help="baselines only (developing sim.py)")
    ap.add_argument("--json-out", help="write every table's figures as JSON (a list, one entry a split)")
    a = ap.parse_args(argv)
    if not a.work:   # one folder per tested tree: engineers running side by side do not collide
        parts = os.path.abspath(a.python).split(os.sep)
        name = parts[parts.index(".venv") - 1] if ".venv" in parts else "python"
        a.work = os.path.join("/tmp/lathe_accept", name)
    texts, records = [], []
    for seed in a.seeds:
        tag = f"s{seed}{'_hard' if a.hard else ''}{'_3rooms' if a.three_rooms else ''}_d{a.decimate}"
        work = os.path.join(a.work, tag)
        raw = os.path.join(work, "raw")
        sim_args = ["--out", raw, "--seed", str(seed), "--runs", str(a.runs)]
        sim.main(sim_args + (["--hard"] if a.hard else []) + (["--three-rooms"] if a.three_rooms else []))
        data = raw
        if a.decimate > 1:
            data = os.path.join(work, "data")
            decimate_campaign(raw, data, a.decimate)
        runs = load_campaign(data)
        for split, (train, test) in splits(runs).items():
            if split not in a.splits:
                continue
            own = own_models(train, test)
            loop = ({"error": "not run (--no-loop)"} if a.no_loop
                    else run_loop(a.python, train, test, work, split))
            if "differ" in loop.get("error", ""):
                # refused: a day lacks a sensor; retry as a user would, without that sensor
                refusal = loop["error"]
                both = restrict_to_common(train + test, os.path.join(work, f"common_{split}"))
                train, test = both[:len(train)], both[len(train):]
                own = own_models(train, test)
                loop = run_loop(a.python, train, test, work, split)
                loop["refused_first"] = refusal
            if "error" not in loop:
                loop["mae"] = loop_mae(loop["pred"], test)
            text = table(seed, split + (" (hard)" if a.hard else "") + (" (three rooms)" if a.three_rooms else "")
                         + (f" (decimate {a.decimate})" if a.decimate > 1 else ""),
                         len(train), len(test), own, loop)
            print(text, flush=True)
            texts.append(text)
            records.append(record(seed, split, a, train, test, own, loop))
            if a.out:
                with open(a.out, "a") as f:
                    f.write(text + "\n")
    if a.json_out:
        with open(a.json_out, "w") as f:
            json.dump(records, f, indent=1)
    return texts


if __name__ == "__main__":
    main()
