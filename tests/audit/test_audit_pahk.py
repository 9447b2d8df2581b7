"""Audit of Pahk (1995): verdicts, named errata, readings, CLI and numeric spot check.

Independent checks: the printed equations are also evaluated numerically (no sympy) against an
independent exact numpy chain (tests/reference_chain.py, finite differences), and errata are
injected into a copy of the printed data to show that the audit detects and names them.
"""

import copy
import json
import re
from collections import defaultdict
import tomllib
from importlib import resources
from pathlib import Path

import numpy as np
import pytest

import volerr
from volerr.audit.numeric import _evaluate, _paper_values, spot_check
from helpers import reference_chain
from helpers.in_process import volerr as volerr_command
from helpers.audit_rule import KIND, expected

#: the module's verdicts come from the full audit (conftest.provider_verdicts), in its group
pytestmark = pytest.mark.xdist_group("full_audit")

audit_pahk = pytest.importorskip("volerr.derive.audit.pahk")

DATA = tomllib.loads((resources.files("volerr.derive.audit") / "data" / "printed_pahk.toml")
                     .read_text(encoding="utf-8"))


@pytest.fixture(scope="module")
def verdicts(provider_verdicts):
    return provider_verdicts(audit_pahk, DATA, None)


def find(verdicts, eq, comp=""):
    hits = [v for v in verdicts if v.equation == eq and v.component == comp]
    assert len(hits) == 1, (eq, comp, [(v.equation, v.component) for v in verdicts])
    return hits[0]


# --------------------------------------------------------------------------- verdicts
def test_every_printed_equation_and_component_gets_a_verdict(verdicts):
    ids = {e["id"] for e in DATA["equation"]}
    assert ids == {"1", "4", "5", "6", "7", "8", "9", "10", "A1", "A2", "A3", "A4", "A5",
                   "A6", "A7", "A8", "A9"}
    for e in DATA["equation"]:
        comps = list(e.get("expr", {})) or [""]
        for c in comps:
            v = find(verdicts, e["id"], c)
            assert v.verdict in ("identical", "differs")
            assert (v.erratum == "") == (v.verdict == "identical")
            assert v.layout == e["layout"] and v.evidence


def test_eq4_is_identical_to_the_mb1_derivation(verdicts):
    for c in ("dX", "dY", "dZ"):
        assert find(verdicts, "4", c).verdict == "identical"


def test_mh2_chain_and_eq7_identical(verdicts):
    assert find(verdicts, "6").verdict == "identical"
    for c in ("dX", "dY", "dZ"):
        assert find(verdicts, "7", c).verdict == "identical"


def test_transfer_rule_omissions_named(verdicts):
    v = find(verdicts, "9", "dx(X)")
    assert v.verdict == "differs"
    assert "omitted Abbe term +Yo*Ez(X)" in v.erratum
    # eq. 4 itself has the Abbe term -Yp*Ez(X) that the rule drops
    assert "Yp*(Ez(X)" in find(verdicts, "4", "dX").printed
    v = find(verdicts, "9", "dy(Y)")
    assert "Ez(Z) for Ez(Y)" in v.erratum
    v = find(verdicts, "9", "beta1")
    # a convention: the erratum names the reading, the evidence the extra term it explains
    # (a squareness rule's errors written at the measuring offset, as Pahk prints them)
    assert "slope of the Z line" in v.erratum and "-Ey(Yo)" in v.erratum
    assert "extra +Ey(Yo)" in v.evidence and "Notation:" in v.evidence
    assert "slope of the Z line alone" in v.evidence
    # Pahk's rule (1) (straightness by roll only) reproduces the printed dy(X) rule
    assert "roll Ex(X) only" in find(verdicts, "9", "dy(X)").evidence


def test_mb1_chain_translation_vectors_misplaced(verdicts):
    v = find(verdicts, "1")
    assert v.verdict == "differs"
    assert "Ty*(Tx*(Tz*P + Lz) + Lx) + Ly" in v.erratum
    assert "beta1" in v.evidence  # the OCR-lost beta1 of eq. 3 is noted


def test_appendix_fb1_xy_labels_and_table_convention(verdicts):
    a1 = find(verdicts, "A1")
    assert a1.verdict == "differs" and "X and Y exchanged" in a1.erratum
    for c in ("dX", "dZ"):
        v = find(verdicts, "A2", c)
        assert v.verdict == "differs" and "moving table origin" in v.erratum
    assert "+Y*Ez(Y)" in find(verdicts, "A2", "dX").evidence


def test_garbled_a5_terms_and_fh1_stacking(verdicts):
    dz = find(verdicts, "A5", "dZ")
    assert "Ey(X) for Ex(X)" in dz.erratum
    assert "extra +X*Ey(X)" in find(verdicts, "A5", "dY").erratum
    dx = find(verdicts, "A5", "dX")
    # printed A4/A5: Z rides on Y (tool Y -> Z), the layout file: Y on Z; the text allows both
    geo = "geometry:FH1 tool Y -> Z, table X"
    assert dx.category == "convention" and dx.readings_used == [geo]
    a4 = find(verdicts, "A4")
    assert a4.category == "convention" and geo in a4.readings_used
    # the unbalanced parenthesis is read where it closes; the raw text is quoted
    raw = next(e for e in DATA["equation"] if e["id"] == "A5")["text"].splitlines()[0]
    assert raw.count("(") == raw.count(")") + 1
    assert "raw 'Z(-\\beta_1 + (Ey(Y) - Ey(X))" in dx.evidence
    assert "print or extraction" in dx.evidence
    # the whole-equation line says where the terms it leaves are: not in dX
    whole = next(t for t in dx.readings_tried if t.startswith("whole equation"))
    assert "in dY" in whole and "in dX" not in whole


