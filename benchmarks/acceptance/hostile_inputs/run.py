"""Hostile inputs to every command: build the cases, run them, judge them (RULE.md).

Usage::

    .venv/bin/python benchmarks/acceptance/hostile_inputs/run.py [WORKDIR] [--only ID,ID]
        [--batch 1|2|1,2] [--md RESULTS_TABLE.md]

Every case is a shipped example (``volerr examples --out WORKDIR/ex``) with one mistake made
by a function below; the command runs in a subprocess (the ``volerr`` beside this Python, a
timeout of :data:`TIMEOUT_S`) and is judged by RULE.md: exit code, the lines on stderr, the
words of the likely mistake, the outputs (absent, or a sentinel unchanged, after a refusal).
Deterministic: no random numbers; the cases run in the order listed.  Prints one line per
case and writes ``WORKDIR/results.json`` and, with ``--md``, the Markdown table.
"""

from __future__ import annotations

import csv
import io
import json
import math
import re
import shutil
import subprocess
import sys
import time
from dataclasses import dataclass, field
from pathlib import Path

#: seconds a case may run (RULE.md defect 7)
TIMEOUT_S = 240
VOLERR = str(Path(sys.executable).with_name("volerr"))
SENTINEL = b"sentinel: this file must survive a refused run\n"


# -- CSV mutations ---------------------------------------------------------------------------
def read(path):
    """(comment lines, header, rows as lists of strings) of a CSV example."""
    lines = Path(path).read_text(encoding="utf-8").splitlines()
    comments = [x for x in lines if x.startswith("#")]
    body = [x for x in lines if x and not x.startswith("#")]
    rows = list(csv.reader(io.StringIO("\n".join(body))))
    return comments, rows[0], rows[1:]


def write(path, comments, header, rows, sep=",", newline="\n", bom=False):
    text = newline.join(comments + [sep.join(header)] + [sep.join(r) for r in rows]) + newline
    Path(path).parent.mkdir(parents=True, exist_ok=True)
    Path(path).write_bytes((b"\xef\xbb\xbf" if bom else b"") + text.encode("utf-8"))
    return str(path)


def fmt(x: float) -> str:
    return repr(float(x)) if math.isfinite(x) else str(x)


def scaled(src, dst, columns, factor):
    """``src`` with the numbers of ``columns`` (names, or a predicate on the name) x factor."""
    comments, header, rows = read(src)
    pick = columns if callable(columns) else (lambda h: h in columns)
    idx = [i for i, h in enumerate(header) if pick(h)]
    for r in rows:
        for i in idx:
            r[i] = fmt(float(r[i]) * factor)
    return write(dst, comments, header, rows)


def mapped(src, dst, fn):
    """``src`` with ``fn(header, rows) -> (header, rows)`` applied."""
    comments, header, rows = read(src)
    header, rows = fn(list(header), [list(r) for r in rows])
    return write(dst, comments, header, rows)


def swap(a, b):
    def fn(header, rows):
        i, j = header.index(a), header.index(b)
        for r in rows:
            r[i], r[j] = r[j], r[i]
        return header, rows
    return fn


def set_cell(row, col, value):
    def fn(header, rows):
        rows[row][header.index(col)] = value
        return header, rows
    return fn


def copy_dir(src, dst):
    shutil.rmtree(dst, ignore_errors=True)
    shutil.copytree(src, dst)
    return str(dst)


# -- the cases -------------------------------------------------------------------------------
@dataclass
class Case:
    id: str
    family: str
    mistake: str
    argv: list
    expect: str                      # refuse | accept | either
    words: tuple = ()                # any of them in the refusal line
    outputs: tuple = ()              # output paths (absent after a refusal)
    sentinel: str | None = None      # an output path made to exist before the run
    same_as: str | None = None       # accept: JSON equal to this case's
    result: dict = field(default_factory=dict)


UM = lambda h: h.endswith("_um")                                   # noqa: E731
URAD = lambda h: h.endswith("_urad")                               # noqa: E731
MM_WORDS = ("mm", "x1000", "1000")


