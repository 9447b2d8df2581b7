"""``volerr ballbar simulate``: the readings of the layout's derived, first-order ballbar
observation model equal the first order of the independent exact chain
(tests/helpers/instrument_sim.py: the odd part in the errors, (f(+e) - f(-e)) / 2, which is
first order up to third-order terms) at the positions the program wrote -- on a CMM and on a
five-axis layout with a rotary axis swept.  The error directory holds linear component errors
(so that the tables' linear interpolation is exact) and constants."""

import csv

import numpy as np
import pytest

from helpers import instrument_sim as S
from instruments._common import in_process

CASES = {
    "MB1": (["--plane", "XY", "--radius", "100", "--centre", "450,290,200", "--tool",
             "0,0,-50"], {"EC0Y": 25.0, "EB0Z": -15.0}),
    "TT_AC": (["--plane", "XY", "--radius", "80", "--centre", "100,0,40", "--rotary",
               "A=0,C=0:360"], {"EC0Y": 20.0, "EX0C": 15.0, "EA0C": 25.0, "EY0A": 10.0,
                            "EB0C": -30.0}),
}
SLOPES = {"EXX": 0.012, "EYY": -0.008, "EZX": 0.005}     # um/mm, linear in their axis


def _write_errors(folder, machine, constants):
    folder.mkdir()
    for axis in ("X", "Y"):
        lo, hi = machine.travel[axis]
        q = np.linspace(lo, hi, 5)
        cols = {axis: q}
        for c in ("EX", "EY", "EZ"):
            cols[f"{c}{axis}_um"] = SLOPES.get(f"{c}{axis}", 0.0) * q
        S.write_csv(folder / f"{axis}.csv", cols)
    with open(folder / "constants.csv", "w") as fh:
        fh.write("name,value,unit\n")
        for k, v in constants.items():
            fh.write(f"{k},{v!r},{'urad' if S.is_angular(k) else 'um'}\n")


@pytest.mark.parametrize("layout", sorted(CASES))
def test_simulated_readings_equal_first_order_of_exact_chain(tmp_path, layout):
    opts, constants = CASES[layout]
    m = S.Machine(layout)
    _write_errors(tmp_path / "errors", m, constants)
    out = tmp_path / "trace.csv"
    r = in_process("ballbar", "simulate", layout, "--errors", tmp_path / "errors", *opts,
                   "--points", "48", "--noise-um", "0", "--direction", "both", "--out", out)
    assert r.returncode == 0, r.stderr[-3000:]
    with open(out) as fh:
        rows = list(csv.DictReader(fh))
    col = lambda k: np.array([float(x[k]) for x in rows])  # noqa: E731
    n = len(rows)
    assert n == 96
    pos = {a: col(a) for a in m.axes}
    probe = np.column_stack([col(k) if k in rows[0] else np.zeros(n) for k in ("Xp", "Yp",
                                                                              "Zp")])
    pivot = np.column_stack([col("pivot_x"), col("pivot_y"), col("pivot_z")])
    b = S.Block("ballbar", "trace.csv", pos, probe, np.full(n, "P1", dtype=object), 0.5,
                pivot=pivot, length=col("length_mm"))
    # the written geometry is consistent (radius = bar length, within rounding)
    t = m.tool_point(pos, None, probe)
    assert np.abs(np.linalg.norm(t - pivot, axis=1) - col("length_mm")).max() < 1e-6
    terms = [S.constant(k) for k in constants]
    terms += [S.Term(f"{c}lin", c, (lambda a: lambda blk: 1e-3 * blk.pos[a])(c[2]))
              for c in SLOPES]
    values = {**constants, **{f"{c}lin": v for c, v in SLOPES.items()}}
    plus = S.readings(m, b, terms, values)
    minus = S.readings(m, b, terms, {k: -v for k, v in values.items()})
    first = (plus - minus) / 2
    assert np.abs(first).max() > 1.0            # the errors do show
    # agreement to the resolution of the file (readings written to 1e-5 um)
    assert np.abs(col("dr_um") - first).max() < 1e-5, np.abs(col("dr_um") - first).max()


def test_python_api_reads_an_error_directory_with_the_command_options(tmp_path):
    # volerr.instruments.ballbar.simulated_trace(model, DIR, ...): the directory read as the
    # command's --errors options read it, the same readings as from the functions built first
    from volerr import InputError
    from volerr.instruments.ballbar import simulated_trace
    from volerr.machine.model import load
    from volerr.tables.functions import ErrorFunctions

    model = load("MB1")
    _write_errors(tmp_path / "errors", S.Machine("MB1"), CASES["MB1"][1])
    funcs = ErrorFunctions.from_dir(tmp_path / "errors", model, "cubic")
    kw = dict(tool=(0.0, 0.0, -50.0), points=24, noise_um=0.0)
    want = simulated_trace(model, funcs, "XY", 100.0, (450.0, 290.0, 200.0), **kw)
    got = simulated_trace(model, str(tmp_path / "errors"), "XY", 100.0, (450.0, 290.0, 200.0),
                          method="cubic", **kw)
    assert np.abs(want.columns["dr_um"]).max() > 1.0
    assert np.array_equal(got.columns["dr_um"], want.columns["dr_um"])
    with pytest.raises(InputError, match="needs method 'poly'"):   # degree is passed on
        simulated_trace(model, tmp_path / "errors", "XY", 100.0, (450.0, 290.0, 200.0),
                        degree=2, **kw)