def _raw_components(eq_id):
    return next(e for e in DATA["equation"] if e["id"] == eq_id)["expr"]


@pytest.mark.parametrize("eq_id, comp, token, elsewhere", [
    ("A5", "dY", "X*Ey(X)", "dZ"),          # the extra term of dY is a term of dZ
    ("A5", "dZ", "Ey(X)", "dZ"),            # Ey(X) for Ex(X): Ey(X) stands again in dZ
    ("A6", "dy(X)", "Yo*Ex(X)", "dz(X)"),   # the extra term of dy(X) is the term of dz(X)
    ("A8", "dY", "Ex(Z)", "dY"),            # Ex(Z) for Ex(X): Ex(Z) stands in the Zp bracket
])
def test_candidate_repetitions_within_one_image_are_undecidable(verdicts, eq_id, comp, token,
                                                                elsewhere):
    """The wrong token of these prints stands elsewhere in the same printed equation (read
    here from the raw transcription): the print and the extraction explain a repetition
    equally, so the verdict is undecidable and says so."""
    raw = _raw_components(eq_id)
    count = sum(raw[c].replace(" ", "").count(token) for c in raw)
    assert count >= 2 and token in raw[elsewhere].replace(" ", "")
    v = find(verdicts, eq_id, comp)
    assert v.category == "undecidable" and "Candidate repetition" in v.evidence
    assert "what would decide" in v.evidence.lower()


def test_a_wrong_symbol_that_stands_nowhere_else_stays_a_printing_error(verdicts):
    """MB1 eq. 9 dy(Y) prints Ez(Z) for Ez(Y); Ez(Z) stands in no other rule of eq. 9 (read
    here), and the right symbol Ez(Y) is read in 'alpha = alpha + Ez(Yo)': a printing error.
    Put Ez(Z) into another rule of eq. 9 and the same print becomes a candidate repetition."""
    raw = _raw_components("9")
    assert [c for c in raw if "Ez(Z)" in raw[c]] == ["dy(Y)"]
    assert "Ez(Yo)" in raw["alpha"]
    v = find(verdicts, "9", "dy(Y)")
    assert v.category == "printing_error" and "nowhere else" in v.evidence
    data = copy.deepcopy(DATA)
    eq9 = next(e for e in data["equation"] if e["id"] == "9")
    eq9["expr"]["dx(Z)"] = "dx(Z) + Yo*Ez(Z)"
    w = find(audit_pahk.audit(data, ["MB1"]), "9", "dy(Y)")
    assert w.category == "undecidable" and "Candidate repetition" in w.evidence


def test_cut_off_rules_are_undecidable_with_every_restoration_named(verdicts):
    """MH2 eq. 10 prints 'dz(Y) = dz' and 'dz(X) = dz(X) - Yo*Ex': cut off.  Written here from
    the MH2 chain of eq. 6 (A = Tx(Tz(Ty P + Ly) + Lz) + Lx): a point of the Y arm offset by
    (Xo, Yo, Zo) measures dz(Y) plus an Abbe shift, and the reference value is the measured one
    minus that shift: dz(Y) - Yo Ex(Y) + Xo Ey(Y), dz(X) - Yo Ex(X) + Xo Ey(X) -- the full
    transfers, so the restorations that print those terms are identical, the ones that keep the
    roll term only (Ey(Y) is the roll of Y, Ex(X) that of X) are Pahk's rule (1)."""
    import sympy as sp
    S = lambda n: sp.Symbol(n, real=True)  # noqa: E731

    def T(a):
        ex, ey, ez = (S(f"E{c}({a})") for c in "xyz")
        return sp.Matrix([[1, -ez, ey], [ez, 1, -ex], [-ey, ex, 1]])
    X, Y, Z = S("X"), S("Y"), S("Z")
    d = {f"d{c}({a})": S(f"d{c}({a})") for c in "xyz" for a in "XYZ"}
    Lx = sp.Matrix([X + d["dx(X)"], d["dy(X)"], d["dz(X)"]])
    Ly = sp.Matrix([d["dx(Y)"], Y + d["dy(Y)"], d["dz(Y)"]])
    Lz = sp.Matrix([d["dx(Z)"], d["dy(Z)"], Z + d["dz(Z)"]])
    Po = sp.Matrix([S("Xo"), S("Yo"), S("Zo")])
    A = T("X") * (T("Z") * (T("Y") * Po + Ly) + Lz) + Lx
    errs = [s for s in A.free_symbols if "(" in s.name]
    # the offsets are measured from the reference point with the other axes at zero
    dZ = _first_order((A[2] - Z - Po[2]).subs({X: 0, Y: 0, Z: 0}), errs)
    for axis, roll in (("Y", "Ey(Y)"), ("X", "Ex(X)")):
        shift = sum(t for t in sp.Add.make_args(dZ) if t.has(S(f"Ex({axis})"))
                    or t.has(S(f"Ey({axis})")))
        full = d[f"dz({axis})"] - shift           # reference = measured - Abbe shift
        v = find(verdicts, "10", f"dz({axis})")
        assert v.category == "undecidable" and "cut off" in v.erratum
        rest = {t.split("'")[1]: t.rsplit(": ", 1)[-1] for t in v.readings_tried}
        by_expr = {sp.expand(audit_pahk.parse(k)): out for k, out in rest.items()}
        assert by_expr[sp.expand(full)] == "identical"
        rule1 = d[f"dz({axis})"] - sum(t for t in sp.Add.make_args(shift) if t.has(S(roll)))
        assert "simplification" in by_expr[sp.expand(rule1)]
    assert _raw_components("10")["dz(Y)"] == "dz"
    v = find(verdicts, "10", "dz(Y)")
    assert "MB1 eq. 9 prints 'dz(Y) = dz(Y) + Xo*Ey(Y)'" in v.evidence


