"""Fused evaluation (volerr.machine.fused): the numpy block kernels behind Model and the optional
numba backend give the values of the generated code; checked against hand-written Pahk eq. (4),
against the generated functions called whole, and on a synthetic straight-line function."""

from __future__ import annotations

import math

import numpy
import numpy as np
import pytest
from hypothesis import given, settings, strategies as st

import volerr
from helpers.pahk_eq4 import hand_eq4
from volerr.cli import main
from volerr.errors import InputError
from volerr.machine import fused, model as model_mod
from volerr.uncertainty import ensemble, montecarlo as mc, tasks

MB1 = volerr.load("MB1")
DMU50 = volerr.load("DMU50")


def _random_case(model, rng, n, subset: bool):
    lo = np.array([model.travel[a][0] for a in model.axes])
    hi = np.array([model.travel[a][1] for a in model.axes])
    pos = lo + rng.random((n, len(model.axes))) * (hi - lo)
    names = [p for p in model.parameters if not subset or rng.random() < 0.4]
    errs = {}
    for p in names:  # mixture of (n,) arrays, non-zero scalars, exact zeros
        kind = rng.integers(3)
        errs[p] = (rng.normal(size=n) * 1e-4 if kind == 0 else
                   float(rng.normal() * 1e-4) if kind == 1 else 0.0)
    probe = rng.normal(size=(n, 3)) * 50 if rng.random() < 0.5 else (10.0, -20.0, -150.0)
    return pos, errs, probe


def _unfused(model, fn, pos, probe, values):
    """The generated function called once on all points, outputs stacked (the old path)."""
    cols = model.positions(pos)
    n = pos.shape[0]
    pr = np.broadcast_to(np.asarray(probe, float), (n, 3))
    out = fn(**cols, Xp=pr[:, 0], Yp=pr[:, 1], Zp=pr[:, 2], **values)
    return np.stack([np.broadcast_to(c, (n,)) for c in out], axis=-1)


@pytest.fixture
def small_blocks(monkeypatch):
    monkeypatch.setattr(model_mod, "BLOCK", 37)  # many blocks and a ragged last one


@settings(max_examples=25, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), n=st.integers(1, 200), subset=st.booleans())
def test_mb1_blocked_kernel_equals_hand_written_eq4(seed, n, subset):
    rng = np.random.default_rng(seed)
    pos, errs, probe = _random_case(MB1, rng, n, subset)
    old = model_mod.BLOCK
    model_mod.BLOCK = 37
    try:
        got = MB1.volumetric_error(pos, errs, probe)
    finally:
        model_mod.BLOCK = old
    assert got.shape == (n, 3)
    np.testing.assert_allclose(got, hand_eq4(pos, errs, probe), rtol=1e-12, atol=1e-15)


@pytest.mark.parametrize("name", ["MB1", "FH2", "DMU50", "TT_AC"])
def test_fused_kernels_identical_to_generated_functions(name, small_blocks):
    """Same expression tree, same order of operations: bitwise the same values (zero folding
    only drops exact ``+ 0`` and ``* 0``), for volumetric and both random-error functions, and
    the tool axis."""
    model = volerr.load(name)
    for f in ("volumetric_error", "random_error_exact", "random_error_termwise"):
        assert fused.parse(getattr(model.module, f)) is not None, f   # really fused
    rng = np.random.default_rng(3)
    for subset in (False, True, True):
        pos, errs, probe = _random_case(model, rng, 300, subset)
        full = {p: errs.get(p, 0.0) for p in model.parameters}
        ref = _unfused(model, model.module.volumetric_error, pos, probe, full)
        assert np.array_equal(model.volumetric_error(pos, errs, probe), ref)
        sig = {p: np.abs(v) for p, v in errs.items()}
        for method, fn in (("exact", model.module.random_error_exact),
                           ("termwise", model.module.random_error_termwise)):
            ref = _unfused(model, fn, pos, probe,
                           {f"s_{p}": sig.get(p, 0.0) for p in model.parameters})
            assert np.array_equal(model.random_error(pos, sig, probe, method=method), ref)
        if hasattr(model.module, "tool_axis"):   # fused tool axis = forward's (unfused) one
            assert np.array_equal(model.tool_axis(pos), model.forward(pos)[:, 3:6])


