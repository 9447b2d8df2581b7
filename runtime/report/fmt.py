"""Numbers and units as every page and certificate prints them."""

from __future__ import annotations


def unit(u: str) -> str:
    """A unit as printed on a page (``um`` -> ``µm``, ``urad`` -> ``µrad``, ``um/mm`` ->
    ``µm/mm``, ``deg`` -> ``°``)."""
    import re

    text = re.sub(r"\bu(m|rad)\b", "\u00b5\\1", str(u or ""))
    return "\u00b0" if text == "deg" else text


def number(v, digits: int = 4) -> str:
    """A value with ``digits`` significant digits, no negative zero, "-" when missing."""
    if v is None:
        return "\u2013"
    try:
        x = float(v)
    except (TypeError, ValueError):
        return str(v)
    text = f"{x:.{digits}g}"
    return text[1:] if text.startswith("-") and float(text) == 0 else text


def value_for(v, u, digits: int = 4) -> str:
    """A value beside its standard uncertainty ``u`` (same unit): :func:`number`, with more
    decimals where those would hide what ``u`` resolves (down to u's second significant
    digit): 399.999965 mm with u = 0.0013 mm reads "400.0000", not "400" (seen on the
    uncertainty certificate)."""
    import math

    text = number(v, digits)
    try:
        x, s = float(v), float(u)
    except (TypeError, ValueError):
        return text
    if "e" in text or not (math.isfinite(x) and math.isfinite(s) and s > 0):
        return text
    need = max(0, 1 - math.floor(math.log10(s)))
    have = len(text.partition(".")[2])
    return f"{x:.{need}f}" if need > have else text


#: the labels of the JSON keys a page shows by name (the loop's evidence ...): words, the
#: unit after a slash; a key not listed is spelt out by :func:`words`
LABELS = {
    "delta_bic": "BIC change (\u0394BIC; negative: better)",
    "delta_bic_given_others": "BIC change given the other effects",
    "delta_bic_vs_replaced": "BIC change against the effects it replaces",
    "rss_reduction_fraction": "share of the residual sum of squares removed",
    "cv_rms_um": "cross-validated RMS / \u00b5m",
    "cv_rms_before_um": "cross-validated RMS before / \u00b5m",
    "cv_rms_after_um": "cross-validated RMS after / \u00b5m",
    "cv_paired_t": "paired t of the cross-validated errors (before \u2212 after)",
    "step": "selection step",
    "indistinguishable_from": "indistinguishable on the screening subset from",
    "same_cause_as": "same cause (parameter and covariate) as",
    "replaces": "replaces",
    "tau": "time constant",
    "max_length": "largest length of the volumetric error",
    "rms_length": "RMS length of the volumetric error",
    "r_eff": "effective stylus radius r_eff",
    **{f"max_abs_d{a}": f"largest |d{a}|" for a in "xyz"},
    **{f"random_max_{a}": f"random component, largest in {a} (k = 1)" for a in "xyz"},
    "contribution_rms_um": "contribution of the effect, RMS / \u00b5m",
    "contribution_max_um": "contribution of the effect, largest / \u00b5m",
}

#: abbreviations of key words spelt out, and the units a key may end in
_WORDS = {"cv": "cross-validated", "rms": "RMS", "abs": "absolute", "bic": "BIC",
          "std": "standard uncertainty",
          "mae": "MAE", "n": "number of", "max": "largest", "min": "smallest"}
_UNIT_WORDS = {"um": "\u00b5m", "urad": "\u00b5rad", "mm": "mm", "s": "s", "deg": "\u00b0",
               "h": "h", "K": "K", "C": "\u00b0C", "ppm": "ppm"}


def words(key: str) -> str:
    """A JSON key as a label in words: :data:`LABELS`, else its parts with the abbreviations
    spelt out and a trailing unit after a slash (``"rms_after_um"`` -> ``"RMS after / µm"``)."""
    key = str(key)
    if key in LABELS:
        return LABELS[key]
    parts = key.split("_")
    tail = ""
    if len(parts) > 1 and parts[-1] in _UNIT_WORDS:
        tail = f" / {_UNIT_WORDS[parts.pop()]}"
    return " ".join(_WORDS.get(p, p) for p in parts) + tail