def table_cases(w: Path, ex: Path) -> list:
    """``map MB1 --errors DIR``: error tables and constants with unit mistakes (RULE.md)."""
    cases = []

    def mb1(cid, mistake, make, expect, words, name="X.csv"):
        d = copy_dir(ex / "errors_MB1", w / cid / "errors")
        make(Path(d) / name)
        out = str(w / cid / "map.csv")
        cases.append(Case(cid, "error tables", mistake,
                          ["map", "MB1", "--errors", d, "--out", out, "--grid", "3"],
                          expect, words, (out,), sentinel=out))

    mb1("tab_um_x1e-3", "X.csv: every _um column in mm (x 1e-3)",
        lambda p: scaled(p, p, UM, 1e-3), "refuse", MM_WORDS)
    mb1("tab_um_x1e-6", "X.csv: every _um column x 1e-6 (0.000005 under _um)",
        lambda p: scaled(p, p, UM, 1e-6), "refuse", MM_WORDS + ("unit",))
    mb1("tab_urad_x1e-6", "X.csv: every _urad column in rad (x 1e-6)",
        lambda p: scaled(p, p, URAD, 1e-6), "refuse", ("rad",))
    mb1("tab_all_x1e-3", "X.csv: _um and _urad columns all x 1e-3 (mm, mrad)",
        lambda p: scaled(p, p, lambda h: UM(h) or URAD(h), 1e-3), "refuse", MM_WORDS + ("mrad",))

    def um_under_mm(p):
        comments, header, rows = read(p)
        header = [h.replace("EXX_um", "EXX_mm") for h in header]
        write(p, comments, header, rows)
    mb1("tab_um_under_mm", "X.csv: EXX in um headed EXX_mm", um_under_mm, "refuse", ("um",))
    mb1("tab_nm_under_um", "X.csv: every _um column in nm (x 1000)",
        lambda p: scaled(p, p, UM, 1e3), "refuse", ("nm",))

    def const(name, value, unit):
        def make(p):
            comments, header, rows = read(p)
            for r in rows:
                if r[0] == name:
                    r[1], r[2] = value, unit
            write(p, comments, header, rows)
        return make
    # EC0Y = 14.1 urad = 8.079e-4 deg = 2.908 arcsec
    mb1("const_deg_under_urad", "constants.csv: EC0Y 14.1 urad written as 0.000808 (deg) urad",
        const("EC0Y", "0.000808", "urad"), "either", ("deg",), name="constants.csv")
    mb1("const_arcsec_under_rad", "constants.csv: EC0Y 2.908 (arcsec) declared rad",
        const("EC0Y", "2.908", "rad"), "refuse", ("arcsec", "urad"), name="constants.csv")
    mb1("const_deg_under_rad", "constants.csv: EC0Y 0.000808 (deg) declared rad",
        const("EC0Y", "0.000808", "rad"), "either", ("deg",), name="constants.csv")
    mb1("const_arcsec_under_urad", "constants.csv: EC0Y 2.908 (arcsec) declared urad",
        const("EC0Y", "2.908", "urad"), "either", ("arcsec",), name="constants.csv")
    mb1("const_unit_deg", "constants.csv: EC0Y 0.000808 deg (a unit volerr may convert)",
        const("EC0Y", "0.000808", "deg"), "either", ("deg", "unit"), name="constants.csv")
    mb1("tab_pos_inches", "X.csv: positions in inches (0 .. 25.6 instead of 0 .. 650)",
        lambda p: scaled(p, p, ["X"], 1 / 25.4), "refuse", ("inch",))
    mb1("tab_dup_column", "X.csv: EYX_um twice",
        lambda p: mapped(p, p, lambda h, r: (h + ["EYX_um"], [x + [x[2]] for x in r])),
        "refuse", ("twice", "duplicate"))
    mb1("tab_nan", "X.csv: a NaN cell", lambda p: mapped(p, p, set_cell(3, "EXX_um", "nan")),
        "refuse", ("nan",))
    mb1("tab_inf", "X.csv: an inf cell", lambda p: mapped(p, p, set_cell(3, "EXX_um", "inf")),
        "refuse", ("inf",))
    mb1("tab_empty_cell", "X.csv: an empty cell", lambda p: mapped(p, p, set_cell(3, "EXX_um", "")),
        "refuse", ("empty",))
    mb1("tab_one_row", "X.csv: one row", lambda p: mapped(p, p, lambda h, r: (h, r[:1])),
        "refuse", ("row", "one", "two", "position"))
    mb1("tab_not_increasing", "X.csv: two rows swapped (positions not increasing)",
        lambda p: mapped(p, p, lambda h, r: (h, [r[0], r[2], r[1]] + r[3:])),
        "either", ("increas", "order", "sorted"))
    mb1("tab_constant_nonzero", "X.csv: EXX_um the same 3.0 at every position",
        lambda p: mapped(p, p, lambda h, r: (h, [x[:1] + ["3.0"] + x[2:] for x in r])),
        "either", ("constant",))

    # DMU50: rotary table positions in radians; tables of a five-axis machine in mm
    def dmu(cid, mistake, make, expect, words):
        d = copy_dir(ex / "dmu50" / "errors", w / cid / "errors")
        make(Path(d))
        out = str(w / cid / "tcp.png")
        cases.append(Case(cid, "error tables", mistake,
                          ["tcpmap", "DMU50", "--errors", d, "--point", "30", "20", "60",
                           "--plot", out], expect, words, (out,), sentinel=out))
    dmu("dmu_C_radians", "C.csv: positions in radians (0 .. 6.28 instead of 0 .. 360)",
        lambda d: scaled(d / "C.csv", d / "C.csv", ["C"], math.pi / 180), "refuse",
        ("radian", "rad"))
    dmu("dmu_C_um_x1e-3", "C.csv: every _um column in mm (x 1e-3)",
        lambda d: scaled(d / "C.csv", d / "C.csv", UM, 1e-3), "refuse", MM_WORDS)
    return cases


