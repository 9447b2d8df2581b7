"""The DMU 50 audit provider: Sorby's formulas and the thesis' chain against the derivation."""

import copy
import tomllib
from importlib import resources

import numpy as np
import pytest

from volerr.derive import audit_dmu50


@pytest.fixture(scope="module")
def printed():
    with (resources.files("volerr") / "data" / audit_dmu50.DATA_FILE).open("rb") as fh:
        return tomllib.load(fh)


@pytest.fixture(scope="module")
def verdicts(printed):
    return {v.equation: v for v in audit_dmu50.audit(printed, None)}


def test_forward_and_inverse_formulas_are_identical(verdicts):
    for n in range(19, 30):
        v = verdicts[f"eq. 3.{n}"]
        assert v.verdict == "identical", (v.equation, v.evidence)
        assert v.layout == "DMU50" and v.source


@pytest.mark.parametrize("equation,erratum", [
    ("eq. 3.31", "row 3 missing"),
    ("eq. 3.32", "sign error in 1 entry"),
    ("eq. 3.33", "row 3 printed twice"),
    ("eq. 3.37", "T_3^2, T_2^1 printed as T_2^2; T_0^t printed as T_1^d"),
    ("error chain after 3.37", "T_4^5 printed as T_3^4"),
    ("Listing 3.3 line 46 (T_r)", "leading minus sign"),
    ("Listing 3.3 rot_y", "rot_y turns by -a"),
    ("Listing 3.3 T_er E_CB", "E_CB read from the data of E_BB"),
    ("Listing 3.3 T_er E_CC", "E_CC read from the data of E_BC"),
    ("Listing 3.3 T_er (error model)", "errors applied in the wrong frame"),
])
def test_printing_errors_are_named(verdicts, equation, erratum):
    v = verdicts[equation]
    assert v.verdict == "differs" and v.erratum == erratum, (v.erratum, v.evidence)
    assert v.evidence and v.printed and v.derived


@pytest.mark.parametrize("name", ["3.30", "3.34", "3.35", "3.36"])
def test_correct_matrices_are_identical(verdicts, name):
    assert verdicts[f"eq. {name}"].verdict == "identical"


def test_listing_matrices_match_the_derived_factors(verdicts):
    for n in ("T_d", "T_45", "T_B", "T_n45", "T_nd", "T_C", "rot_x", "rot_z"):
        assert verdicts[f"Listing 3.3 {n}"].verdict == "identical"


def test_a_changed_print_is_detected(printed):
    """The verdicts come from the comparison, not from a list: flip one sign in eq. 3.22 and
    one entry of eq. 3.30."""
    bad = copy.deepcopy(printed)
    bad["formula"] = [f for f in bad["formula"] if f["id"] == "3.22"]
    bad["formula"][0]["expr"] = bad["formula"][0]["expr"].replace("+ X*cos(C)*cos(B)",
                                                                  "- X*cos(C)*cos(B)")
    bad["matrix"] = [m for m in bad["matrix"] if m["id"] == "3.30"]
    bad["matrix"][0]["rows"][2][3] = "-d"
    for k in ("product", "listing"):
        bad.pop(k)
    vs = {v.equation: v for v in audit_dmu50.audit(bad, ["DMU50"])}
    assert vs["eq. 3.22"].verdict == "differs"
    assert vs["eq. 3.30"].verdict == "differs" and "sign error" in vs["eq. 3.30"].erratum
    assert audit_dmu50.audit(bad, ["MB1"]) == []


def _rx(a):
    c, s = np.cos(a), np.sin(a)
    return np.array([[1, 0, 0, 0], [0, c, -s, 0], [0, s, c, 0], [0, 0, 0, 1.0]])


def test_repetitions_within_an_image_are_undecidable(verdicts, printed):
    """The T_4^5 of the chain 'updated' with the errors is T_3^4 = Rx(-45 deg) (computed here),
    the factor printed just before it in the same image; the data sources of E_CB and E_CC
    repeat the file name of the line above.  Repetitions within an image: print or extraction
    (the cross-copy rule does not decide them), so undecidable with both explanations."""
    item = next(m for m in printed["matrix"] if m["id"] == "error chain after 3.37")
    env = {"c45": np.sqrt(0.5), "s45": np.sqrt(0.5)}
    m = np.array([[eval(e, {}, env) for e in r] for r in item["rows"]])  # noqa: S307
    assert np.allclose(m, _rx(-np.pi / 4))
    v = verdicts["error chain after 3.37"]
    assert v.category == "undecidable" and v.readings_used[0].startswith("glyph:")
    assert "For the print" in v.evidence and "For the extraction" in v.evidence
    assert "What would decide" in v.evidence
    texts = printed["listing"]["sources_text"]
    for name, (above, line) in texts.items():
        src = printed["listing"]["sources"][name]
        # the quoted file name of this line is the one of the line above (braces of the
        # LaTeX rendering dropped), and not the parameter's own
        quoted = [t.split("'")[1].replace("{", "").replace("}", "") for t in (above, line)]
        assert quoted[0][:4] == quoted[1][:4] == src[:4] != name
        v = verdicts[f"Listing 3.3 T_er {name}"]
        assert v.category == "undecidable" and "For the extraction" in v.evidence


def test_t_er_effects_state_their_frame(verdicts):
    v = verdicts["Listing 3.3 T_er (error model)"]
    assert v.category == "simplification"
    assert "workpiece (table) frame" in v.evidence and "not as an approximation" in v.evidence