def test_unchanged_rule_pattern_names_the_prints_that_differ(verdicts):
    """A3 dz(Y) = dz(Y): the other layouts print it unchanged (FH1, CY), with the roll term
    (MB1 eq. 9) and cut off (MH2 eq. 10): the evidence names all of them."""
    raw = {e["layout"]: e["expr"].get("dz(Y)") for e in DATA["equation"]
           if e["kind"] == "transfer"}
    assert raw["MB1"].replace(" ", "") == "dz(Y)+Xo*Ey(Y)" and raw["MH2"] == "dz"
    v = find(verdicts, "A3", "dz(Y)")
    assert v.category == "undecidable"
    assert "MB1 eq. 9 prints 'dz(Y) = dz(Y) + Xo*Ey(Y)'" in v.evidence
    assert "MH2 eq. 10 prints 'dz(Y) = dz' (cut off)" in v.evidence
    assert "FH1 eq. A6" in v.evidence and "CY eq. A9" in v.evidence


def test_random_error_readings(verdicts):
    for c in ("RX2", "RY2", "RZ2"):
        assert "term-wise" in find(verdicts, "5", c).erratum
    assert "Z*Zp" in find(verdicts, "5", "RX2").evidence  # the dropped cross term
    assert "MB1 (eq. 5) reprinted" in find(verdicts, "8", "RY2").erratum
    rx = find(verdicts, "8", "RX2")
    assert "beta1 for Rbeta1" in rx.erratum
    assert rx.category == "undecidable" and "letter R lost" in rx.evidence   # a lost glyph


# ------------------------------------------------------ the same reading, every layout
def test_pahk_reading_kinds_one_category_across_layouts(verdicts):
    """Per reading kind, the layouts that use it and the categories: one category each."""
    table = defaultdict(lambda: defaultdict(set))
    for v in verdicts:
        for k in v.readings_used:
            table[k.split(":")[0]][v.layout].add(v.category)
        if v.readings_used:
            assert v.category == expected(v.readings_used), (v.equation, v.component)
    for kind, per_layout in table.items():
        single = {c for v in verdicts for c in [v.category]
                  if [k.split(":")[0] for k in v.readings_used] == [kind]}
        assert len(single) <= 1, (kind, single)
        if single:
            assert single == {KIND[kind]}
    # the table origin pivot: convention on every layout with a table that needs it
    assert set(table["table_origin"]) >= {"FB1", "FH1", "CY"}
    assert table["rule1"].keys() >= {"MB1", "MH2", "FB1", "FH1", "CY"}
    for layout, cats in table["rule1"].items():
        assert cats <= {"simplification", "undecidable"}     # + a zero offset: undecidable


def test_every_non_identical_pahk_verdict_lists_its_readings(verdicts):
    for v in verdicts:
        if v.category != "identical":
            assert v.readings_tried, (v.equation, v.component)
            assert v.readings_used or v.category == "printing_error", (v.equation, v.component)


# ------------------------------------------------------------ injected errata (can fail)
def _with(eq_id, comp, text):
    data = copy.deepcopy(DATA)
    eq = next(e for e in data["equation"] if e["id"] == eq_id)
    eq["expr"][comp] = text
    eq.get("ocr", {}).pop(comp, None)
    return data


def test_injected_omission_sign_and_swap_are_named():
    good = next(e for e in DATA["equation"] if e["id"] == "4")["expr"]["dZ"]
    data = _with("4", "dZ", good.replace("- X*Ey(Y)", "+ X*Ey(Y)"))
    v = find(audit_pahk.audit(data, ["MB1"]), "4", "dZ")
    assert v.verdict == "differs" and "sign of -X*Ey(Y) flipped" in v.erratum
    data = _with("4", "dZ", good.replace("- X*Ey(Y)", "- X*Ex(Y)"))
    v = find(audit_pahk.audit(data, ["MB1"]), "4", "dZ")
    assert "Ex(Y) for Ey(Y)" in v.erratum
    data = _with("9", "dx(X)", "dx(X) - Zo*Ey(X) + Yo*Ez(X)")
    assert find(audit_pahk.audit(data, ["MB1"]), "9", "dx(X)").verdict == "identical"


def test_layout_filter(verdicts):
    only = audit_pahk.audit(DATA, ["MH2"])
    assert {v.layout for v in only} == {"MH2"}
    assert len(only) == sum(1 for v in verdicts if v.layout == "MH2")


# ------------------------------------------- numeric, independent of the derivation
def _printed_numeric(name, eq_id, q, errors, probe):
    model = volerr.load(name)
    eq = next(e for e in DATA["equation"] if e["id"] == eq_id)
    ns = {**{k: np.array([v]) for k, v in q.items()}, "Xp": probe[0], "Yp": probe[1],
          "Zp": probe[2], **_paper_values(model, errors)}
    return np.array([float(np.squeeze(_evaluate(eq.get("ocr", {}).get(c, eq["expr"][c]), ns)))
                     for c in ("dX", "dY", "dZ")])


@pytest.mark.parametrize("name,eq_id,agrees", [("MB1", "4", True), ("MH2", "7", True),
                                               ("FB1", "A2", False)])