def drift_cases(w: Path, ex: Path) -> list:
    """``iso230-3 FILE --json F``: drift runs with unit mistakes."""
    src = ex / "drift_spindle.csv"
    cases = []

    def case(cid, mistake, make, expect, words, rows_kept=None):
        f = w / cid / "drift.csv"
        f.parent.mkdir(parents=True, exist_ok=True)
        make(f)
        out = str(w / cid / "drift.json")
        cases.append(Case(cid, "drift", mistake, ["iso230-3", str(f), "--json", out],
                          expect, words, (out,), sentinel=out))
    D = lambda h: h.startswith("d_") and h.endswith("_um")        # noqa: E731
    case("drift_mm_under_um", "channels in mm under _um (x 1e-3)",
         lambda f: scaled(src, f, D, 1e-3), "refuse", MM_WORDS)
    case("drift_nm_under_um", "channels in nm under _um (x 1000)",
         lambda f: scaled(src, f, D, 1e3), "refuse", ("nm",))
    case("drift_t_ms", "time in ms under t_s (x 1000)",
         lambda f: scaled(src, f, ["t_s"], 1e3), "either", ("ms", "millisecond"))
    case("drift_T_degF", "temperatures in degF under T_",
         lambda f: mapped(src, f, lambda h, r: (h, [[fmt(float(c) * 9 / 5 + 32)
                                                     if h[i].startswith("T_") else c
                                                     for i, c in enumerate(x)] for x in r])),
         "refuse", ("degF", "fahrenheit"))
    case("drift_T_kelvin", "temperatures in K under T_",
         lambda f: mapped(src, f, lambda h, r: (h, [[fmt(float(c) + 273.15)
                                                     if h[i].startswith("T_") else c
                                                     for i, c in enumerate(x)] for x in r])),
         "refuse", ("kelvin", " K"))
    case("drift_one_row", "one reading", lambda f: mapped(src, f, lambda h, r: (h, r[:1])),
         "refuse", ("row", "reading", "one"))
    case("drift_const_channel", "every channel constant (logger lost the sensors)",
         lambda f: mapped(src, f, lambda h, r: (h, [[("1.5" if D(h[i]) else c)
                                                     for i, c in enumerate(x)] for x in r])),
         "refuse", ("constant", "range", "zero"))
    case("drift_nan", "a NaN reading", lambda f: mapped(src, f, set_cell(5, "d_x1_um", "nan")),
         "either", ("nan",))
    case("drift_xy_swapped", "d_x1 and d_x2 columns swapped with T_spindle, T_motor",
         lambda f: mapped(src, f, swap("d_x1_um", "T_spindle")), "refuse",
         ("swapped", "temperature"))
    return cases


