"""Derivation of the three-point equations and the audit of the thesis' printed forms."""

import tomllib
from importlib import resources

import numpy as np
import pytest

from volerr.derive import audit_tracker, three_point


def _printed():
    return tomllib.loads((resources.files("volerr") / "data" / "printed_tracker.toml")
                         .read_text(encoding="utf-8"))


@pytest.fixture(scope="module")
def verdicts():
    return {(v.equation, v.component): v for v in audit_tracker.audit(_printed())}


@pytest.mark.parametrize("sel", sorted(three_point.SELECTIONS))
def test_generated_closed_form_solves_selected_system(sel):
    from volerr.generated import three_point as gen

    A, b = three_point.selected_system(sel)
    rng = np.random.default_rng(5)
    lever = rng.uniform(-150, 150, size=(3, 3))
    d = rng.normal(size=6) * 0.01
    subs = {s: lever["PQK".index(s.name[-1]), "xyz".index(s.name[0])]
            for s in A.free_symbols}
    An = np.array(A.subs(subs), dtype=float)
    want = np.linalg.solve(An, d)
    got = getattr(gen, f"solve_{sel}")(*lever.ravel(), *d)
    assert np.allclose(got, want, rtol=1e-9, atol=1e-12)
    N = getattr(gen, f"det_{sel}")(*lever.ravel())["N"]
    assert N == pytest.approx(np.linalg.det(An), rel=1e-9)
    assert gen.SELECTIONS == three_point.SELECTIONS


def test_eq_33_34_identical(verdicts):
    for m in ("EZX", "EAX", "EBX", "ECX", "N"):
        assert verdicts[("eq. 33-34", m)].verdict == "identical"
    # E_XX, E_YX: identical once the factor printed inside the subscript of z multiplies it;
    # a subscript's scope is glyph-level damage (print or extraction): undecidable
    for m in ("EXX", "EYX"):
        v = verdicts[("eq. 33-34", m)]
        assert v.category == "undecidable" and "subscript" in v.erratum


def test_appendix_z_identical(verdicts):
    for m in ("EAZ", "EBZ", "ECZ"):
        assert verdicts[("Appendix (Z axis)", m)].verdict == "identical"
    for m in ("EXZ", "EYZ", "EZZ", "EAZ", "EBZ", "ECZ"):
        assert verdicts[("Appendix (Z axis), denominators", m)].verdict == "identical"


def test_rotary_errata_named(verdicts):
    n = verdicts[("eq. 3.7-3.8", "N")]
    assert n.verdict == "differs" and "minus sign" in n.erratum
    a = verdicts[("eq. 3.7-3.8", "EAC")]
    assert a.verdict == "differs" and "yh_Q printed for xh_P" in a.erratum
    for m in ("EXC", "EYC", "EZC", "EBC", "ECC"):
        assert "otherwise as derived" in verdicts[("eq. 3.7-3.8", m)].erratum
    z = verdicts[("eq. 3.4", "Delta_z right-hand side")]
    assert z.verdict == "differs"
    for c in ("x", "y"):
        assert verdicts[("eq. 3.4", f"Delta_{c} right-hand side")].verdict == "identical"


def test_systems(verdicts):
    assert verdicts[("eq. 31", "coefficient matrix")].verdict == "differs"
    assert "twice" in verdicts[("eq. 31", "coefficient matrix")].erratum
    for eq in ("eq. 32", "eq. 36", "eq. 37", "eq. 3.5", "eq. 3.6"):
        assert verdicts[(eq, "coefficient matrix")].verdict == "identical", eq
    assert verdicts[("eq. 32", "right-hand side")].verdict == "identical"
    assert "EAX missing" in verdicts[("eq. 32", "unknown vector")].erratum
    assert verdicts[("eq. 37", "right-hand side")].verdict == "differs"


def test_mutation_detected_and_named():
    doc = _printed()
    eq = next(e for e in doc["equation"] if e["id"] == "33-34")
    eq = dict(eq)
    eq["expr"] = dict(eq["expr"])
    eq["expr"]["EB"] = "(d_xQ - d_xP)/(z_Q - z_P) + (y_Q - y_K)/(z_Q - z_P)*M/N"
    eq["expr"] = {"EB": eq["expr"]["EB"]}
    eq["ocr"] = {}
    out = audit_tracker.audit_closed_form(eq)
    v = next(v for v in out if v.component == "EBX")
    assert v.verdict == "differs" and "y_K printed for y_P" in v.erratum


def test_layout_filter():
    assert audit_tracker.audit(_printed(), ["MB1"]) == []