def test_printed_volumetric_vs_independent_exact_chain(name, eq_id, agrees):
    rng = np.random.default_rng(7)
    model = volerr.load(name)
    layout = model.layout
    q = {a: rng.uniform(*layout.axes[a].travel) for a in layout.axis_names}
    probe = rng.uniform(-80, 80, 3)
    errors = {p: rng.normal(0, 20e-6 if p[1] in "ABC" else 5e-3) for p in model.parameters}
    ref = reference_chain.first_order_by_differences(layout, q, errors, probe)
    printed = _printed_numeric(name, eq_id, q, errors, probe)
    if agrees:
        np.testing.assert_allclose(printed, ref, atol=1e-9)
    else:
        # A2: own-travel terms of the table (Y*Ez(Y) in dX, -Y*Ex(Y) in dZ, paper signs)
        ez_y, ex_y = -errors["ECY"], -errors["EAY"]
        np.testing.assert_allclose(printed - ref, [q["Y"] * ez_y, 0, -q["Y"] * ex_y],
                                   atol=1e-9)


def test_spot_check_reports_rounding_level_and_real_differences():
    rows = {(r["equation"], r["component"]): r for r in spot_check(volerr.load("MB1"), n=50)}
    assert all(rows[("4", c)]["status"] == "agrees" for c in ("dX", "dY", "dZ"))
    assert rows[("5", "RX2")]["status"] == "agrees"         # term-wise quadrature
    assert rows[("5", "RX2")]["max_diff_exact_um"] > 1e-6    # ... not exact propagation
    rows = {(r["equation"], r["component"]): r for r in spot_check(volerr.load("FB1"), n=50)}
    assert rows[("A2", "dY")]["status"] == "agrees"
    assert rows[("A2", "dX")]["status"] == "differs"
    assert spot_check(volerr.load("MB2")) == []


# ------------------------------------------------------------------------------- CLI
def run(*args):
    """``volerr audit ARGS`` as ``python -m volerr`` runs it (exit code, stdout, stderr), in this
    process (``helpers.in_process.volerr``: ``main``'s exit code and lines; a warning a process
    would print counts as a line of stderr), without an interpreter importing sympy again."""
    return volerr_command("audit", *args)


def assert_clean_failure(proc, fragment=""):
    assert proc.returncode == 2, proc.stderr
    lines = [ln for ln in proc.stderr.splitlines() if ln.strip()]
    assert len(lines) == 1 and "Traceback" not in proc.stderr, proc.stderr
    assert fragment.lower() in lines[0].lower()


def in_process(capsys, *args):
    """``volerr audit ARGS`` through ``volerr.cli.main`` in this process (the parser, command and
    exit code of ``python -m volerr``, without a fresh interpreter importing sympy again)."""
    from types import SimpleNamespace

    from volerr.cli import main

    capsys.readouterr()
    code = main(["audit", *args])
    out, err = capsys.readouterr()
    return SimpleNamespace(returncode=code, stdout=out, stderr=err)


def test_cli_table_and_json(tmp_path, capsys):
    out = tmp_path / "audit.json"
    proc = in_process(capsys, "MB1", "--json", str(out))
    assert proc.returncode == 0, proc.stderr
    rows = json.loads(out.read_text())
    assert isinstance(rows, list) and rows
    keys = {"source", "equation", "layout", "verdict", "erratum", "evidence", "printed",
            "derived"}
    for r in rows:
        assert keys <= set(r) and r["layout"] == "MB1"
        assert r["verdict"] in ("identical", "differs")
    assert {r["equation"] for r in rows} == {"1", "3", "4", "5", "9"}   # 3: the Lz vector
    lines = proc.stdout.splitlines()
    row4 = next(ln for ln in lines if ln.split()[2:3] == ["4"])
    assert "identical" in row4
    assert any("omitted Abbe term +Yo*Ez(X)" in ln for ln in lines)


def test_cli_numeric(capsys):
    proc = in_process(capsys, "MB1", "--numeric", "--points", "20")
    assert proc.returncode == 0, proc.stderr
    assert "numeric spot check" in proc.stdout and "agrees" in proc.stdout


def test_cli_bad_input(tmp_path):
    assert_clean_failure(run("NOPE"), "unknown layout")
    assert_clean_failure(run("MB1", "--points", "0"), "points")
    data = resources.files("volerr.derive.audit") / "data" / "printed_pahk.toml"
    before = Path(str(data)).read_bytes()
    assert_clean_failure(run("MB1", "--json", str(data)), "refusing to overwrite")
    assert Path(str(data)).read_bytes() == before


def test_literal_eq3_lz_without_ocr_reading_is_not_a_valid_chain():
    data = copy.deepcopy(DATA)
    eq1 = next(e for e in data["equation"] if e["id"] == "1")
    eq1["ocr"].pop("L.z")                  # 'dx(Z) - Z' taken literally: a -Z nominal offset
    v = find(audit_pahk.audit(data, ["MB1"]), "1")
    assert v.verdict == "differs" and "cannot be evaluated" in v.erratum
    assert "nominal point" in v.evidence


# ------------------------------------------------- squareness as one line's slope (Pahk eq. 3)
def _first_order(expr, errs):
    import sympy as sp
    eps = sp.Symbol("eps")
    e = sp.expand(expr.subs({s: eps * s for s in errs}, simultaneous=True))
    return sp.expand(e.coeff(eps, 0) + e.coeff(eps, 1))


