"""Hostile measured data: realistic user mistakes planted in valid example files.

Usage: python hostile.py EXAMPLES DEMO OUT [FILTER]
  EXAMPLES  folder written by ``volerr examples --out``
  DEMO      folder written by ``volerr demo --out`` (interim check files)
  OUT       work folder; writes OUT/results.json and OUT/table.md
Each case: one mutated copy of an example file, the shortest documented command, its
outputs in a fresh folder; rc, stderr and the files written are recorded (RULE.md).
"""
import csv
import io
import json
import math
import os
import shutil
import subprocess
import sys

VOLERR = os.path.join(os.path.dirname(sys.executable), "volerr")


def read(path):
    """Comment lines (kept verbatim), header and rows (lists of str) of a CSV."""
    comments, body = [], []
    with open(path) as f:
        for line in f:
            (comments if line.startswith("#") and not body else body).append(line)
    rows = list(csv.reader(io.StringIO("".join(body))))
    return comments, rows[0], [r for r in rows[1:] if r]


def write(path, comments, header, rows, sep=","):
    with open(path, "w", newline="") as f:
        f.writelines(comments)
        w = csv.writer(f, delimiter=sep, lineterminator="\n")
        w.writerow(header)
        w.writerows(rows)


def col(header, name):
    return header.index(name)


def scale(*names, k):
    def m(c, h, rows):
        for r in rows:
            for n in names:
                i = col(h, n)
                r[i] = repr(float(r[i]) * k)
        return c, h, rows
    return m


def shift(name, d, row=None):
    def m(c, h, rows):
        i = col(h, name)
        for j, r in enumerate(rows):
            if row is None or j == row:
                r[i] = repr(float(r[i]) + d)
        return c, h, rows
    return m


def swap(a, b):
    def m(c, h, rows):
        i, j = col(h, a), col(h, b)
        h = list(h)
        h[i], h[j] = h[j], h[i]
        return c, h, rows
    return m


def dup(c, h, rows):
    return c, h, rows + [list(r) for r in rows[:5]]


def dup_all(c, h, rows):
    return c, h, rows + [list(r) for r in rows]


def drop_row(j):
    def m(c, h, rows):
        return c, h, rows[:j] + rows[j + 1:]
    return m


def cell(name, value, row=3):
    def m(c, h, rows):
        rows[row][col(h, name)] = value
        return c, h, rows
    return m


def add_col(name, f):
    def m(c, h, rows):
        return c, h + [name], [r + [f(j)] for j, r in enumerate(rows)]
    return m


def set_col(name, f):
    def m(c, h, rows):
        i = col(h, name)
        for r in rows:
            r[i] = f(r[i])
        return c, h, rows
    return m


def header_line(old, new):
    def m(c, h, rows):
        return [line.replace(old, new) for line in c], h, rows
    return m


DECIMAL_COMMA = "decimal_comma"


def case(inst, mistake, src, mut, argv, expect, outs=("out",)):
    return dict(inst=inst, mistake=mistake, src=src, mut=mut, argv=argv, expect=expect,
                outs=outs)


