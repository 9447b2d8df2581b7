"""Certificates (issue 23): ISO 230-2 and ISO 10360-2 verdicts follow ISO 14253-1 -- pass only
inside the tolerance reduced by U, fail only outside it widened by U, undecided in between --
on constructed cases at the conformance boundary; U recomputed here from the documented
budget; identification fields and no negative zero on the page."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from volerr import conformance
from volerr.cli import main

TARGETS = np.linspace(0.0, 800.0, 9)
N = 5


def _run(tmp_path):
    """A deterministic run: a smooth error, a reversal and a fixed scatter pattern, um."""
    pattern = np.array([-0.4, 0.3, 0.0, 0.25, -0.15])
    lines = ["target_mm,cycle,direction,deviation_um"]
    dev = np.empty((TARGETS.size, 2, N))
    for i, t in enumerate(TARGETS):
        for d, half in enumerate((1.0, -1.0)):
            dev[i, d] = 3.0 * np.sin(t / 250.0) + half + pattern * (1 + 0.1 * i)
            for c in range(N):
                lines.append(f"{t:g},{c + 1},{'+1' if d == 0 else '-1'},{dev[i, d, c]:.6f}")
    f = tmp_path / "run.csv"
    f.write_text("\n".join(lines) + "\n")
    return f, dev


def _expected(dev, ppm=0.5, align_mm=0.1):
    """E, M, A, R, B and U (k = 2) from the definitions of ISO 230-2 and the budget of the
    certificate's documentation (instrument, alignment, repeatability; no temperature, no
    EVE), um."""
    xm, s = dev.mean(axis=2), dev.std(axis=2, ddof=1)
    mean = xm.mean(axis=1)
    b = xm[:, 0] - xm[:, 1]
    L = TARGETS[-1] - TARGETS[0]
    S = s.max()
    uS = S / math.sqrt(2 * (N - 1))
    inst = ppm * 1e-6 * L * 1e3 / math.sqrt(3)
    align = align_mm ** 2 / (2 * L) * 1e3 / math.sqrt(12)
    rep = {"E": S * math.sqrt(2 / N), "M": S / math.sqrt(N), "B": S * math.sqrt(2 / N),
           "R": 4 * uS, "A": math.sqrt(2 * S ** 2 / N + 2 * (2 * uS) ** 2)}
    value = {"E": xm.max() - xm.min(), "M": mean.max() - mean.min(), "B": np.abs(b).max(),
             "R": np.maximum.reduce([2 * s[:, 0] + 2 * s[:, 1] + np.abs(b), 4 * s[:, 0],
                                     4 * s[:, 1]]).max(),
             "A": (xm + 2 * s).max() - (xm - 2 * s).min()}
    U = {q: 2 * math.sqrt((inst ** 2 + align ** 2 if q in "AEM" else 0.0) + rep[q] ** 2)
         for q in value}
    return value, U


def _iso(tmp_path, f, *extra):
    out = tmp_path / "r.json"
    assert main(["iso230-2", str(f), "--json", str(out), *map(str, extra)]) == 0
    return json.loads(out.read_text())


def test_iso230_2_uncertainty_is_the_documented_budget(tmp_path, capsys):
    f, dev = _run(tmp_path)
    value, U = _expected(dev)
    r = _iso(tmp_path, f)
    for q in value:
        assert r[f"{q}_um"] == pytest.approx(value[q], abs=1e-6)
        assert r["uncertainty_um"][q] == pytest.approx(U[q], rel=1e-9)
    assert "verdict" not in r
    capsys.readouterr()


@pytest.mark.parametrize("where, expect", [
    (+1.01, "pass"),        # tolerance above value + U: inside the conformance zone
    (+0.99, "undecided"),   # value + U just beyond the tolerance
    (-0.99, "undecided"),   # value just inside tolerance + U
    (-1.01, "fail"),        # value beyond tolerance + U
])
def test_iso230_2_verdicts_at_the_conformance_boundary(tmp_path, capsys, where, expect):
    """Tolerance T = value + where * U for every quantity: ISO 14253-1 says pass for T > v + U,
    undecided for v - U < T < v + U, fail for T < v - U."""
    f, dev = _run(tmp_path)
    value, U = _expected(dev)
    tol = ",".join(f"{q}={value[q] + where * U[q]:.6f}" for q in value)
    page = ("--html", tmp_path / "c.html") if expect == "fail" else ()   # one page is enough
    r = _iso(tmp_path, f, "--tolerance", tol, *page,
             "--machine", "test machine SN 1", "--operator", "T. Ester", "--date", "2024-05-06")
    assert r["verdicts"] == {q: expect for q in value}
    assert r["verdict"] == expect
    assert r["identification"]["machine"] == "test machine SN 1"
    assert r["identification"]["date"] == "2024-05-06"
    if not page:
        return
    page = (tmp_path / "c.html").read_text()
    assert "test machine SN 1" in page and "2024-05-06" in page and "T. Ester" in page
    assert expect.upper() in page and "ISO 14253-1" in page
    assert not _negative_zero(page)
    capsys.readouterr()


def _negative_zero(text: str) -> bool:
    import re

    return re.search(r"(?<![\w.])[-\u2212]0(?:\.0+)?(?![\d.])", text) is not None


def test_one_failing_quantity_fails_the_certificate_and_is_ringed(tmp_path, capsys):
    f, dev = _run(tmp_path)
    value, U = _expected(dev)
    tol = f"E={value['E'] - 1.5 * U['E']:.6f},R={value['R'] + 2 * U['R']:.6f}"
    r = _iso(tmp_path, f, "--tolerance", tol, "--plot", tmp_path / "p.png")
    assert r["verdicts"] == {"E": "fail", "R": "pass"} and r["verdict"] == "fail"
    capsys.readouterr()


def test_decision_rule_itself():
    """conformance.verdict on both sides of both zone limits, upper-only and two-sided."""
    v = conformance.verdict
    assert v(9.0, 10.0, 1.0) == "pass" and v(9.0001, 10.0, 1.0) == "undecided"
    assert v(11.0, 10.0, 1.0) == "undecided" and v(11.0001, 10.0, 1.0) == "fail"
    assert v(0.0, 1.0, 0.5, lower=-1.0) == "pass"
    assert v(-0.6, 1.0, 0.5, lower=-1.0) == "undecided"
    assert v(-1.6, 1.0, 0.5, lower=-1.0) == "fail"
    assert conformance.overall(["pass", "undecided", "pass"]) == "undecided"
    assert conformance.overall(["pass", "undecided", "fail"]) == "fail"
    assert conformance.overall(["pass"]) == "pass"
    with pytest.raises(Exception):
        conformance.parse_tolerances("A=1,Q=2", "AEMRB")


# ---------------------------------------------------------------------------------------------
# ISO 10360-2
def test_iso10360_verdicts_at_the_conformance_boundary():
    """Constructed E0 values on both sides of MPE - U and MPE + U at every test length."""
    from volerr.uncertainty.iso10360 import Spec, TestResult, TestUncertainty

    lengths = np.tile(np.array([100.0, 250.0, 400.0, 550.0, 700.0]), (7, 1))
    spec, tu = Spec(2.0, 300.0), TestUncertainty()
    mpe = 2.0 + lengths / 300.0
    # independent U(L): calibration 0.1 + L/2000 (k = 2), 0.2 K on 11.5 ppm/K, T = 20 C
    U = 2 * np.sqrt((0.5 * (0.1 + lengths / 2000.0)) ** 2
                    + (lengths * 11.5 * 0.2 * 1e-3) ** 2)
    assert np.allclose(tu.U_um(lengths), U)
    for scale, expect in ((-1.0 - 1e-3, "pass"), (-1.0 + 1e-3, "undecided"),
                          (1.0 - 1e-3, "undecided"), (1.0 + 1e-3, "fail")):
        E = np.repeat((mpe + scale * U)[..., None], 3, axis=2)
        E[::2] *= -1          # the sign does not matter: |E0| against the MPE
        res = TestResult(tuple(f"line {i}" for i in range(7)), lengths, E, spec, tu)
        d = res.as_dict()
        assert d["verdict"] == expect and d["verdict_counts"][expect] == 105
    # one value beyond MPE + U among passing ones: the test fails, that value is named
    E = np.zeros((7, 5, 3))
    E[4, 2, 1] = -(mpe[4, 2] + 1.01 * U[4, 2])
    d = TestResult(tuple(f"line {i}" for i in range(7)), lengths, E, spec, tu).as_dict()
    assert d["verdict"] == "fail" and d["verdict_counts"]["fail"] == 1
    assert d["positions"][4]["verdicts"][2][1] == "fail"


def test_iso10360_cli_marks_and_judges_the_simulated_test(tmp_path, capsys):
    """A pure scale error EXX = k X: on the X line |E0| = k L (sign convention of
    volerr.uncertainty.iso10360); the verdict of every value recomputed here."""
    d = tmp_path / "e"
    d.mkdir()
    k = 20e-6   # 20 um/m
    x = np.linspace(0, 900, 10)
    (d / "X.csv").write_text("X,EXX_um\n" + "".join(f"{v:g},{k * v * 1e3:.9f}\n" for v in x))
    out = tmp_path / "t.json"
    assert main(["iso10360", "MB1", "--errors", str(d), "--mpe", "E0=1.5+L/100",
                 "--temperature-u-K", "0.05", "--json", str(out),
                 "--plot", str(tmp_path / "t.png"), "--html", str(tmp_path / "t.html"),
                 "--machine", "MB1 virtual"]) == 0
    doc = json.loads(out.read_text())
    counts = {"pass": 0, "undecided": 0, "fail": 0}
    for pos in doc["positions"]:
        for j, L in enumerate(pos["lengths_mm"]):
            U = 2 * math.sqrt((0.5 * (0.1 + L / 2000)) ** 2 + (L * 11.5 * 0.05e-3) ** 2)
            mpe = 1.5 + L / 100
            if pos["line"] == "axis X":
                assert all(abs(abs(E) - k * L * 1e3) < 1e-6 for E in pos["E_um"][j])
            for E, v in zip(pos["E_um"][j], pos["verdicts"][j]):
                want = ("pass" if abs(E) <= mpe - U else "fail" if abs(E) > mpe + U
                        else "undecided")
                assert v == want
                counts[want] += 1
    assert counts["fail"] > 0 and counts["pass"] > 0
    assert doc["verdict"] == "fail" and doc["verdict_counts"] == counts
    assert doc["uncertainty_um"]["E0"] > 0
    page = (tmp_path / "t.html").read_text()
    assert "MB1 virtual" in page and "FAIL" in page and not _negative_zero(page)
    capsys.readouterr()