def option_cases(w: Path, ex: Path) -> list:
    """Option values: tolerances, MPE, radii, noise."""
    run = str(ex / "iso230_2_run_X.csv")
    cases = []

    def case(cid, mistake, argv, words, out):
        cases.append(Case(cid, "options", mistake, argv, "refuse", words, (out,), sentinel=out))
    for cid, tol, words in [("tol_zero", "A=0", ("positive", "zero", "> 0")),
                            ("tol_negative", "A=-5", ("positive", "negative")),
                            ("tol_mm_bare", "A=0.012", ("mm",)),
                            ("tol_12mm", "A=12 mm", ("mm", "beyond", "large")),
                            ("tol_E_mm_as_um", "E=25000", ("mm", "beyond", "large"))]:
        out = str(w / cid / "r.json")
        Path(out).parent.mkdir(parents=True, exist_ok=True)
        case(cid, f"iso230-2 --tolerance {tol}", ["iso230-2", run, "--json", out,
                                                   "--tolerance", tol], words, out)
    for cid, mpe, words in [("mpe_zero_K", "E0=2+L/0", ("K", "zero", "positive")),
                            ("mpe_negative_A", "E0=-2+L/300", ("positive", "negative")),
                            ("mpe_mm", "E0=0.002+L/300", ("mm", "below"))]:
        out = str(w / cid / "r.json")
        Path(out).parent.mkdir(parents=True, exist_ok=True)
        case(cid, f"iso10360 --mpe {mpe}", ["iso10360", "MB1", "--errors",
                                             str(ex / "errors_MB1"), "--mpe", mpe, "--json", out],
             words, out)
    for cid, r, words in [("probe_radius_zero", "0", ("positive", "radius")),
                          ("probe_radius_negative", "-25.006", ("positive", "negative")),
                          ("probe_radius_diameter", "50.012", ("diameter",)),
                          ("probe_radius_inches", "0.9845", ("inch",))]:
        out = str(w / cid / "map.csv")
        Path(out).parent.mkdir(parents=True, exist_ok=True)
        case(cid, f"probe-cal --sphere-radius {r}", ["probe-cal", str(ex / "probe_sphere.csv"),
                                                      "--sphere-radius", r, "--out", out],
             words, out)
    out = str(w / "noise_negative" / "u.json")
    Path(out).parent.mkdir(parents=True, exist_ok=True)
    case("noise_negative", "uncertainty --noise-um -1",
         ["uncertainty", "MH2", "--task", str(ex / "task_distance.csv"), "--evaluate",
          "distance", "--noise-um", "-1", "--samples", "200", "--json", out],
         ("positive", "negative", "noise"), out)
    out = str(w / "history_tol_zero" / "h.json")
    Path(out).parent.mkdir(parents=True, exist_ok=True)
    case("history_tol_zero", "history show --tolerance 'EX0C=0 um'",
         ["history", "show", "--db", str(w / "history_tol_zero" / "h.db"), "--machine", "M1",
          "--tolerance", "EX0C=0 um", "--json", out], ("positive", "zero", "tolerance"), out)
    return cases


