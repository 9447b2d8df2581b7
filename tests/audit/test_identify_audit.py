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
    for m, inner in (("EXX", "z_{xP(y_{xQ} - y_{xP})}"), ("EYX", "z_{xP(x_{xP} - x_{xK})}")):
        v = verdicts[("eq. 33-34", m)]
        assert v.category == "undecidable" and "subscript" in v.erratum
        # the printed field and the evidence carry the raw text, where the scope shows
        eq = next(e for e in _printed()["equation"] if e["id"] == "33-34")
        assert inner in eq["text"] and inner in v.printed and inner in v.evidence
    # each names the same defect in the other line
    assert "z_{xP(x_{xP} - x_{xK})}" in verdicts[("eq. 33-34", "EXX")].evidence


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


def _x_subscripts(eq):
    """(row label, column) of the lever arms printed with the X axis' subscript in the raw
    LaTeX of a rotary system (own parse of the extraction text)."""
    body = eq["text"].split("\\begin{bmatrix}")[1].split("\\end{bmatrix}")[0]
    rows = [r for r in body.split("\\\\")]
    assert len(rows) == len(eq["rows"])
    return {(lab, j + 1) for (lab, _), raw in zip(eq["rows"], rows)
            for j, cell in enumerate(raw.split("&")) if "}_{x" in cell and "hat" in cell}


def test_systems(verdicts):
    v31 = verdicts[("eq. 31", "coefficient matrix")]
    assert v31.verdict == "differs" and "twice" in v31.erratum
    # a row repeated within one image: print (copied matrix) or extraction -> undecidable
    assert v31.category == "undecidable" and "T_0^{t,c}" in v31.evidence
    for eq in ("eq. 32", "eq. 36", "eq. 37"):
        assert verdicts[(eq, "coefficient matrix")].verdict == "identical", eq
    # eq. 3.5 / 3.6: lever arms with the X axis' subscript x, at the same entries of the rows
    # the two systems share -> the cross-copy rule decides: printing error
    eqs = {e["id"]: e for e in _printed()["equation"]}
    x35, x36 = _x_subscripts(eqs["3.5"]), _x_subscripts(eqs["3.6"])
    shared = {lab for lab, _ in eqs["3.5"]["rows"]} & {lab for lab, _ in eqs["3.6"]["rows"]}
    assert x35 and {p for p in x35 if p[0] in shared} == {p for p in x36 if p[0] in shared}
    for eq, xs in (("eq. 3.5", x35), ("eq. 3.6", x36)):
        v = verdicts[(eq, "coefficient matrix")]
        assert v.category == "printing_error" and f"{len(xs)} lever arms" in v.erratum, eq
        assert "cross-copy rule" in v.evidence
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
