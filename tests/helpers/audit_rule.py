"""The audit's category rule restated independently of volerr.derive.audit (for the tests)."""

#: the rule, restated independently: kind of a key prefix -> category
KIND = {"table_origin": "convention", "geometry": "convention", "flip": "convention",
        "line": "convention", "notation": "convention", "rounding": "convention",
        "rule1": "simplification", "termwise": "simplification",
        "stated": "simplification", "ocr": "extraction", "zero": "undecidable",
        "glyph": "undecidable", "missing": "undecidable", "stacking": "printing_error",
        "inconsistent": "printing_error", "copy": "printing_error"}


def expected(keys) -> str:
    cats = {KIND[k.split(":")[0]] for k in keys}
    if not cats:
        return "identical"
    if "printing_error" in cats:                    # a reading that contradicts the text
        return "printing_error"
    if "undecidable" in cats:                       # rests on an unstated assumption
        return "undecidable"
    if "simplification" in cats:
        return "simplification"
    if "convention" in cats:
        return "convention"
    return "extraction"