def positioning_cases(w: Path, ex: Path) -> list:
    """``iso230-2 RUN --json F``: positioning runs."""
    src = ex / "iso230_2_run_X.csv"
    cases = []

    def case(cid, mistake, make, expect, words, same_as=None):
        f = w / cid / "run.csv"
        f.parent.mkdir(parents=True, exist_ok=True)
        make(f)
        out = str(w / cid / "r.json")
        cases.append(Case(cid, "positioning", mistake, ["iso230-2", str(f), "--json", out],
                          expect, words, (out,), sentinel=None if expect == "accept" else out,
                          same_as=same_as))
    case("run_plain", "the shipped run, unchanged", lambda f: shutil.copy(src, f), "accept", ())
    case("run_nm_under_um", "deviations in nm under _um (x 1000)",
         lambda f: scaled(src, f, ["deviation_um"], 1e3), "refuse", ("nm",))
    case("run_mm_under_um", "deviations in mm under _um (x 1e-3)",
         lambda f: scaled(src, f, ["deviation_um"], 1e-3), "refuse", MM_WORDS)
    case("run_columns_swapped", "target_mm and deviation_um values swapped",
         lambda f: mapped(src, f, swap("target_mm", "deviation_um")), "refuse",
         ("swapped", "column"))
    case("run_constant", "every deviation 2.5 (a constant column)",
         lambda f: mapped(src, f, lambda h, r: (h, [x[:3] + ["2.5"] for x in r])),
         "refuse", ("constant", "identical", "same"))
    case("run_one_row", "one reading", lambda f: mapped(src, f, lambda h, r: (h, r[:1])),
         "refuse", ("reading", "row", "one", "target", "cycle"))
    case("run_bom_crlf", "BOM and CRLF line ends (accept, same result)",
         lambda f: write(f, *read(src), newline="\r\n", bom=True), "accept", (),
         same_as="run_plain")
    case("run_semicolon_comma", "semicolons and decimal commas (European Excel)",
         lambda f: write(f, [], read(src)[1], [[c.replace(".", ",") for c in r]
                                              for r in read(src)[2]], sep=";"),
         "either", ("decimal comma", "comma"), same_as="run_plain")
    case("run_trailing_empty", "trailing empty columns (Excel)",
         lambda f: write(f, [], read(src)[1] + ["", ""], [r + ["", ""] for r in read(src)[2]]),
         "either", ("empty",), same_as="run_plain")
    case("run_units_row", "a units row under the header",
         lambda f: write(f, [], read(src)[1], [["mm", "", "", "um"]] + read(src)[2]),
         "either", ("not a number", "unit"), same_as="run_plain")
    case("run_dup_column", "deviation_um twice",
         lambda f: mapped(src, f, lambda h, r: (h + ["deviation_um"], [x + [x[3]] for x in r])),
         "refuse", ("twice", "duplicate"))

    def million(f):
        targets = [i * 1.0 for i in range(1000)]
        with open(f, "w") as fh:
            fh.write("target_mm,cycle,direction,deviation_um\n")
            for c in range(1, 501):
                for d in (1, -1):
                    for t in targets:
                        # a deterministic, plausible deviation: scale error + reversal + ripple
                        dev = 0.004 * t + 0.6 * d + 0.3 * math.sin(t * 0.37 + c * 1.3)
                        fh.write(f"{t:g},{c},{d:+d},{dev:.4f}\n")
    case("run_1e6_rows", "10^6 readings (1000 targets x 500 cycles x 2 directions)",
         million, "accept", ())
    return cases


