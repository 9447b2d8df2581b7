"""Acceptance of the NC programs `volerr plan` writes for layouts other than MB1, read by LinuxCNC's
rs274 and followed along the whole path (RULE.md, "Plan programs").

Usage: python plans.py [--work DIR]   (needs rs274 on PATH and volerr installed)

Per program: rs274 reads it without an error; every canonical move end and 10 samples on each
straight move / 16 on each arc lie inside the layout's declared travel (1e-6 mm / deg); the first
move is along Z alone to the top of the Z travel (docs/formats.md "NC programs": retract first);
the last move ends at the top of the Z travel; a rotary axis turns only with Z at the top of its
travel in a sphere / R-test program ("up to the clearance height, across with the rotary
axes turned there"); in a ballbar program the bar stays within 0.05 mm of its length along
every block (32 samples) between the program stop that mounts it and the one that removes it
(circles and ISO 10791-6 sweeps: "the bar at its length all the way", "within 0.05 mm").
"""

from __future__ import annotations

import argparse
import json
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np

from run import CANON, rs274, sample_arc, sample_line

VOLERR = [sys.executable, "-m", "volerr"]
PLANS = {
    "HH_BC-sphere": ["HH_BC", "--instrument", "sphere:tool=100", "--readings", "30"],
    "TT_AC-sphere": ["TT_AC", "--instrument", "sphere:tool=100", "--readings", "30"],
    "DMU50-sphere": ["DMU50", "--instrument", "sphere:tool=100", "--readings", "30"],
    "FB2-ballbar": ["FB2", "--instrument", "ballbar:lengths=150", "--readings", "60"],
    "HH_BC-ballbar": ["HH_BC", "--instrument", "ballbar:lengths=150", "--readings", "300"],
    "TT_AC-interferometer": ["TT_AC", "--instrument", "interferometer:optics=linear",
                             "--readings", "150", "--parameters",
                             "EXX@slope,EYY@slope,EZZ@slope"],
    "HH_BC-distances": ["HH_BC", "--instrument", "distances:stations=3", "--readings", "40",
                        "--parameters", "squareness,EXX@slope,EYY@slope,EZZ@slope"],
}
TOL = 1e-6


#: ISO 10791-6 sweep promise (docs/formats.md "ballbar sweep"): the bar within 0.05 mm of its
#: length along every block with the bar mounted; samples per block
BAR_TOL_MM = 0.05
BAR_SAMPLES = 32


def mounted_moves(canon: Path, moves: list) -> list[int]:
    """Indices of the moves between a program stop that mounts the bar and the next one that
    removes it (the 1st and 2nd PROGRAM_STOP, the 3rd and 4th, ...)."""
    stops, k, out = 0, 0, []
    for ln in canon.read_text().splitlines():
        if "PROGRAM_STOP()" in ln:
            stops += 1
        elif any(w in ln for w in ("STRAIGHT_TRAVERSE(", "STRAIGHT_FEED(", "ARC_FEED(")):
            if stops % 2 == 1:
                out.append(k)
            k += 1
    return out


def bar_deviation_mm(nc: Path, moves: list, model) -> float:
    """Largest abs(distance ball - pivot - length) (mm) along the moves with the bar mounted,
    the axes interpolated linearly block by block (no TCPM), the ball at the nominal tip with
    the plan's probe offset (columns Xp Yp Zp of the file beside the program)."""
    import csv
    from volerr.fiveaxis.compensate import ErrorModel
    with open(nc.with_suffix(".csv"), newline="") as fh:
        row = next(csv.DictReader(ln for ln in fh if not ln.startswith("#")))
    tool = tuple(float(row[c]) for c in ("Xp", "Yp", "Zp"))
    pivot = np.array([float(row[c]) for c in ("pivot_x", "pivot_y", "pivot_z")])
    length = float(row["length_mm"])
    em = ErrorModel(model, None, tool=tool)
    worst = 0.0
    for k in mounted_moves(nc.parent.parent / (nc.name + ".canon"), moves):
        _, s, e, arc = moves[k]
        pts = sample_arc(s, e, arc, BAR_SAMPLES) if arc is not None else \
            sample_line(s, e, BAR_SAMPLES)
        q = np.array([[p[a] for a in model.axes] for p in pts])
        ball = em.nominal_position(q)
        worst = max(worst, float(np.abs(np.linalg.norm(ball - pivot, axis=1) - length).max()))
    return worst