@pytest.mark.parametrize("name", ["DMU50", "TT_AC", "HH_BC", "MB1"])
def test_prepared_positions_give_the_same_values(name, small_blocks):
    """Model.prepared: the positions validated once with the sines and cosines of the rotary
    axes, which the kernels read instead of computing them: bitwise the values of the plain
    calls, and not changed when the caller changes its array afterwards."""
    model = volerr.load(name)
    rng = np.random.default_rng(8)
    pos, errs, probe = _random_case(model, rng, 120, False)
    prep = model.prepared(pos)
    want = {"exact": model.exact_error(pos, errs, probe),
            "volumetric": model.volumetric_error(pos, errs, probe),
            "nominal": model.nominal_position(pos, probe)}
    if model.rotary_axes:
        want["orientation"] = model.orientation_error(pos, errs)
        want["axis"] = model.tool_axis(pos)
    pos += 1.0       # the prepared positions are the model's own copies
    got = {"exact": model.exact_error(prep, errs, probe),
           "volumetric": model.volumetric_error(prep, errs, probe),
           "nominal": model.nominal_position(prep, probe)}
    if model.rotary_axes:
        got["orientation"] = model.orientation_error(prep, errs)
        got["axis"] = model.tool_axis(prep)
    for k in want:
        assert np.array_equal(got[k], want[k]), k
    assert set(prep.trig) == set(model.rotary_axes)
    if model.rotary_axes:   # the kernels really take the given sines and cosines
        src, _ = fused.numpy_source(fused.parse(model.module.exact_error), trig=prep.trig)
        a = model.rotary_axes[0]
        assert f"numpy.sin({a}" not in src and fused.trig_name("sin", a) in src


# ---- a synthetic straight-line function, in the form of the generated code ------------------
def _synthetic(a, b, c, d):
    """Doc."""
    _shape = numpy.broadcast_shapes(numpy.shape(a), numpy.shape(b), numpy.shape(c),
                                    numpy.shape(d))
    _t0 = a * b - c
    _t1 = -_t0 + d**2
    _t2 = _t1
    _o0 = numpy.broadcast_to(numpy.sqrt(_t2 * _t2 + 1) - 0 * a, _shape)
    _o1 = numpy.broadcast_to(numpy.cos(c) * _t0 + (d - a) / 2, _shape)
    _o2 = numpy.broadcast_to(b, _shape)
    return _o0, _o1, _o2


def _synthetic_reference(a, b, c, d):
    """The same formulas written again, in plain numpy."""
    t0 = a * b - c
    t1 = d * d - t0
    return (np.sqrt(t1 * t1 + 1), np.cos(c) * t0 + (d - a) / 2, b)


@settings(max_examples=60, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), kinds=st.lists(st.integers(0, 2), min_size=4,
                                                      max_size=4))
def test_zero_folding_and_scalars_on_a_synthetic_function(seed, kinds):
    import ast

    fn = _synthetic
    parsed = fused.parse(fn)
    assert parsed is not None and parsed.args == ("a", "b", "c", "d")
    assert isinstance(parsed.outputs[0], ast.expr)
    rng = np.random.default_rng(seed)
    m = 11
    values = {}
    for name, kind in zip("abcd", kinds):  # 0: zero scalar, 1: scalar, 2: (m,) array
        values[name] = 0.0 if kind == 0 else (float(rng.normal()) if kind == 1
                                              else rng.normal(size=m))
    zeros = frozenset(k for k, v in values.items() if np.ndim(v) == 0 and v == 0)
    scalars = frozenset(k for k, v in values.items() if np.ndim(v) == 0) - zeros
    kernel, n_scratch = fused.numpy_kernel(fn, zeros, scalars)
    out = np.full((m, 3), np.nan)
    kernel(out, np.empty((n_scratch, m)), **values)
    ref = np.stack([np.broadcast_to(r, (m,)) for r in _synthetic_reference(**values)], axis=-1)
    np.testing.assert_allclose(out, ref, rtol=1e-14, atol=1e-14)