def instrument_cases(w: Path, ex: Path) -> list:
    """Tracker, ballbar, kinds that are not what they say, deviations covariates."""
    cases = []

    def out_in(cid, name):
        p = w / cid / name
        p.parent.mkdir(parents=True, exist_ok=True)
        return str(p)

    f = mapped(ex / "tracker_example_X.csv", out_in("tracker_xy_swapped", "t.csv"),
               swap("x", "y"))
    o = out_in("tracker_xy_swapped", "tabs")
    cases.append(Case("tracker_xy_swapped", "instruments", "tracker x and y columns swapped",
                      ["identify", "MB1", "--axis", "X", f, "--errors-out", o], "refuse",
                      ("swapped", "x", "column"), (o,)))

    def flip_direction(h, r):
        i = h.index("direction")
        for x in r:
            x[i] = str(-int(float(x[i])))
        return h, r
    f = mapped(ex / "ballbar_example_XY.csv", out_in("ballbar_dir_flipped", "b.csv"),
               flip_direction)
    o = out_in("ballbar_dir_flipped", "b.json")
    cases.append(Case("ballbar_dir_flipped", "instruments",
                      "ballbar direction column sign flipped (ccw trace labelled cw)",
                      ["ballbar", "evaluate", f, "--json", o], "refuse",
                      ("direction", "sign", "clockwise"), (o,), sentinel=o))
    o = out_in("ballbar_as_interferometer", "c.json")
    cases.append(Case("ballbar_as_interferometer", "instruments",
                      "a ballbar trace given as interferometer:",
                      ["calibrate", "MB1", "interferometer:" + str(ex / "ballbar_example_XY.csv"),
                       "--json", o], "refuse", ("interferometer", "ballbar", "column"), (o,),
                      sentinel=o))
    o = out_in("deviations_to_probecal", "m.csv")
    cases.append(Case("deviations_to_probecal", "instruments",
                      "a deviations file given to probe-cal",
                      ["probe-cal", str(ex / "deviations_MB1.csv"), "--sphere-radius", "25.006",
                       "--out", o], "refuse", ("sphere", "deviations", "column", "probe"), (o,),
                      sentinel=o))
    o = out_in("drift_as_deviations", "l.json")
    cases.append(Case("drift_as_deviations", "instruments",
                      "a drift file given to calibrate as deviations:",
                      ["calibrate", "MB1", "deviations:" + str(ex / "drift_spindle.csv"),
                       "--json", o], "refuse", ("deviations", "drift", "column"), (o,),
                      sentinel=o))
    for cid, col, fn, words in [
            ("deviations_T_degF", "T_C", lambda v: v * 9 / 5 + 32, ("degF", "fahrenheit")),
            ("deviations_T_kelvin", "T_C", lambda v: v + 273.15, ("kelvin", " K")),
            ("deviations_t_ms", "t_s", lambda v: v * 1e3, ("ms", "millisecond"))]:
        f = mapped(ex / "deviations_MB1.csv", out_in(cid, "d.csv"),
                   lambda h, r, col=col, fn=fn: (h, [[fmt(fn(float(c))) if h[i] == col else c
                                                      for i, c in enumerate(x)] for x in r]))
        o = out_in(cid, "c.json")
        cases.append(Case(cid, "instruments", f"deviations: {col} mistaken",
                          ["calibrate", "MB1", f, "--json", o],
                          "either" if col == "t_s" else "refuse", words, (o,), sentinel=o))
    return cases


def batch2_cases(w: Path, ex: Path) -> list:
    """The amendment of RULE.md: spreadsheet exports of tables and drift files, files not of
    their kind, a reversal column in nm."""
    cases = []

    def out_in(cid, name):
        p = w / cid / name
        p.parent.mkdir(parents=True, exist_ok=True)
        return str(p)

    def map_case(cid, mistake, make, expect, words, same_as=None):
        d = copy_dir(ex / "errors_MB1", w / cid / "errors")
        make(Path(d) / "X.csv")
        out = out_in(cid, "map.csv")
        cases.append(Case(cid, "b2 exports", mistake,
                          ["map", "MB1", "--errors", d, "--out", out, "--grid", "3"],
                          expect, words, (out,), sentinel=None if expect == "accept" else out,
                          same_as=same_as))
    map_case("b2_tab_plain", "errors_MB1 unchanged", lambda p: None, "accept", ())
    map_case("b2_tab_bom_crlf", "X.csv with BOM and CRLF",
             lambda p: write(p, *read(p), newline="\r\n", bom=True), "accept", (),
             same_as="b2_tab_plain")
    map_case("b2_tab_semicolon_comma", "X.csv with semicolons and decimal commas",
             lambda p: (lambda c, h, r: write(p, c, h, [[x.replace(".", ",") for x in row]
                                                       for row in r], sep=";"))(*read(p)),
             "either", ("decimal comma", "comma"), same_as="b2_tab_plain")
    map_case("b2_tab_rv_nm", "an RV_X_um reversal column in nm (x 1000)",
             lambda p: mapped(p, p, lambda h, r: (h + ["RV_X_um"],
                                                  [x + [fmt(2000.0 + 10 * i)]
                                                   for i, x in enumerate(r)])),
             "refuse", ("nm",))

    src = ex / "drift_spindle.csv"

    def drift_case(cid, mistake, make, expect, words, same_as=None):
        f = Path(out_in(cid, "drift.csv"))
        make(f)
        out = out_in(cid, "drift.json")
        cases.append(Case(cid, "b2 exports", mistake, ["iso230-3", str(f), "--json", out],
                          expect, words, (out,), sentinel=None if expect == "accept" else out,
                          same_as=same_as))
    drift_case("b2_drift_plain", "drift_spindle.csv unchanged", lambda f: shutil.copy(src, f),
               "accept", ())
    drift_case("b2_drift_bom_crlf", "BOM and CRLF",
               lambda f: write(f, *read(src), newline="\r\n", bom=True), "accept", (),
               same_as="b2_drift_plain")
    drift_case("b2_drift_semicolon_comma", "semicolons and decimal commas",
               lambda f: (lambda c, h, r: write(f, c, h, [[x.replace(".", ",") for x in row]
                                                         for row in r], sep=";"))(*read(src)),
               "either", ("decimal comma", "comma"), same_as="b2_drift_plain")

    for cid, mistake, argv, words in [
            ("b2_sphere_as_ballbar", "a sphere file given as ballbar:",
             ["calibrate", "DMU50", "ballbar:" + str(ex / "sphere_example_DMU50.csv")],
             ("ballbar", "column", "dr_um", "sphere")),
            ("b2_run_as_deviations", "a positioning run given as deviations:",
             ["calibrate", "MB1", "deviations:" + str(ex / "iso230_2_run_X.csv")],
             ("deviations", "column", "interferometer")),
            ("b2_tracker_to_calibrate", "a tracker file given to calibrate",
             ["calibrate", "MB1", str(ex / "tracker_example_X.csv")],
             ("tracker", "identify", "column", "kind")),
            ("b2_ballbar_to_iso230_2", "a ballbar trace given to iso230-2",
             ["iso230-2", str(ex / "ballbar_example_XY.csv")],
             ("column", "target", "ballbar"))]:
        out = out_in(cid, "r.json")
        cases.append(Case(cid, "b2 kinds", mistake, argv + ["--json", out], "refuse", words,
                          (out,), sentinel=out))
    return cases