def check_program(nc: Path, travel: dict, work: Path, model=None) -> list[str]:
    """The failures of one program (empty: passes)."""
    rc, err, moves = rs274(nc, work / (nc.name + ".canon"))
    fails = []
    if rc != 0 or err:
        return [f"rs274: {err or rc}"]
    if not moves:
        return ["no motion"]
    ztop = travel["Z"][1]
    for k, (kind, s, e, arc) in enumerate(moves):
        pts = sample_arc(s, e, arc) if arc is not None else sample_line(s, e, 10)
        for a, (lo, hi) in travel.items():
            v = np.array([p[a] for p in pts])
            if k > 0 and (v.min() < lo - TOL or v.max() > hi + TOL):
                fails.append(f"move {k} ({kind}) {a} {v.min():.4f} .. {v.max():.4f} outside "
                             f"{lo} .. {hi}")
        turns = [a for a in travel if a not in ("X", "Y", "Z") and abs(e[a] - s[a]) > TOL]
        if nc.name.startswith("sphere") and k > 0 and turns and (abs(s["Z"] - ztop) > TOL or abs(e["Z"] - ztop) > TOL):
            fails.append(f"move {k}: {','.join(turns)} turns at Z {s['Z']:.3f} -> "
                         f"{e['Z']:.3f} (clearance {ztop})")
    _, s0, e0, _ = moves[0]
    if any(abs(e0[a] - s0[a]) > TOL for a in CANON if a != "Z") or abs(e0["Z"] - ztop) > TOL:
        fails.append(f"first move is not a retract along Z alone to {ztop}: {s0} -> {e0}")
    if abs(moves[-1][2]["Z"] - ztop) > TOL:
        fails.append(f"last move ends at Z {moves[-1][2]['Z']} (clearance {ztop})")
    if nc.name.startswith("ballbar") and model is not None:
        dev = bar_deviation_mm(nc, moves, model)
        fails.append(f"{'' if dev <= BAR_TOL_MM else 'FAIL: '}bar off its length by at most "
                     f"{dev:.4f} mm with the bar mounted")
    return fails


def main(argv=None) -> int:
    import volerr
    ap = argparse.ArgumentParser()
    ap.add_argument("--work", default="/tmp/nc_plans")
    a = ap.parse_args(argv)
    work = Path(a.work)
    results = []
    for name, args in PLANS.items():
        d = work / name
        shutil.rmtree(d, ignore_errors=True)
        d.mkdir(parents=True)
        p = subprocess.run([*VOLERR, "plan", *args, "--out", str(d / "plan"), "--dialect",
                            "linuxcnc"], capture_output=True, text=True, timeout=1200)
        if p.returncode != 0:
            results.append({"plan": name, "passed": False,
                            "detail": f"plan rc {p.returncode}: {p.stderr.strip()[-300:]}"})
            continue
        m = volerr.load(args[0])
        travel = {ax: tuple(map(float, m.travel[ax])) for ax in m.axes}
        for nc in sorted((d / "plan").glob("*.nc")):
            fails = check_program(nc, travel, d, m)
            passed = all(f.startswith("bar off") for f in fails)
            results.append({"plan": name, "program": nc.name, "passed": passed,
                            "lines": len(nc.read_text().splitlines()),
                            "detail": "; ".join(fails[:3]) + (f" (+{len(fails) - 3})"
                                                             if len(fails) > 3 else "")})
    for r in results:
        print(f"| {r['plan']} | {r.get('program', '-')} | {'PASS' if r['passed'] else 'FAIL'} "
              f"| {r['detail']} |")
    (work / "plans.json").write_text(json.dumps(results, indent=1))
    print(f"{sum(r['passed'] for r in results)} of {len(results)} programs pass")
    return 0


if __name__ == "__main__":
    sys.exit(main())