def test_trivial_alpha_rule_is_the_x_line_slope_on_mh2_and_mb1(verdicts):
    """Pahk eq. 3: Lx = [X + dx(X), dy(X) - alpha X, dz(X)], so alpha is minus the slope of the
    X line in y.  Written here from the chains of eq. 1 (MB1) and eq. 6 (MH2): the apparent
    alpha measured on the X line (-d dY/dX, the angular errors constants at the measuring
    position) minus the true one is the shift the rule removes.  MH2: no shift (the printed
    'alpha = alpha'); MB1: -Ez(Y) (the printed 'alpha = alpha + Ez(Yo)').  The MH2 verdict is a
    convention and must say that the same reading reproduces MB1's non-trivial rule."""
    import sympy as sp
    S = lambda n: sp.Symbol(n, real=True)  # noqa: E731
    X, Y, Z, alpha = S("X"), S("Y"), S("Z"), S("alpha")

    def T(a):
        ex, ey, ez = (S(f"E{c}({a})") for c in "xyz")
        return sp.Matrix([[1, -ez, ey], [ez, 1, -ex], [-ey, ex, 1]])
    d = {f"d{c}({a})": S(f"d{c}({a})") for c in "xyz" for a in "XYZ"}
    Lx = sp.Matrix([X + d["dx(X)"], d["dy(X)"] - alpha * X, d["dz(X)"]])
    Ly = sp.Matrix([d["dx(Y)"], Y + d["dy(Y)"], d["dz(Y)"]])
    Lz = sp.Matrix([d["dx(Z)"] - S("beta1") * Z, d["dy(Z)"] - S("beta2") * Z, Z + d["dz(Z)"]])
    P = sp.zeros(3, 1)
    chains = {"MB1": T("Y") * (T("X") * (T("Z") * P + Lz) + Lx) + Ly,
              "MH2": T("X") * (T("Z") * (T("Y") * P + Ly) + Lz) + Lx}
    errs = [s for s in chains["MB1"].free_symbols if "(" in s.name] + [alpha, S("beta1"),
                                                                         S("beta2")]
    shift = {}
    for name, A in chains.items():
        dY = _first_order(A[1] - Y, errs)
        shift[name] = sp.expand(-sp.diff(dY, X) - alpha)
    assert shift["MH2"] == 0 and shift["MB1"] == -S("Ez(Y)")
    rules = {e["layout"]: e["expr"]["alpha"] for e in DATA["equation"]
             if e["kind"] == "transfer" and "alpha" in e["expr"]}
    assert rules["MH2"] == "alpha" and rules["MB1"].replace(" ", "") == "alpha+Ez(Yo)"
    v = find(verdicts, "10", "alpha")
    assert v.category == "convention" and v.readings_used == ["line:X"]
    assert "Lx = [X + δx(X), δy(X) - αX, δz(X)]^T" in v.evidence
    assert "MB1 eq. 9: alpha = alpha + Ez(Yo)" in v.evidence
    assert not v.erratum.startswith("omitted")


def test_only_minimal_combinations_are_listed_and_pattern_noted(verdicts):
    """A3 dz(Z) = dz(Z): a sign reading that does not change this component is not counted,
    so no printing-error combination is listed beside the zero offsets; the same unchanged
    rule stands for four layouts in the data file."""
    v = find(verdicts, "A3", "dz(Z)")
    assert v.category == "undecidable"
    assert not any("inconsistent" in t for t in v.readings_tried)
    bare = sorted(e["layout"] for e in DATA["equation"]
                  if e["kind"] == "transfer" and e["expr"].get("dz(Z)") == "dz(Z)")
    assert bare == ["CY", "FB1", "FH1", "MB1"]
    for lay in bare:
        if lay != "FB1":
            assert lay in v.evidence


def _paper(text):
    """A printed expression of the data file -> sympy, own parse: 'dx(X)' -> symbol dx_X."""
    import re

    import sympy as sp
    return sp.sympify(re.sub(r"\b([Ed][xyz])\(([XYZ])o?\)", r"\1_\2", text))


def test_a8_dx_is_the_printed_chain_a7_to_first_order(verdicts):
    """Review 3 (#6): the CY chain A7 as printed, Ty{Tx A + Lx} + Ly = Tz P + Lz with its
    printed vectors, solved here for A to first order (T = I + [e]x, T^-1 = I - [e]x), gives
    A8's dX exactly and A8's dY not; the dX convention verdict says so, the dY one does not."""
    import sympy as sp
    e = next(x for x in DATA["equation"] if x["id"] == "A7")

    def T(a):
        ex, ey, ez = (sp.Symbol(f"E{c}_{a}") for c in "xyz")
        return sp.Matrix([[0, -ez, ey], [ez, 0, -ex], [-ey, ex, 0]])

    L = {k: sp.Matrix([_paper(t) for t in e["L"][k]]) for k in "xyz"}
    P = sp.Matrix(sp.symbols("Xp Yp Zp"))
    rhs = (sp.eye(3) + T("Z")) * P + L["z"]
    A = (sp.eye(3) - T("X")) * ((sp.eye(3) - T("Y")) * (rhs - L["y"]) - L["x"])
    X, Y, Z = sp.symbols("X Y Z")
    nominal = sp.Matrix([X, Y, Z]) + P
    errs = [s for s in A.free_symbols if "_" in s.name or s.name.startswith(("alpha", "beta"))]
    eps = sp.Symbol("eps")
    first = [sp.expand((A[i] - nominal[i]).subs({s: eps * s for s in errs},
                                                 simultaneous=True)).coeff(eps, 1)
             for i in range(3)]
    a8 = next(x for x in DATA["equation"] if x["id"] == "A8")["expr"]
    assert sp.expand(first[0] - _paper(a8["dX"])) == 0
    assert sp.expand(first[1] - _paper(a8["dY"])) != 0
    v = find(verdicts, "A8", "dX")
    assert v.category == "convention" and "eq. A7" in v.evidence
    assert "expanded to first order, gives exactly this dX" in v.evidence
    assert "gives exactly this dY" not in find(verdicts, "A8", "dY").evidence