def cases():
    rad = math.pi / 180
    T = "tracker_example_X.csv"
    ident = ["identify", "MB1", "--axis", "X", "{f}", "--out", "{o}/X.csv"]
    S = "sphere_example_DMU50.csv"
    cal_d = ["calibrate", "DMU50", "{f}", "--json", "{o}/c.json"]
    cal_m = ["calibrate", "MB1", "{f}", "--json", "{o}/c.json"]
    B = "ballbar_example_XY.csv"
    bbe = ["ballbar", "evaluate", "{f}", "--json", "{o}/b.json"]
    P = "ballplate_MB1.csv"
    cal_p = ["calibrate", "MB1", "{f}", "--parameters", "EXX,EYY,EZZ,EC0Y,EB0Z,EA0Z",
             "--degree", "1", "--json", "{o}/c.json"]
    M = "multilateration_DMU50.csv"
    Q = "probe_sphere.csv"
    pc = ["probe-cal", "{f}", "--sphere-radius", "25.006", "--out", "{o}/m.csv"]
    I = "iso230_2_run_X.csv"
    iso = ["iso230-2", "{f}", "--json", "{o}/i.json"]
    F = "ifm_X.csv"
    W = "week01.csv"
    chk = ["check", "DMU50", "--reference", "{ref}", "{f}", "--json", "{o}/k.json"]
    D = "deviations_MB1.csv"
    c = [
        case("tracker", "valid", T, None, ident, "possible"),
        case("tracker", "x,y,z in inches", T, scale("x", "y", "z", k=1 / 25.4), ident, "impossible"),
        case("tracker", "x,y,z in m", T, scale("x", "y", "z", k=1e-3), ident, "impossible"),
        case("tracker", "x,y,z in um", T, scale("x", "y", "z", k=1e3), ident, "impossible"),
        case("tracker", "x,y swapped", T, swap("x", "y"), ident, "impossible"),
        case("tracker", "x sign flipped", T, scale("x", k=-1), ident, "impossible"),
        case("tracker", "position in inches", T, scale("position", k=1 / 25.4), ident, "impossible"),
        case("tracker", "position sign flipped", T, scale("position", k=-1), ident, "impossible"),
        case("tracker", "one point 5 m off", T, shift("x", 5000, row=20), ident, "impossible"),
        case("tracker", "duplicated rows", T, dup, ident, "impossible"),
        case("tracker", "a row dropped", T, drop_row(10), ident, "impossible"),
        case("tracker", "NaN cell", T, cell("x", "NaN"), ident, "impossible"),
        case("tracker", "blank cell", T, cell("y", ""), ident, "impossible"),
        case("tracker", "decimal commas ;", T, DECIMAL_COMMA, ident, "impossible"),
        case("tracker", "file of Y given as X", "tracker_example_Y.csv", None, ident, "impossible"),
        case("sphere", "valid", S, None, cal_d, "possible"),
        case("sphere", "B,C in radians", S, scale("B", "C", k=rad), cal_d, "impossible"),
        case("sphere", "X,Y swapped", S, swap("X", "Y"), cal_d, "impossible"),
        case("sphere", "Zp sign flipped", S, scale("Zp", k=-1), cal_d, "impossible"),
        case("sphere", "sphere centre in inches", S,
             scale("sphere_x", "sphere_y", "sphere_z", k=1 / 25.4), cal_d, "impossible"),
        case("sphere", "dx,dy,dz in nm under _um", S, scale("dx_um", "dy_um", "dz_um", k=1e3),
             cal_d, "impossible"),
        case("sphere", "dx,dy,dz in mm under _um", S, scale("dx_um", "dy_um", "dz_um", k=1e-3),
             cal_d, "impossible"),
        case("sphere", "dx,dy swapped", S, swap("dx_um", "dy_um"), cal_d, "impossible"),
        case("sphere", "dx sign flipped", S, scale("dx_um", k=-1), cal_d, "impossible"),
        case("sphere", "all d signs flipped", S, scale("dx_um", "dy_um", "dz_um", k=-1), cal_d,
             "impossible"),
        case("sphere", "duplicated rows", S, dup, cal_d, "impossible"),
        case("sphere", "NaN cell", S, cell("dz_um", "NaN"), cal_d, "impossible"),
        case("sphere", "blank cell", S, cell("dz_um", ""), cal_d, "impossible"),
        case("sphere", "decimal commas ;", S, DECIMAL_COMMA, cal_d, "impossible"),
        case("sphere", "T_C in degF", S, add_col("T_C", lambda j: "%.2f" % (68 + 0.1 * j)), cal_d,
             "impossible"),
        case("sphere", "for MB1 layout", S, None, cal_m, "impossible"),
        case("ballbar", "valid", B, None, bbe, "possible"),
        case("ballbar", "length_mm in inches", B, scale("length_mm", k=1 / 25.4), bbe, "impossible"),
        case("ballbar", "length_mm = 100 (not the radius 150)", B, set_col("length_mm", lambda v: "100"),
             bbe, "impossible"),
        case("ballbar", "length_mm = 300 (diameter)", B, set_col("length_mm", lambda v: "300"), bbe,
             "impossible"),
        case("ballbar", "dr in nm under _um", B, scale("dr_um", k=1e3), bbe, "impossible"),
        case("ballbar", "dr in mm under _um", B, scale("dr_um", k=1e-3), bbe, "possible"),
        case("ballbar", "dr sign flipped", B, scale("dr_um", k=-1), bbe, "possible"),
        case("ballbar", "X,Y swapped", B, swap("X", "Y"), bbe, "impossible"),
        case("ballbar", "pivot in inches", B, scale("pivot_x", "pivot_y", "pivot_z", k=1 / 25.4),
             bbe, "impossible"),
        case("ballbar", "direction flipped", B, scale("direction", k=-1), bbe, "impossible"),
        case("ballbar", "duplicated rows (file pasted twice)", B, dup_all, bbe, "impossible"),
        case("ballbar", "NaN cell", B, cell("dr_um", "NaN"), bbe, "impossible"),
        case("ballbar", "blank cell", B, cell("dr_um", ""), bbe, "impossible"),
        case("ballbar", "decimal commas ;", B, DECIMAL_COMMA, bbe, "impossible"),
        case("ballbar", "calibrate: dr in nm", B, scale("dr_um", k=1e3), cal_m, "impossible"),
        case("ballbar", "calibrate: length in inches", B, scale("length_mm", k=1 / 25.4), cal_m,
             "impossible"),
        case("ballbar", "calibrate: circle 2 m outside travel", B,
             lambda c, h, r: shift("pivot_x", 2000)(*shift("X", 2000)(c, h, r)), cal_m, "impossible"),
        case("artifact", "valid", P, None, cal_p, "possible"),
        case("artifact", "x,y,z measured in um", P, scale("x_mm", "y_mm", "z_mm", k=1e3), cal_p,
             "impossible"),
        case("artifact", "u,v,w calibrated in inches", P, scale("u_mm", "v_mm", "w_mm", k=1 / 25.4),
             cal_p, "impossible"),
        case("artifact", "x,y measured swapped", P, swap("x_mm", "y_mm"), cal_p, "impossible"),
        case("artifact", "nominal/actual swapped (u<->x ...)", P,
             lambda c, h, r: swap("w_mm", "z_mm")(*swap("v_mm", "y_mm")(*swap("u_mm", "x_mm")(c, h, r))),
             cal_p, "possible"),
        case("artifact", "x sign flipped", P, scale("x_mm", k=-1), cal_p, "impossible"),
        case("artifact", "plate 2 m outside travel", P, shift("x_mm", 2000), cal_p, "impossible"),
        case("artifact", "duplicated rows", P, dup, cal_p, "impossible"),
        case("artifact", "NaN cell", P, cell("x_mm", "NaN"), cal_p, "impossible"),
        case("artifact", "decimal commas ;", P, DECIMAL_COMMA, cal_p, "impossible"),
        case("distances", "valid", M, None, cal_d, "possible"),
        case("distances", "dd in um under _mm", M, scale("dd_mm", k=1e3), cal_d, "impossible"),
        case("distances", "dd in inches", M, scale("dd_mm", k=1 / 25.4), cal_d, "impossible"),
        case("distances", "dd sign flipped", M, scale("dd_mm", k=-1), cal_d, "impossible"),
        case("distances", "B,C in radians", M, scale("B", "C", k=rad), cal_d, "impossible"),
        case("distances", "X,Y swapped", M, swap("X", "Y"), cal_d, "impossible"),
        case("distances", "Zp sign flipped", M, scale("Zp", k=-1), cal_d, "impossible"),
        case("distances", "X 3 m outside travel", M, shift("X", 3000, row=7), cal_d, "impossible"),
        case("distances", "duplicated rows", M, dup, cal_d, "impossible"),
        case("distances", "NaN cell", M, cell("dd_mm", "NaN"), cal_d, "impossible"),
        case("probe-sphere", "valid", Q, None, pc, "possible"),
        case("probe-sphere", "x,y,z in inches", Q, scale("x", "y", "z", k=1 / 25.4), pc, "impossible"),
        case("probe-sphere", "x,y swapped", Q, swap("x", "y"), pc, "possible"),
        case("probe-sphere", "z sign flipped", Q, scale("z", k=-1), pc, "possible"),
        case("probe-sphere", "duplicated rows", Q, dup, pc, "impossible"),
        case("probe-sphere", "NaN cell", Q, cell("x", "NaN"), pc, "impossible"),
        case("probe-sphere", "decimal commas ;", Q, DECIMAL_COMMA, pc, "impossible"),
        case("probe-sphere", "--sphere-radius the diameter", Q, None,
             ["probe-cal", "{f}", "--sphere-radius", "50.012", "--out", "{o}/m.csv"], "impossible"),
        case("probe-sphere", "--sphere-radius in inches", Q, None,
             ["probe-cal", "{f}", "--sphere-radius", "0.98449", "--out", "{o}/m.csv"], "impossible"),
        case("iso230-2", "valid", I, None, iso, "possible"),
        case("iso230-2", "deviation in nm under _um", I, scale("deviation_um", k=1e3), iso, "impossible"),
        case("iso230-2", "deviation in mm under _um", I, scale("deviation_um", k=1e-3), iso, "impossible"),
        case("iso230-2", "deviation sign flipped", I, scale("deviation_um", k=-1), iso, "possible"),
        case("iso230-2", "target/deviation swapped", I, swap("target_mm", "deviation_um"), iso,
             "impossible"),
        case("iso230-2", "target in inches", I, scale("target_mm", k=1 / 25.4), iso, "possible"),
        case("iso230-2", "direction flipped", I, scale("direction", k=-1), iso, "possible"),
        case("iso230-2", "duplicated rows", I, dup, iso, "impossible"),
        case("iso230-2", "a row dropped", I, drop_row(7), iso, "impossible"),
        case("iso230-2", "NaN cell", I, cell("deviation_um", "NaN"), iso, "impossible"),
        case("iso230-2", "blank cell", I, cell("deviation_um", ""), iso, "impossible"),
        case("iso230-2", "decimal commas ;", I, DECIMAL_COMMA, iso, "impossible"),
        case("iso230-2", "T_C in degF", I, add_col("T_C", lambda j: "68.4"),
             iso[:2] + ["--cte-ppm-per-K", "11.5"] + iso[2:], "impossible"),
        case("iso230-2", "T_C in K", I, add_col("T_C", lambda j: "293.5"),
             iso[:2] + ["--cte-ppm-per-K", "11.5"] + iso[2:], "impossible"),
        case("iso230-2", "--material-temp-C in K", I, None,
             iso[:2] + ["--cte-ppm-per-K", "11.5", "--material-temp-C", "293.4"] + iso[2:], "impossible"),
        case("iso230-2", "time column in ms", I, add_col("t_s", lambda j: "%d" % (j * 30000)), iso,
             "possible"),
        case("interferometer", "valid", F, None, cal_m, "possible"),
        case("interferometer", "targets outside travel (+2000)", F, shift("target_mm", 2000), cal_m,
             "impossible"),
        case("interferometer", "targets in inches", F, scale("target_mm", k=1 / 25.4), cal_m, "possible"),
        case("interferometer", "axis Y (travel 575) for a 0..800 run", F, header_line("axis: X", "axis: Y"),
             cal_m, "impossible"),
        case("interferometer", "at: Y=3000 outside travel", F,
             lambda c, h, r: (c + ["# at: Y=3000, Z=200\n"], h, r), cal_m, "impossible"),
        case("interferometer", "deviation in nm", F, scale("deviation_um", k=1e3), cal_m, "impossible"),
        case("interferometer", "duplicated rows", F, dup, cal_m, "impossible"),
        case("check", "valid", W, None, chk, "possible"),
        case("check", "B,C in radians", W, scale("B", "C", k=rad), chk, "impossible"),
        case("check", "dx in nm", W, scale("dx_um", "dy_um", "dz_um", k=1e3), chk, "impossible"),
        case("check", "X,Y swapped", W, swap("X", "Y"), chk, "impossible"),
        case("check", "date in the future", W, None, chk + ["--date", "2031-01-01"], "impossible"),
        case("deviations", "valid", D, None, cal_m, "possible"),
        case("deviations", "dx in nm", D, scale("dx_um", "dy_um", "dz_um", k=1e3), cal_m, "impossible"),
        case("deviations", "X,Y swapped", D, swap("X", "Y"), cal_m, "impossible"),
        case("deviations", "X 2 m outside travel", D, shift("X", 2000, row=4), cal_m, "impossible"),
        case("deviations", "Zp sign flipped", D, scale("Zp", k=-1), cal_m, "impossible"),
        case("deviations", "T_C in degF", D, set_col("T_C", lambda v: repr(float(v) * 1.8 + 32)), cal_m,
             "possible"),
        case("deviations", "duplicated rows", D, dup, cal_m, "impossible"),
    ]
    H = "calibrate_rotary.json"
    hadd = ["history", "add", "--db", "{o}/h.sqlite", "--machine", "M1", "{f}"]
    c += [
        case("deviations", "t_s in ms", D, scale("t_s", k=1e3), cal_m, "impossible"),
        case("deviations", "T_C in K", D, set_col("T_C", lambda v: repr(float(v) + 273.15)), cal_m,
             "impossible"),
        case("deviations", "loop: T_C in degF", D, set_col("T_C", lambda v: repr(float(v) * 1.8 + 32)),
             ["loop", "MB1", "{f}", "--json", "{o}/l.json"], "impossible"),
        case("sphere", "t_s in ms", S, add_col("t_s", lambda j: "%d" % (j * 60000)), cal_d,
             "impossible"),
        case("sphere", "Zp in inches", S, scale("Zp", k=1 / 25.4), cal_d, "impossible"),
        case("distances", "Zp in inches", M, scale("Zp", k=1 / 25.4), cal_d, "impossible"),
        case("ballbar", "calibrate: T_C in degF", B, add_col("T_C", lambda j: "%.2f" % (68 + 0.01 * j)),
             cal_m, "impossible"),
        case("iso230-2", "direction words swapped (+1 <-> -1)", I,
             set_col("direction", lambda v: "-1" if v.strip() == "+1" else "+1"), iso, "possible"),
        case("check", "a row dropped (15 declared)", W, drop_row(4), chk, "possible"),
        case("history", "valid calibrate JSON", H, None, hadd, "possible"),
        case("history", "date in the future", H, None, hadd + ["--date", "2031-01-01"], "impossible"),
        case("history", "date not a date (07/12/2026)", H, None, hadd + ["--date", "07/12/2026"],
             "impossible"),
    ]
    return c


