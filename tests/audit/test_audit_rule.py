"""The category rule of the audit (derive.audit.framework.PRIORITY_RULE): every combination of
readings is tried and the category follows fixed priorities; one reading key has one category on
every layout and in every document; every verdict lists its readings. The expected categories are
derived here from the rule's definition (not through the audit's own search)."""

from __future__ import annotations

from collections import defaultdict
from importlib import resources

import pytest

from volerr.derive.audit import framework as A

from helpers.audit_rule import KIND, expected


def test_reading_kinds_match_the_documented_rule():
    assert {k: A.READING_KINDS[k] for k in KIND} == {
        k: {"convention": "convention", "simplification": "simplification",
            "extraction": "extraction", "undecidable": "assumption",
            "printing_error": "other_machine"}[v] for k, v in KIND.items()}
    for keys in (["table_origin"], ["rule1", "zero:Yo"], ["flip:a", "line:X"], ["ocr:x"],
                 ["ocr:x", "flip:y"], ["stated:s", "flip:x"], ["inconsistent:x", "glyph:y"],
                 ["missing:m"], []):
        assert A.category_of(keys) == expected(keys), keys


def test_best_combination_prefers_stated_readings_then_fewest():
    hits = [(("zero:Yo",), "a"), (("rule1", "line:X"), "b"), (("table_origin",), "c")]
    assert A.best_combination(hits)[1] == "c"          # convention, 1 reading
    hits = [(("zero:Xo", "zero:Yo"), "a"), (("rule1", "zero:Yo"), "b")]
    assert A.best_combination(hits)[1] == "b"          # fewer unstated assumptions
    hits = [(("inconsistent:alpha",), "a"), (("zero:Yo",), "b")]
    assert A.best_combination(hits)[1] == "b"          # a contradiction only diagnoses
    assert A.best_combination([]) is None


def test_the_rule_is_documented_in_formats_and_the_module():
    text = (resources.files("volerr") / "data" / "formats.md").read_text("utf-8")
    sec = text[text.index("## Audit verdicts (audit)"):]
    rule = sec[sec.index("The category follows this rule"):]
    order = [rule.index(f"{i}. `{c}`") for i, c in enumerate(
        ("identical", "convention", "extraction", "printing_error", "undecidable"), start=1)]
    assert order == sorted(order)
    for k in KIND:
        assert f"`{k}" in sec, k
    assert "readings_tried" in sec and "readings_used" in sec
    # the recurrence of a failure at the same place in two images is an assumption (review 3)
    cross = " ".join(sec[sec.index("Cross-copy rule"):].split())
    assert "is an assumption the documents neither show nor exclude" in cross
    assert "weighs towards the author's source but does not decide" in cross
    assert "recurs at the same place" not in " ".join(A.PRIORITY_RULE.split()).replace(
        "recurs at the same place in another image of the same layout is an assumption", "")


@pytest.mark.slow
@pytest.mark.xdist_group("full_audit")
def test_every_document_one_category_per_reading_kind(full_audit):
    """All verdicts of both documents: category == the rule applied to the keys it rests on,
    and, per reading kind, the categories seen across layouts and documents."""
    _, entries, _ = full_audit
    per_kind = defaultdict(lambda: defaultdict(set))
    for e in entries:
        assert "readings_tried" in e and "readings_used" in e
        if e["category"] != "identical":
            assert e["readings_tried"], (e["equation"], e["component"])
        if e["readings_used"]:
            assert e["category"] == expected(e["readings_used"]), (e["equation"], e["component"])
            if len({k.split(":")[0] for k in e["readings_used"]}) == 1:
                per_kind[e["readings_used"][0].split(":")[0]][e["layout"]].add(e["category"])
    for kind, layouts in per_kind.items():
        cats = set().union(*layouts.values())
        assert cats == {KIND[kind]}, (kind, dict(layouts))
    assert len(per_kind["glyph"]) >= 3          # glyph-level defects in several places