def test_mb1_dx_rule_omission_pattern_across_layouts(verdicts):
    """Review 3 (#2): the bridge layouts MB1 (eq. 9) and FB1 (A3) print the identical
    'dx(X) - Zo*Ey(X)'; MH2, FH1 and CY print the yaw term in Yo*Ez(X) (read from the data
    here).  The verdict names the pattern and stays undecidable."""
    prints = {x["layout"]: x["expr"]["dx(X)"] for x in DATA["equation"]
              if x["kind"] == "transfer" and "dx(X)" in x["expr"]}
    assert prints["MB1"] == prints["FB1"] and "Ez(X)" not in prints["MB1"]
    keep = sorted(n for n, t in prints.items() if "Yo*Ez(X)" in t)
    assert keep == ["CY", "FH1", "MH2"]
    v = find(verdicts, "9", "dx(X)")
    assert v.category == "undecidable"
    assert f"the identical 'dx(X) = {prints['FB1']}' is printed for FB1 eq. A3" in v.evidence
    for n in keep:
        assert f"{n} eq." in v.evidence.split("Across the layouts")[1]
    assert ("Yo: the prints split by machine type (the arm and column layouts MH2, FH1, CY "
            "write a Yo term in dx(X), the bridge layouts MB1, FB1 write none)") in v.evidence
    assert "the category stays undecidable" in v.evidence


def _omission_sentences(verdicts):
    """(verdict, offset, error, argument, omitted layouts, layouts printing it exactly) of every
    cross-layout omission sentence."""
    out = []
    for v in verdicts:
        if "Across the layouts whose derived rule has the term " not in v.evidence:
            continue
        tail = v.evidence.split("Across the layouts whose derived rule has the term ")[1]
        m = re.match(r"(E[xyz])\(([XYZ])\)\*([XYZ]o) ", tail)
        if m is None:                         # a sum of two terms: not checked here
            continue
        omitted = re.search(r"it is omitted by ([^.]*)\.", tail).group(1)
        omit = re.findall(r"\b(MB1|FB1|MH2|FH1|CY) \(", omitted)
        stands = tail.split("the term stands in ")[1].split("; it is omitted")[0] \
            if "the term stands in " in tail else ""
        keep = re.findall(r"\b(MB1|FB1|MH2|FH1|CY) eq\. \S+ \('", stands)
        out.append((v, m.group(3), m.group(1), m.group(2), omit, keep))
    return out


def test_cross_layout_omission_sentences_are_true_to_the_prints(verdicts):
    """Review 4 (#8): every layout an omission sentence names as omitting the term prints no
    term with that offset and error motion at all (any argument), read from the data with a
    regex here; every layout named as printing it prints it exactly."""
    prints = {(x["layout"], k): t for x in DATA["equation"] if x["kind"] == "transfer"
              for k, t in x["expr"].items()}
    found = _omission_sentences(verdicts)
    assert len(found) >= 4
    for v, off, err, arg, omit, keep in found:
        key = v.component
        for n in omit:
            assert not re.search(rf"{off}\*{err}\(", prints[(n, key)]), (v.layout, key, n)
        for n in keep:
            assert f"{off}*{err}({arg})" in prints[(n, key)], (v.layout, key, n)


_LAYOUT_KIND = {"MB1": "bridge", "FB1": "bridge", "MH2": "arm", "FH1": "arm", "CY": "column"}


def test_zero_offset_weighing_is_one_rule_consistent_with_the_prints(verdicts):
    """Review 5 (#5, #15): every zero-offset undecidable verdict weighs each unprinted offset
    by one rule, recomputed here from the printed data alone (regex, no sympy): which layouts
    print a term with that offset in the same rule (a cut-off print excluded), whether they
    split by machine type (the kinds from Pahk's layout names, written out here), and which
    rules of the same equation write a term with that offset (``Yo*E..``; ``Ez(Yo)`` is an
    argument).  A split, or an equation with no such term, must read as a set-up, never as
    "points towards an omission"; the category stays undecidable."""
    eqs = [x for x in DATA["equation"] if x["kind"] == "transfer"]
    checked = 0
    for v in verdicts:
        zero = [r.split(":")[1] for r in v.readings_used if r.startswith("zero:")]
        if v.category != "undecidable" or not zero:
            continue
        eq = next(x for x in eqs if x["id"] == v.equation)
        key = v.component
        assert v.evidence.count(" Weighing (the same rule") == 1, (v.layout, key)
        for z in zero:
            part = re.split(rf"(?:\): |; ){z}: ", v.evidence)[1]
            part = re.split(r"; [XYZ]o: |\. The prints do not decide", part)[0]
            used = [k for k, t in eq["expr"].items() if re.search(rf"\b{z}\*[Ed][xyz]", t)]
            if used:
                assert f"eq. {eq['id']} writes {z} terms in {', '.join(used)}" in part
            else:
                assert f"eq. {eq['id']} writes no {z} term in any rule" in part
            other = [x for x in eqs if key in x["expr"] and key not in x.get("cut", {})]
            present = {x["layout"] for x in other if re.search(rf"\b{z}\b", x["expr"][key])
                       or (z == "Yo" and re.search(r"\bY\*E", x["expr"][key]))}
            omit = {x["layout"] for x in other} - present
            # only layouts whose derived rule has a term in z can omit it: dz(Z) etc. do for
            # every layout here; the sentence's own omit list must be a subset of ours
            split = bool(present) and len(omit) > 1 and not (
                {_LAYOUT_KIND[n] for n in present} & {_LAYOUT_KIND[n] for n in omit})
            assert ("the prints split by machine type" in part) == split, (v.layout, key, z)
            if split or not used or not present:
                assert "towards an omission" not in part, (v.layout, key, z)
                assert "fits a set-up" in part
            else:
                assert "points towards an omission of the printed term here" in part
            checked += 1
        assert "the category stays undecidable" in v.evidence
    assert checked >= 25
    for eq_id, key in (("9", "dz(X)"), ("A6", "dz(Y)")):      # the review's two entries
        ev = find(verdicts, eq_id, key).evidence
        assert "towards an omission here" not in ev and "omission of the printed term" not in ev