def decimal_comma(src, dst):
    comments, h, rows = read(src)
    rows = [[v.replace(".", ",") for v in r] for r in rows]
    write(dst, comments, h, rows, sep=";")


def run_case(k, cs, examples, demo, out):
    wd = os.path.join(out, "c%03d" % k)
    shutil.rmtree(wd, ignore_errors=True)
    os.makedirs(os.path.join(wd, "out"))
    src = os.path.join(examples, cs["src"])
    if cs["src"].startswith("week"):
        src = os.path.join(demo, "check_plan", cs["src"])
    elif cs["src"].endswith(".json"):
        src = os.path.join(demo, cs["src"])
    f = os.path.join(wd, os.path.basename(cs["src"]))
    if cs["mut"] is None:
        shutil.copy(src, f)
        if f.endswith(".json"):    # the instrument files a result names, beside it
            for name in os.listdir(os.path.dirname(src)):
                if name.startswith("sphere_DMU50"):
                    shutil.copy(os.path.join(os.path.dirname(src), name), wd)
    elif cs["mut"] == DECIMAL_COMMA:
        decimal_comma(src, f)
    else:
        write(f, *cs["mut"](*read(src)))
    argv = [a.format(f=f, o=os.path.join(wd, "out"), ref=os.path.join(demo, "check_reference.json"))
            for a in cs["argv"]]
    p = subprocess.run([VOLERR] + argv, capture_output=True, text=True, cwd=wd)
    written = sorted(os.listdir(os.path.join(wd, "out")))
    lines = [line for line in p.stderr.splitlines() if line.strip()]
    return dict(inst=cs["inst"], mistake=cs["mistake"], expect=cs["expect"], rc=p.returncode,
                stderr=lines, written=written, argv=["volerr"] + [os.path.basename(a) if os.sep in a
                                                                  else a for a in argv],
                verdict=verdict(cs["expect"], p.returncode, lines, written, p.stderr))


def verdict(expect, rc, lines, written, err):
    if "Traceback" in err or rc not in (0, 2):
        return "BAD"
    if rc == 2 and written:
        return "BAD"
    if expect == "impossible":
        if rc == 0:
            return "MISS"
        return "OK?" if len(lines) == 1 else "BAD"
    return "OK" if rc == 0 else "REFUSED"


def main():
    examples, demo, out = [os.path.abspath(a) for a in sys.argv[1:4]]
    filt = sys.argv[4] if len(sys.argv) > 4 else ""
    res = []
    for k, cs in enumerate(cases()):
        if filt.startswith("from:"):
            if k < int(filt[5:]):
                continue
        elif filt and filt not in cs["inst"]:
            continue
        r = run_case(k, cs, examples, demo, out)
        r["case"] = k
        res.append(r)
        print("%3d %-14s %-40s rc=%d %-7s %s" % (k, r["inst"], r["mistake"], r["rc"], r["verdict"],
                                                 (r["stderr"][-1] if r["stderr"] else "")[:150]),
              flush=True)
    with open(os.path.join(out, "results%s.json" % ("_" + filt if filt else "")), "w") as f:
        json.dump(res, f, indent=1)


if __name__ == "__main__":
    main()
