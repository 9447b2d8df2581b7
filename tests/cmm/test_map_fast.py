"""Fast map paths: vectorised CSV numbers, the fused exact random error, streamed map CSV."""

from decimal import ROUND_HALF_EVEN, Decimal

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

import volerr
from volerr.cmm import csvformat
from volerr.cmm.examples import write_example_errors
from volerr.cmm.volmap import map_csv, volumetric_map
from volerr.tables.functions import ErrorFunctions


def _reference(v: float, d: int) -> str:
    """Independent: exact decimal rounding of the float, shortest text, no '-0'."""
    q = Decimal(v).quantize(Decimal(1).scaleb(-d), rounding=ROUND_HALF_EVEN)
    s = format(q, "f")
    if "." in s:
        s = s.rstrip("0").rstrip(".")
    return "0" if s in ("-0", "") else s


@settings(max_examples=60, deadline=None)
@given(st.lists(st.floats(-1e7, 1e7, allow_nan=False), min_size=1, max_size=40),
       st.integers(0, 7))
def test_numbers_match_exact_decimal_rounding(values, d):
    text = csvformat.rows_text([np.array(values)], d).decode()
    got = text.split("\n")[:-1]
    for v, s in zip(values, got):
        ref = _reference(v, d)
        if s != ref:  # only a value on a rounding tie after v * 10^d may differ, by one unit
            assert abs(float(s) - float(ref)) <= 1.01 * 10.0 ** -d, (v, s, ref)
            assert abs(abs(v * 10 ** d) % 1 - 0.5) < 1e-6, (v, s, ref)


def test_rows_columns_scalars_and_codes():
    text = csvformat.rows_text([(np.array([0.0, 2.5]), np.array([1, 0, 1])), 7.0,
                                np.array([-0.0000004, -1.25, 3e-6])], [3, 0, 6]).decode()
    assert text == "2.5,7,0\n0,7,-1.25\n2.5,7,0.000003\n"


def test_fused_random_error_equals_sensitivity_propagation(tmp_path):
    """Independent: sqrt(sum_p S_kp^2 s_p^2) from the model's sensitivity array."""
    rng = np.random.default_rng(3)
    for name in ("MH2", "DMU50"):
        model = volerr.load(name)
        n = 2000
        lo = np.array([model.travel[a][0] for a in model.axes])
        hi = np.array([model.travel[a][1] for a in model.axes])
        pos = lo + rng.random((n, len(lo))) * (hi - lo)
        sig = {p: rng.random(n) * (1e-6 if p[1] in "ABC" else 1e-3) for p in model.parameters}
        probe = (5.0, -30.0, 120.0)
        s = model.sensitivity(pos, probe)
        var = np.stack([sig[p] for p in model.parameters], axis=-1) ** 2
        ref = np.sqrt(np.einsum("nij,nj->ni", s ** 2, var))
        np.testing.assert_allclose(model.random_error(pos, sig, probe), ref, rtol=1e-12,
                                   atol=1e-18)


def test_blocked_map_and_csv_equal_direct_evaluation(tmp_path, monkeypatch):
    """A map evaluated and written in small blocks equals one direct evaluation of the model."""
    from volerr.cmm import volmap

    write_example_errors(tmp_path / "e", "MH2")
    model = volerr.load("MH2")
    funcs = ErrorFunctions.from_dir(tmp_path / "e", model)
    monkeypatch.setattr(volmap, "BLOCK", 7)
    vm = volumetric_map(model, funcs, (3, 4, 5), probe=(0, 50, 0))
    pos = {a: vm.positions[a] for a in model.axes}
    np.testing.assert_array_equal(vm.error, model.volumetric_error(pos, funcs(pos), (0, 50, 0)))
    rows = map_csv(vm).splitlines()
    data = np.array([[float(v) for v in r.split(",")] for r in rows[1:]])
    assert data.shape == (60, 12)
    grid = np.stack(np.meshgrid(*[np.linspace(*model.travel[a], k) for a, k in
                                  zip("XYZ", (3, 4, 5))], indexing="ij"), -1).reshape(-1, 3)
    np.testing.assert_allclose(data[:, :3], grid, atol=5e-7)
    np.testing.assert_allclose(data[:, 6:9], vm.error * 1e3, atol=5.1e-7)
    np.testing.assert_allclose(data[:, 9:12], vm.random * 1e3, atol=5.1e-7)