def test_fh1_dy_rule_names_mb1s_term_with_the_wrong_argument(verdicts):
    """Review 4 (#8): MB1 eq. 9 prints '- Xo*Ez(Z)' in dy(Y) (seed l. 174): the Xo yaw term is
    there with the argument Z, which MB1's own verdict finds a printing error.  The FH1 and CY
    sentences say so, and name the split by machine type (the bridge layouts write the term,
    FH1, MH2, CY do not); the same text when only FH1 is audited."""
    mb1 = next(x for x in DATA["equation"] if x["id"] == "9")["expr"]["dy(Y)"]
    assert "Xo*Ez(Z)" in mb1 and "Xo*Ez(Y)" not in mb1
    own = find(verdicts, "9", "dy(Y)").category
    assert own == "printing_error"
    for eq in ("A6", "A9"):
        ev = find(verdicts, eq, "dy(Y)").evidence
        assert (f"MB1 eq. 9 prints the term with another argument, Xo*Ez(Z) for Xo*Ez(Y) "
                f"('dy(Y) = {mb1}'; that layout's own verdict on dy(Y): {own})") in ev
        omitted = ev.split("it is omitted by ")[1].split(".")[0]
        assert "MB1" not in omitted and "FB1" not in omitted
        assert ("the prints split by machine type (the bridge layouts MB1, FB1 write an Xo "
                "term in dy(Y), the arm and column layouts") in ev
    alone = audit_pahk.audit(DATA, ["FH1"])
    assert next(v for v in alone if v.equation == "A6" and v.component == "dy(Y)").evidence \
        == find(verdicts, "A6", "dy(Y)").evidence


def test_worst_case_names_the_machine_it_scales(verdicts):
    """Review 3 (#3, #6, #11): a worst case on a layout other than MB1 says whose travels it
    takes (CMM A's), the layout's own machine in Pahk (MH2: CMM B) or that Pahk has none, and
    whether the travels enter the term at all."""
    v = find(verdicts, "10", "dy(X)")            # MH2, term -Xo*Ez(X): offsets only
    assert "Pahk's own MH2 machine is CMM B (1100 mm cube)" in v.evidence
    assert "depends on the offsets only" in v.evidence
    v = find(verdicts, "A8", "dX")               # CY, term -Ez(Y)*Y: CMM A's Y travel
    assert "Pahk describes no CY machine" in v.evidence
    assert "the travel of Y (575 mm) enters the size" in v.evidence
    assert v.dropped_um == pytest.approx(575 * 10e-6 * 1e3)
    v = find(verdicts, "9", "dx(X)")             # MB1 is CMM A itself
    assert "this MB1 layout's own machine" in v.evidence


def test_a6_squareness_rules_read_at_the_offsets_is_a_named_reading(verdicts):
    """Review 4 (#18): of the printed squareness rules only A6 writes travel arguments
    (Ey(Y) - Ey(X), read from the data here); its verdicts name the reading 'at the offsets'
    in readings_used and state the substitution where the identity with the print is claimed,
    and the identity holds with that substitution (sympy here); the other layouts' squareness
    verdicts name A6 as the exception and carry no such reading."""
    squ = ("alpha", "a", "beta1", "beta2")
    travel = {x["id"] for x in DATA["equation"] if x["kind"] == "transfer"
              for k, t in x["expr"].items()
              if k in squ and re.search(r"[Ed][xyz]\([XYZ]\)", t)}
    assert travel == {"A6"}
    import sympy as sp
    a6 = next(x for x in DATA["equation"] if x["id"] == "A6")["expr"]
    for key in ("alpha", "beta1", "beta2"):
        v = find(verdicts, "A6", key)
        assert any(r.startswith("notation:A6") for r in v.readings_used), key
        assert "eq. A6 is the exception" in v.evidence
        moves = sorted(set(re.findall(r"([Ed][xyz])\(([XYZ])\)", a6[key])))
        subst = ", ".join(f"{e}({a}) as {e}({a}o)" for e, a in moves)
        assert f"(expand(alternative - printed) == 0, with the print's {subst})" in v.evidence
        names = lambda t: re.sub(r"([Ed][xyz])\(([XYZ])o?\)", r"\1_\2", t)  # noqa: E731
        assert sp.expand(sp.sympify(names(v.alternative)) - sp.sympify(names(a6[key]))) == 0
        assert v.printed == a6[key]                     # the print quoted as printed
    for x in DATA["equation"]:
        if x["kind"] != "transfer" or x["id"] == "A6":
            continue
        for key in squ:
            if key not in x["expr"]:
                continue
            v = find(verdicts, x["id"], key)
            if v.category != "identical":
                assert not any(r.startswith("notation:A6") for r in v.readings_used)
                assert "eq. A6 (FH1) prints travel arguments instead" in v.evidence


