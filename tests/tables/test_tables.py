"""Error tables (CSV) and error functions: round trips, interpolation, fitting, strict input."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings, strategies as st

import volerr
from volerr.errors import InputError
from volerr.tables.functions import ErrorFunctions, choose_degree, make_function
from volerr.tables.table import (ErrorTable, read_constants, read_constants_full, read_error_table,
                                 write_constants, write_error_table)

MB1 = volerr.load("MB1")

finite = st.floats(min_value=-1e3, max_value=1e3, allow_nan=False, allow_infinity=False)


@settings(max_examples=40, deadline=None)
@given(n=st.integers(2, 12), data=st.data(), std=st.booleans())
def test_table_round_trip(tmp_path_factory, n, data, std):
    steps = data.draw(st.lists(st.floats(0.01, 100), min_size=n - 1, max_size=n - 1))
    pos = data.draw(finite) + np.concatenate([[0.0], np.cumsum(steps)])
    vals = {name: np.array(data.draw(st.lists(finite, min_size=n, max_size=n))) * scale
            for name, scale in (("EXX", 1e-3), ("EZX", 1.0), ("EBX", 1e-6), ("ECX", 1e-3))}
    sd = {"EXX": np.abs(vals["EXX"])} if std else {}
    t = ErrorTable("X", pos, vals, std=sd)
    path = tmp_path_factory.mktemp("rt") / "X.csv"
    write_error_table(path, t)
    back = read_error_table(path)
    assert back.axis == "X"
    np.testing.assert_allclose(back.positions, pos, rtol=1e-11, atol=1e-9)
    assert set(back.values) == set(vals)
    for k in vals:
        np.testing.assert_allclose(back.values[k], vals[k], rtol=1e-11, atol=1e-15)
    assert set(back.std) == set(sd)


def _write(path, text):
    path.write_text(text)
    return path


def test_unit_conversion_on_read(tmp_path):
    p = _write(tmp_path / "Y.csv", "Y,EXY_um,EYY_mm,EAY_urad,EBY_rad,EXY_std_um,EYY_mm_std,EAY_u95_urad\n"
                                   "0,1,0.002,3,4e-6,0.5,0.001,2\n10,2,0.004,6,8e-6,0.5,0.001,2\n")
    t = read_error_table(p)
    assert t.values["EXY"][0] == pytest.approx(1e-3)
    assert t.values["EYY"][1] == pytest.approx(0.004)
    assert t.values["EAY"][0] == pytest.approx(3e-6)
    assert t.values["EBY"][1] == pytest.approx(8e-6)
    assert t.std["EXY"][0] == pytest.approx(5e-4)
    assert t.std["EYY"][0] == pytest.approx(1e-3)
    assert t.u95["EAY"][0] == pytest.approx(2e-6)


def test_constants_round_trip(tmp_path):
    vals = {"EC0Y": 14.1e-6, "EB0Z": -56.4e-6, "EX0C": 0.012}
    write_constants(tmp_path / "c.csv", vals, std={"EC0Y": 1e-6})
    back, std, _ = read_constants_full(tmp_path / "c.csv")
    assert back == pytest.approx(vals)
    assert std == pytest.approx({"EC0Y": 1e-6})
    p = _write(tmp_path / "d.csv", "name,value,unit\nEA0Z,-0.032,mm\n")
    with pytest.raises(InputError, match="wrong units"):
        read_constants(p)
    p = _write(tmp_path / "e.csv", "name,value,unit\nEA0Z,-32,urad\n")
    assert read_constants(p) == pytest.approx({"EA0Z": -32e-6})


@pytest.mark.parametrize("text,match", [
    ("X,EXX\n0,1\n1,2\n", "unit suffix"),
    ("X,EXX_nm\n0,1\n1,2\n", "wrong units"),
    ("X,EAX_um\n0,1\n1,2\n", "wrong units"),
    ("X,EXY_um\n0,1\n1,2\n", "not a component error of axis X"),
    ("X,EXX_um\n0,nan\n1,2\n", "NaN"),
    ("X,EXX_um\n0,abc\n1,2\n", "not a number"),
    ("X,EXX_um\n0,\n1,2\n", "empty value"),
    ("X,EXX_um\n0,1\n0,2\n", "duplicate position"),
    ("X,EXX_um\n1,1\n0,2\n", "decreasing"),
    ("Y,EXY_um\n0,1\n1,2\n", "header mismatch"),
    ("X,EXX_um\n0,1,3\n1,2\n", "fields"),
    ("X,EXX_um,EXX_um\n0,1,1\n1,2,2\n", "duplicate column"),
    ("X,EXX_um\n0,1\n", "at least two"),
    ("", "empty file"),
    ("X,EXX_std_um\n0,1\n1,2\n", "without"),
])
def test_bad_tables(tmp_path, text, match):
    p = _write(tmp_path / "X.csv", text)
    with pytest.raises(InputError, match=match):
        read_error_table(p, axis="X")


def _funcs(tmp_path, method="linear", **kw):
    x = np.linspace(0, 900, 10)
    t = ErrorTable("X", x, {"EXX": 1e-6 * (x - 300) ** 2 / 100, "ECX": 1e-8 * x})
    return ErrorFunctions({"X": t}, {"EC0Y": 14.1e-6}, MB1, method=method, **kw), t


@pytest.mark.parametrize("method", ["linear", "cubic"])
def test_interpolation_exact_at_nodes(tmp_path, method):
    f, t = _funcs(tmp_path, method)
    pos = {"X": t.positions, "Y": 0.0 * t.positions, "Z": 0.0 * t.positions}
    out = f(pos)
    np.testing.assert_allclose(out["EXX"], t.values["EXX"], rtol=1e-12, atol=1e-15)
    np.testing.assert_allclose(out["EC0Y"], 14.1e-6)
    mid = {"X": [50.0], "Y": [0.0], "Z": [0.0]}
    if method == "linear":
        assert f(mid)["EXX"][0] == pytest.approx(0.5 * (t.values["EXX"][0] + t.values["EXX"][1]))
    else:  # cubic spline reproduces the quadratic
        assert f(mid)["EXX"][0] == pytest.approx(1e-6 * (50 - 300) ** 2 / 100, rel=1e-9)


@settings(max_examples=60, deadline=None)
@given(data=st.data(), even=st.booleans())
def test_linear_functions_equal_numpy_interp_and_the_end_lines(data, even):
    """All parameters of an axis are interpolated together (one bracket search): inside the
    range the values are numpy.interp's bit for bit, outside (extrapolate) the end segments
    extended, for evenly and unevenly spaced tables."""
    n = data.draw(st.integers(2, 15))
    x0 = data.draw(st.floats(-500, 500))
    if even:
        x = x0 + data.draw(st.floats(0.1, 100)) * np.arange(n)
    else:
        x = x0 + np.concatenate([[0.0], np.cumsum(data.draw(
            st.lists(st.floats(0.01, 100), min_size=n - 1, max_size=n - 1)))])
    vals = {k: np.array(data.draw(st.lists(finite, min_size=n, max_size=n))) * 1e-6
            for k in ("EXX", "EYX", "ECX")}
    sd = {"EXX": np.abs(vals["EXX"]) + 1e-7, "ECX": np.abs(vals["ECX"])}
    f = ErrorFunctions({"X": ErrorTable("X", x, vals, std=sd)}, None, MB1, extrapolate=True)
    span = x[-1] - x[0]
    q = np.concatenate([x, data.draw(st.lists(st.floats(x[0] - span, x[-1] + span),
                                              min_size=1, max_size=30))])
    out = f({"X": q, "Y": 0.0 * q, "Z": 0.0 * q})
    sig = f.sigmas({"X": q, "Y": 0.0 * q, "Z": 0.0 * q})
    assert set(sig) == set(sd)
    for k, y in sd.items():     # standard deviations: clamped at the ends, as numpy.interp
        assert np.array_equal(sig[k], np.interp(q, x, y))
    inside = (q >= x[0]) & (q <= x[-1])
    for k, y in vals.items():
        assert np.array_equal(out[k][inside], np.interp(q[inside], x, y))
        lo, hi = q < x[0], q > x[-1]
        np.testing.assert_allclose(out[k][lo], y[0] + (q[lo] - x[0]) * (y[1] - y[0]) / (x[1] - x[0]),
                                   rtol=1e-12, atol=1e-18)
        np.testing.assert_allclose(out[k][hi], y[-1] + (q[hi] - x[-1]) * (y[-1] - y[-2])
                                   / (x[-1] - x[-2]), rtol=1e-12, atol=1e-18)


def test_extrapolation_refused_unless_asked(tmp_path):
    f, _ = _funcs(tmp_path)
    with pytest.raises(InputError, match=r"X = 950 mm is outside the measured range 0 \.\. 900"):
        f({"X": [950.0], "Y": [0.0], "Z": [0.0]})
    g, t = _funcs(tmp_path, extrapolate=True)
    v = g({"X": [1000.0], "Y": [0.0], "Z": [0.0]})["ECX"][0]
    assert v == pytest.approx(1e-8 * 1000)  # linear function extended exactly


def test_poly_recovers_polynomial():
    x = np.linspace(-50, 400, 15)
    y = 2e-3 - 1e-5 * x + 3e-8 * x ** 2 - 1e-11 * x ** 3
    f = make_function(x, y, "poly", degree=3)
    q = np.linspace(-50, 400, 101)
    np.testing.assert_allclose(f(q), 2e-3 - 1e-5 * q + 3e-8 * q ** 2 - 1e-11 * q ** 3, atol=1e-15)
    assert choose_degree(x, y) == 3


@pytest.mark.parametrize("true_degree", [1, 2, 3])
def test_cross_validation_picks_true_degree(true_degree):
    rng = np.random.default_rng(7 + true_degree)
    x = np.linspace(0, 1000, 41)
    t = (x - 500) / 500
    # Legendre-orthogonal shape: every coefficient up to true_degree is well above the noise
    coef = [0.0, 3.0, -2.5, 2.0][: true_degree + 1]
    hits = 0
    for _ in range(10):
        y = np.polynomial.legendre.legval(t, coef) + rng.normal(0, 0.1, x.size)
        hits += choose_degree(x, y) == true_degree
    assert hits >= 8


def test_model_parameter_checks(tmp_path):
    t = ErrorTable("X", [0, 1], {"EXX": [0, 1e-3]})
    with pytest.raises(InputError, match="no constant parameter EX0C"):
        ErrorFunctions({"X": t}, {"EX0C": 1e-3}, MB1)
    with pytest.raises(InputError, match="unknown interpolation"):
        ErrorFunctions({"X": t}, {}, MB1, method="spline")


def test_error_dir(tmp_path):
    d = tmp_path / "err"
    d.mkdir()
    _write(d / "X.csv", "X,EXX_um,EXX_std_um\n0,0,1\n900,9,3\n")
    _write(d / "constants.csv", "name,value,unit,std\nEC0Y,14.1,urad,2\n")
    f = ErrorFunctions.from_dir(d, MB1)
    assert f.has_random
    pos = {"X": [450.0], "Y": [100.0], "Z": [5.0]}
    assert f(pos)["EXX"][0] == pytest.approx(4.5e-3)
    s = f.sigmas(pos)
    assert s["EXX"][0] == pytest.approx(2e-3) and s["EC0Y"][0] == pytest.approx(2e-6)
    # Y has no table: any Y is fine, and the model gets zeros for EXY...
    e = MB1.volumetric_error(pos, f(pos))
    assert e.shape == (1, 3)
    _write(d / "notes.csv", "a,b\n1,2\n")
    with pytest.raises(InputError, match="unknown file"):
        ErrorFunctions.from_dir(d, MB1)
    (d / "notes.csv").unlink()
    _write(d / "C.csv", "C,EXC_um\n0,0\n10,1\n")
    with pytest.raises(InputError, match="machine's axes"):
        ErrorFunctions.from_dir(d, MB1)


def test_write_refuses_input(tmp_path):
    t = ErrorTable("X", [0, 1], {"EXX": [0, 1e-3]})
    p = tmp_path / "X.csv"
    write_error_table(p, t)
    before = p.read_text()
    with pytest.raises(InputError, match="refusing to overwrite"):
        write_error_table(p, ErrorTable("X", [0, 1], {"EXX": [0, 2e-3]}), inputs=[p])
    assert p.read_text() == before


def test_rotary_table_in_degrees(tmp_path):
    p = _write(tmp_path / "C.csv", "C_deg,EXC_um,EAC_urad,ECC_urad\n-180,0,0,0\n0,1.5,2,3\n180,3,4,6\n")
    t = read_error_table(p, axis="C")
    np.testing.assert_array_equal(t.positions, [-180, 0, 180])  # degrees stay degrees
    assert t.values["EXC"][1] == pytest.approx(1.5e-3) and t.values["ECC"][2] == pytest.approx(6e-6)
    write_error_table(tmp_path / "C2.csv", t)
    assert (tmp_path / "C2.csv").read_text().splitlines()[0] == "C,EXC_um,EAC_urad,ECC_urad"
    p = _write(tmp_path / "C3.csv", "C_mm,EXC_um\n0,0\n1,1\n")
    with pytest.raises(InputError, match="deg"):
        read_error_table(p)


def test_poly_functions_from_tables():
    x = np.linspace(0, 900, 19)
    rng = np.random.default_rng(0)
    y = 1e-3 * (0.5 * ((x - 450) / 450) ** 2 - 0.2 * (x - 450) / 450) + rng.normal(0, 2e-5, x.size)
    t = ErrorTable("X", x, {"EXX": y})
    f = ErrorFunctions({"X": t}, {}, MB1, method="poly")
    assert f.degrees == {"EXX": choose_degree(x, y)}
    q = {"X": x, "Y": 0 * x, "Z": 0 * x}
    truth = 1e-3 * (0.5 * ((x - 450) / 450) ** 2 - 0.2 * (x - 450) / 450)
    assert np.max(np.abs(f(q)["EXX"] - truth)) < 3 * 2e-5  # smooths the noise
    g = ErrorFunctions({"X": t}, {}, MB1, method="poly", degree=1)
    lin = np.polyval(np.polyfit(x, y, 1), x)  # independent least squares
    np.testing.assert_allclose(g(q)["EXX"], lin, atol=1e-12)
    with pytest.raises(InputError, match="degree"):
        ErrorFunctions({"X": t}, {}, MB1, method="poly", degree=19)


def test_lenient_spelling_of_tables_and_constants(tmp_path):
    """Case, the micro sign, the axis column elsewhere and comment columns read as the plain form;
    a parameter column without a valid unit is still refused."""
    for sub in ("0", "1", "2", "3", "bad"):
        (tmp_path / sub).mkdir()
    plain = read_error_table(_write(tmp_path / "X.csv", "X,EXX_um,EAX_urad\n0,1,2\n10,3,-4\n"),
                             axis="X")
    for i, text in enumerate([
            "x,exx_UM,eax_URAD\n0,1,2\n10,3,-4\n",
            "X,EXX_\u00b5m,EAX_\u03bcrad\n0,1,2\n10,3,-4\n",
            "EXX_um,X,EAX_urad\n1,0,2\n3,10,-4\n",
            "X,note,EXX_um,T_C,EAX_urad\n0,start,1,20.1,2\n10,,3,20.3,-4\n"]):
        t = read_error_table(_write(tmp_path / f"{i}" / "X.csv", text), axis="X")
        np.testing.assert_array_equal(t.positions, plain.positions)
        assert t.values.keys() == plain.values.keys()
        for k in plain.values:
            np.testing.assert_allclose(t.values[k], plain.values[k], rtol=1e-15)
    for text, match in (("X,dx_um\n0,1\n1,2\n", "not a component error"),
                        ("X,note\n0,a\n1,b\n", "no error columns"),
                        ("X,exx\n0,1\n1,2\n", "unit suffix")):
        with pytest.raises(InputError, match=match):
            read_error_table(_write(tmp_path / "bad" / "X.csv", text), axis="X")
    c = _write(tmp_path / "c.csv", "Unit,Name,Value,comment\nURAD,ec0y,12,squareness\n"
                                   "\u00b5m,EX0C,5,\n")
    assert read_constants(c) == pytest.approx({"EC0Y": 12e-6, "EX0C": 5e-3})


@settings(max_examples=40, deadline=None)
@given(data=st.data())
def test_table_csv_cells_are_format_number_of_the_values(data):
    """The table writer formats whole blocks at once; every cell must still be the documented
    rule (units.format_number: 12 significant digits, never -0) of its value in um / urad."""
    from volerr.tables.table import table_to_csv
    from volerr.units import format_number

    n = data.draw(st.integers(2, 8))
    pos = np.cumsum(data.draw(st.lists(st.floats(0.01, 100), min_size=n, max_size=n)))
    vals = {name: np.array(data.draw(st.lists(st.one_of(finite, st.just(-0.0),
                                                         st.floats(-1e-12, 1e-12)),
                                               min_size=n, max_size=n))) * 1e-3
            for name in ("EXX", "EBX")}
    text = table_to_csv(ErrorTable("X", pos, vals, std={"EXX": np.abs(vals["EXX"])}))
    lines = text.splitlines()
    assert lines[0] == "X,EXX_um,EBX_urad,EXX_std_um"
    for i, line in enumerate(lines[1:]):
        want = [pos[i], vals["EXX"][i] * 1e3, vals["EBX"][i] * 1e6, abs(vals["EXX"][i]) * 1e3]
        assert line.split(",") == [format_number(v) for v in want]


@settings(max_examples=60, deadline=None)
@given(st.data())
def test_stacked_linear_functions_give_each_axis_group_bits(data):
    """A few positions (a compensation chunk of one line): the linear functions of all axes
    evaluated at once (_LinearStack) give the bits of each axis' _LinearGroup, inside the
    nodes, on them, beyond them (the end rule, clamped or extended) and for unevenly spaced
    nodes."""
    from volerr.tables.functions import _LinearGroup, _LinearStack

    rng = np.random.default_rng(data.draw(st.integers(0, 2 ** 32 - 1)))
    groups = []
    for _ in range(data.draw(st.integers(1, 5))):
        m = int(rng.integers(2, 30))
        lo = rng.uniform(-500, 0)
        hi = lo + rng.uniform(1, 900)
        x = np.linspace(lo, hi, m) if rng.random() < 0.8 else np.sort(rng.uniform(lo, hi, m))
        ys = [rng.normal(size=m) * 1e-3 for _ in range(int(rng.integers(1, 8)))]
        groups.append(_LinearGroup(x, ys, clamp=bool(rng.integers(2))))
    n = data.draw(st.integers(0, 12))
    Q = np.array([np.where(rng.random(n) < 0.3, g.x[rng.integers(0, len(g.x), n)],
                           rng.uniform(g.x[0] - 5, g.x[-1] + 5, n)) for g in groups])
    got = _LinearStack(groups)(Q.reshape(len(groups), n))
    for g, q, v in zip(groups, Q.reshape(len(groups), n), got):
        assert v.tobytes() == g(q).tobytes()