# -- running and judging ---------------------------------------------------------------------
def _json_values(path):
    """A JSON result without what differs between equal runs (file names, dates, versions)."""
    def clean(x):
        if isinstance(x, dict):
            return {k: clean(v) for k, v in x.items()
                    if k not in ("file", "files", "input", "inputs", "identification",
                                 "date", "created", "version", "volerr", "sha256")}
        if isinstance(x, list):
            return [clean(v) for v in x]
        if isinstance(x, str) and ("/" in x or "\\" in x):
            return "<path>"
        return x
    return clean(json.loads(Path(path).read_text()))


def run_case(c: Case, done: dict) -> dict:
    if c.sentinel:
        Path(c.sentinel).parent.mkdir(parents=True, exist_ok=True)
        Path(c.sentinel).write_bytes(SENTINEL)
    for o in c.outputs:
        if o != c.sentinel and Path(o).exists():
            shutil.rmtree(o) if Path(o).is_dir() else Path(o).unlink()
    t0 = time.perf_counter()
    try:
        p = subprocess.run([VOLERR] + c.argv, capture_output=True, text=True,
                           timeout=TIMEOUT_S, cwd=str(Path(c.outputs[0]).parent)
                           if c.outputs else None)
        code, err = p.returncode, p.stderr
    except subprocess.TimeoutExpired:
        code, err = None, ""
    seconds = time.perf_counter() - t0
    lines = [x for x in err.splitlines() if x.strip()]
    defects = judge(c, code, err, lines, done)
    return {"id": c.id, "family": c.family, "mistake": c.mistake, "expect": c.expect,
            "command": "volerr " + " ".join(Path(a).name if "/" in a else a for a in c.argv),
            "exit": code, "stderr": lines[-1] if lines else "", "n_lines": len(lines),
            "seconds": round(seconds, 1), "defects": defects,
            "verdict": "pass" if not defects else "DEFECT"}


def _written(c: Case) -> list:
    bad = []
    for o in c.outputs:
        if o == c.sentinel:
            if Path(o).read_bytes() != SENTINEL:
                bad.append(o)
        elif Path(o).exists():
            bad.append(o)
    return bad