def test_omitted_terms_in_a_damaged_equation_name_the_extraction(verdicts):
    """Review 4 (#19): in eq. 10 two rules are visibly cut off and one lost a subscript (read
    from the data here), so for the rules there that omit terms an extraction that dropped
    them is a third explanation, named with the damaged rules; eq. 9 has no damaged rule and
    its omissions name none."""
    e10 = next(x for x in DATA["equation"] if x["id"] == "10")
    cut = sorted(e10.get("cut", {}))
    assert len(cut) == 2
    for key in ("dx(Y)", "dy(Y)"):
        v = find(verdicts, "10", key)
        assert v.category == "undecidable"
        ev = v.evidence
        assert "A third explanation: the extraction of this same eq. 10 is visibly damaged" in ev
        for k in cut:
            assert f"{k} '{e10['expr'][k]}' cut off" in ev
    e9 = next(x for x in DATA["equation"] if x["id"] == "9")
    assert not e9.get("cut") and not e9.get("ocr")
    assert "A third explanation" not in find(verdicts, "9", "dz(Z)").evidence


def test_undecidable_alternative_and_dropped_mean_what_formats_md_says(verdicts):
    """Review 5 (schema): docs/formats.md describes 'alternative'/'dropped' for undecidable
    verdicts too.  A zero-offset verdict's alternative reproduces the print once the offset is
    0 in the derivation (recomputed with sympy here: derived with the offset set to 0 equals
    the print, and dropped == derived - alternative); a verdict no reading reproduces names its
    alternative as the closest reading and leaves dropped empty."""
    import sympy as sp
    from volerr.derive.audit.pahk_model import parse, printed_component
    text = (resources.files("volerr") / "data" / "formats.md").read_text("utf-8")
    assert "an `undecidable` verdict that rests on an unstated zero offset" in text
    n_zero = n_close = 0
    for v in verdicts:
        if v.category != "undecidable" or not v.alternative:
            continue
        zero = [r.split(":")[1] for r in v.readings_used if r.startswith("zero:")]
        if zero:
            eq = next(x for x in DATA["equation"] if x["id"] == v.equation)
            printed = printed_component(eq, v.component)[0]    # a lost glyph read as noted
            derived, alt = parse(v.derived), parse(v.alternative)
            assert sp.expand(derived - alt - parse(v.dropped)) == 0, (v.equation, v.component)
            assert sp.expand(alt - printed) == 0, (v.equation, v.component)
            at_zero = derived.subs({x: 0 for x in derived.free_symbols if str(x) in zero})
            if v.readings_used == [f"zero:{z}" for z in zero]:     # the offset alone
                assert sp.expand(at_zero - alt) == 0, (v.equation, v.component)
            else:                     # with rule (1): the offset's terms are among the dropped
                assert sp.expand(at_zero - alt) != sp.expand(derived - alt)
            n_zero += 1
        else:
            assert v.dropped == "" and "closest" in v.evidence, (v.equation, v.component)
            n_close += 1
    assert n_zero >= 25 and n_close >= 1


def test_a6_dy_x_is_the_lone_outlier_of_its_rule(verdicts):
    """Review 5 (#2): every other layout prints dy(X) with one text (read from the data), A6
    another; the verdict says so and stays undecidable; no other rule verdict claims it."""
    prints = {x["id"]: x["expr"]["dy(X)"] for x in DATA["equation"]
              if x["kind"] == "transfer" and "dy(X)" in x["expr"]}
    others = {k: t for k, t in prints.items() if k != "A6"}
    assert len(set(others.values())) == 1 and prints["A6"] not in others.values()
    v = find(verdicts, "A6", "dy(X)")
    assert v.category == "undecidable"
    assert (f"All {len(others)} other layouts print 'dy(X) = {next(iter(others.values()))}'"
            in v.evidence and "lone outlier" in v.evidence)
    assert [w for w in verdicts if "lone outlier" in w.evidence] == [v]


def test_chain_in_the_polynomial_ring_is_the_sympy_chain():
    """The chains' first-order error computed in a polynomial ring is the sympy-matrix result,
    expression for expression; a relabelled chain whose nominal point is wrong raises the
    same error; what the ring cannot take (a damaged vector) is left to sympy."""
    import sympy as sp

    from volerr.derive.audit import pahk_chain

    by_id = {e["id"]: e for e in DATA["equation"]}
    seen = {"result": 0, "raised": 0}
    for eq in [e for e in DATA["equation"] if e["id"] in ("1", "A1")]:
        L, _, _ = pahk_chain.chain_vectors(eq, by_id)
        for _, lhs, rhs, LL, _ in pahk_chain.chain_readings(eq, L)[::5]:
            outcome = []
            for f in (pahk_chain._chain_error_ring, pahk_chain._chain_error_sympy):
                try:
                    outcome.append([sp.srepr(x) for x in f(lhs, rhs, LL)])
                except ValueError as exc:
                    outcome.append(str(exc))
            assert outcome[0] == outcome[1], (lhs, rhs)
            seen["raised" if isinstance(outcome[0], str) else "result"] += 1
    assert seen["result"] and seen["raised"]
    bad = {"x": ["X +", "0", "0"], "y": ["0", "Y", "0"], "z": ["0", "0", "Z"]}
    assert pahk_chain._chain_error_ring("A", "Lx + Ly + Lz", bad) is None