def test_non_straight_line_function_falls_back(small_blocks):
    def odd(X, Y, Z, Xp, Yp, Zp):
        if np.ndim(X) > 5:   # a statement the fuser does not know: evaluate the function itself
            raise AssertionError
        return X + Xp, Y * 2 + Yp, Z - Zp

    assert fused.parse(odd) is None
    pos = np.arange(300.0).reshape(100, 3)
    kw = {"X": pos[:, 0], "Y": pos[:, 1], "Z": pos[:, 2], "Xp": 1.0, "Yp": 2.0, "Zp": 3.0}
    got = model_mod._blocked(odd, kw, 100)
    np.testing.assert_array_equal(got, np.column_stack([pos[:, 0] + 1, pos[:, 1] * 2 + 2,
                                                        pos[:, 2] - 3]))


# ---- checks stay complete with the per-block finiteness test --------------------------------
def test_nan_error_in_last_block_is_named(small_blocks):
    pos = np.random.default_rng(0).random((200, 3)) * 400
    errs = {"EXX": np.zeros(200), "EBY": np.full(200, 1e-5)}
    errs["EBY"][-1] = np.nan
    with pytest.raises(InputError, match="error EBY has NaN"):
        MB1.volumetric_error(pos, errs)
    pos[150, 2] = np.inf
    with pytest.raises(InputError, match="position Z has NaN"):
        MB1.volumetric_error(pos, {})   # all errors zero: the position check alone finds it


def test_huge_finite_values_are_not_mistaken_for_nan():
    """The checks sum a block first: an overflowing sum of finite values must not raise."""
    pos = np.full((1000, 3), 1e306)
    out = MB1.volumetric_error(pos, {"EXX": 1e306, "EXY": 1e306})
    assert np.all(out[:, 0] == 2e306) and np.all(out[:, 1:] == 0)


# ---- the backend choice ---------------------------------------------------------------------
def test_unknown_backend_is_input_error():
    with pytest.raises(InputError, match="unknown backend"):
        fused.resolve_backend("cuda")


def test_numba_missing_falls_back_with_one_warning(monkeypatch, tmp_path, capsys):
    monkeypatch.setattr(fused, "numba_available", lambda: False)
    with pytest.warns(fused.FallbackWarning, match="numba is not installed") as rec:
        assert fused.resolve_backend("numba") == "numpy"
    assert len(rec) == 1
    task = tmp_path / "t.csv"
    task.write_text("X,Y,Z\n100,100,100\n300,100,100\n")
    argv = ["uncertainty", "MB1", "--task", str(task), "--evaluate", "distance", "--noise-um",
            "1", "--samples", "300", "--contributions", "0", "--quiet", "--json"]
    assert main(argv + [str(tmp_path / "a.json"), "--backend", "numba"]) == 0
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and err.startswith("volerr: warning: numba is not installed")
    assert main(argv + [str(tmp_path / "b.json")]) == 0      # default: numpy, no warning
    assert capsys.readouterr().err == ""
    assert (tmp_path / "a.json").read_text() == (tmp_path / "b.json").read_text()


# ---- numba (optional) -----------------------------------------------------------------------
@pytest.fixture
def numba_cache(monkeypatch, tmp_path):
    pytest.importorskip("numba", reason="numba is an optional extra (volerr[fast])")
    monkeypatch.setenv("VOLERR_CACHE_DIR", str(tmp_path))
    return tmp_path


@pytest.mark.parametrize("name", ["MB1", "TT_AC"])
def test_numba_kernel_equals_numpy_path(name, numba_cache):
    model = volerr.load(name)
    rng = np.random.default_rng(5)
    pos, errs, probe = _random_case(model, rng, 500, True)
    cols = model.positions(pos)
    pr = np.broadcast_to(np.asarray(probe, float), (500, 3))
    kw = {**cols, "Xp": pr[:, 0], "Yp": pr[:, 1], "Zp": pr[:, 2],
          **{p: errs.get(p, 0.0) for p in model.parameters}}
    got = fused.evaluate_numba(model.module.volumetric_error, kw)
    ref = model.volumetric_error(pos, errs, probe)
    np.testing.assert_allclose(got, ref, rtol=1e-12, atol=1e-12 * np.abs(ref).max())
    # (S, P) broadcasting as in the Monte Carlo: positions (P,), errors (S, P) and (S, 1)
    S = 7
    kw2 = dict(kw, EXX=rng.normal(size=(S, 500)) * 1e-3, EYY=rng.normal(size=(S, 1)) * 1e-3)
    got2 = fused.evaluate_numba(model.module.volumetric_error, kw2)
    ref2 = np.stack(np.broadcast_arrays(*model.module.volumetric_error(**kw2)), axis=-1)
    assert got2.shape == (S, 500, 3)
    np.testing.assert_allclose(got2, ref2, rtol=1e-12, atol=1e-12 * np.abs(ref2).max())
    # the kernel source went to the cache folder, with numba's cache files beside it
    assert list((numba_cache / "fused").glob("*.py"))