def judge(c: Case, code, err, lines, done) -> list:
    d = []
    if code is None:
        return [f"7: over {TIMEOUT_S} s"]
    if "Traceback" in err:
        d.append("1: traceback")
    if code not in (0, 2):
        d.append(f"1: exit {code}")
    if re.search(r"\w*Warning\b", err):
        d.append("2: warning on stderr")
    if code == 2:
        if len(lines) != 1:
            d.append(f"2: {len(lines)} lines on stderr")
        if c.expect == "accept":
            d.append("4: a plausible input refused")
        # the words are looked for in the line without its paths and file names (a file
        # named tracker_example_X.csv does not name the mistake "tracker")
        said = re.sub(r"\S*(?:/|\.csv|\.json|\.png)\S*", "", lines[-1] if lines else "")
        if c.expect in ("refuse", "either") and c.words and not any(
                w.lower() in said.lower() for w in c.words):
            if c.expect == "refuse":
                d.append("5: the line names none of " + "/".join(c.words))
        if _written(c):
            d.append("6: output written despite exit 2")
    if code == 0:
        if c.expect == "refuse":
            d.append("3: exit 0 on impossible data")
        same = c.same_as and done.get(c.same_as)
        if same and c.outputs and str(c.outputs[0]).endswith(".json"):
            if _json_values(c.outputs[0]) != _json_values(same.outputs[0]):
                d.append(f"4: result differs from {c.same_as}")
        elif same and c.outputs and str(c.outputs[0]).endswith(".csv"):
            if Path(c.outputs[0]).read_bytes() != Path(same.outputs[0]).read_bytes():
                d.append(f"4: output differs from {c.same_as}'s (bytes)")
        for o in c.outputs:
            if not Path(o).exists() or (o == c.sentinel and Path(o).read_bytes() == SENTINEL):
                d.append(f"4: output {Path(o).name} not written")
    return d


def markdown(results) -> str:
    head = ("| case | mistake | command | expect | exit | stderr (last line) | s | verdict |\n"
            "| --- | --- | --- | --- | --- | --- | --- | --- |\n")
    rows = []
    for r in results:
        msg = r["stderr"].replace("|", "\\|")
        msg = msg if len(msg) < 220 else msg[:217] + "..."
        verdict = r["verdict"] + ("" if not r["defects"] else ": " + "; ".join(r["defects"]))
        rows.append(f"| {r['id']} | {r['mistake']} | `{r['command']}` | {r['expect']} | "
                    f"{r['exit']} | {msg} | {r['seconds']} | {verdict} |")
    return head + "\n".join(rows) + "\n"


def main(argv=None) -> int:
    argv = list(sys.argv[1:] if argv is None else argv)
    only = md = batch = None
    if "--batch" in argv:
        i = argv.index("--batch")
        batch = argv[i + 1]
        del argv[i:i + 2]
    if "--only" in argv:
        i = argv.index("--only")
        only = set(argv[i + 1].split(","))
        del argv[i:i + 2]
    if "--md" in argv:
        i = argv.index("--md")
        md = argv[i + 1]
        del argv[i:i + 2]
    if argv and argv[0] in ("-h", "--help"):
        print(__doc__)
        return 0
    w = Path(argv[0] if argv else "/tmp/volerr_hostile").resolve()
    ex = w / "ex"
    w.mkdir(parents=True, exist_ok=True)
    if not ex.is_dir():
        subprocess.run([VOLERR, "examples", "--out", str(ex)], check=True,
                       capture_output=True)
    batches = {"1": lambda: (table_cases(w, ex) + drift_cases(w, ex) + option_cases(w, ex)
                             + positioning_cases(w, ex) + instrument_cases(w, ex)),
               "2": lambda: batch2_cases(w, ex)}
    cases = [c for b in (batch.split(",") if batch else ("1", "2")) for c in batches[b]()]
    done, results = {}, []
    for c in cases:
        if only and c.id not in only and not (c.id == "run_plain"):
            continue
        r = run_case(c, done)
        done[c.id] = c
        results.append(r)
        print(f"{r['verdict']:6} {r['id']:28} exit={r['exit']} {r['seconds']:6.1f}s "
              f"{'; '.join(r['defects'])} | {r['stderr'][:160]}", flush=True)
    (w / "results.json").write_text(json.dumps(results, indent=1))
    if md:
        Path(md).write_text(markdown(results))
    n_bad = sum(r["verdict"] != "pass" for r in results)
    print(f"{len(results)} cases, {n_bad} with defects")
    return 0


if __name__ == "__main__":
    sys.exit(main())