def test_monte_carlo_numba_backend_same_values(numba_cache):
    th = np.linspace(0, 2 * np.pi, 9, endpoint=False)
    n = np.column_stack([np.cos(th), np.sin(th), np.zeros(9)])
    p = np.array([420.0, 260.0, 180.0]) + 15 * n
    task = tasks.Task({"X": p[:, 0], "Y": p[:, 1], "Z": p[:, 2]}, np.zeros_like(p), n)
    ens = ensemble.Ensemble.build(spec=ensemble.parse_spec("E0=3+L/250"), noise_um=0.3, seed=2)
    v = {}
    for backend in ("numpy", "numba"):
        prob = mc.prepare(MB1, "MB1", task, "circle", ens, seed=4, backend=backend)
        assert prob.backend == backend
        v[backend], _ = mc.run(prob, 600)
    scale = np.abs(v["numpy"]).max()
    np.testing.assert_allclose(v["numba"], v["numpy"], rtol=1e-12, atol=1e-12 * scale)
    assert not math.isnan(v["numba"].sum())


@pytest.mark.parametrize("model", [DMU50, MB1, volerr.load("TT_AC")], ids=lambda m: m.name)
def test_point_kernel_gives_the_numpy_kernel_bits(model):
    """One point (a compensation chunk of one line): the point kernel (Python float
    arithmetic, the other ufuncs on one-element arrays) writes the bits of the numpy kernel
    on (1,) arrays, for random zero / scalar / array patterns, with and without the rotary
    axes' sines and cosines given; Model methods on one point take it."""
    rng = np.random.default_rng(7)
    names = ("volumetric_error", "exact_error", "orientation_error", "nominal_position",
             "tool_axis")
    for fname in names:
        fn = getattr(model.module, fname)
        args = fused.parse(fn).args
        for trial in range(8):        # each trial compiles two kernels (~25 ms)
            kw = {}
            for a in args:
                r = rng.random()
                kw[a] = (0.0 if r < 0.25 else float(rng.normal() * 10.0 ** rng.integers(-9, 3))
                         if r < 0.4 else np.array([rng.normal() * 10.0 ** rng.integers(-9, 3)]))
            rot = [a for a in model.rotary_axes if a in args]
            for a in rot:
                kw[a] = np.array([rng.uniform(-7, 7)])
            trig = {a: (np.sin(kw[a]), np.cos(kw[a])) for a in rot} if trial % 2 else {}
            scalars = {k for k, v in kw.items() if np.ndim(v) == 0}
            zeros = frozenset(k for k in scalars if kw[k] == 0)
            full = {**kw, **{fused.trig_name(f, a): v for a, sc in trig.items()
                             for f, v in zip(("sin", "cos"), sc)}}
            kernel, n_s = fused.numpy_kernel(fn, zeros, frozenset(scalars) - zeros,
                                             frozenset(trig))
            want = np.empty((1, fused.n_outputs(fn)))
            kernel(want, np.empty((n_s, 1)), **full)
            point = fused.point_kernel(fn, zeros, frozenset(scalars) - zeros, frozenset(trig))
            got = np.empty_like(want)
            point(got, **{k: (v.item() if isinstance(v, np.ndarray) else v)
                          for k, v in full.items()})
            assert got.tobytes() == want.tobytes(), (fname, trial)
            via = model_mod._blocked(fn, kw, 1, want.shape[1], trig=trig)
            assert via.tobytes() == want.tobytes(), (fname, trial)
