"""Every fit judged by its residual, and changes beyond a limit only with consent: the one
rule that ``calibrate``, ``identify``, ``ballbar evaluate``, ``check`` and ``loop`` apply
before they write anything a controller or a later command would use.

**The residual rule.**  A fit's weighted residual sum of squares ``chi2 = sum (r / u)^2``
(``r`` reading minus model, ``u`` the reading's declared standard uncertainty, both in the
reading's unit) is, for readings that agree with the model within their uncertainty, a
chi-square variable with ``dof`` = readings - determined unknowns degrees of freedom.  Its
Birge ratio squared ``chi2 / dof`` is about 1; the p-value is ``P(chi2_dof >= chi2)``
(:func:`scipy.stats.chi2.sf`).  A fit is **far above** its declared uncertainty, and refused,
when both

    p < P_REFUSE (1e-6)   and   chi2 / dof > RATIO_REFUSE (4: residuals twice u, RMS)

hold: the p-value alone would refuse a large campaign for a scatter 10 % above ``u``; the
ratio alone a small one for chance.  Far above, nothing is written into error tables, maps,
compensations or controller tables and the command exits 2 with one line
(:func:`require_fit`) naming chi2/dof, p and what is likely (a unit, a sign, swapped axes, the
wrong layout, an effect the model lacks: ``volerr loop``), unless the user forces it
(``--accept-residual``); then the verdict is ``"forced"`` and every output says so.  Verdicts:
``"consistent"`` (p >= 1e-3 or chi2/dof <= 1.5), ``"above"`` (clearly above but not far:
reported, written), ``"refused"`` and ``"forced"``.

Where a file declares no uncertainty the instrument's default is assumed (deviations 1 um per
coordinate, ballbar 0.5 um, sphere 1 um, interferometer 0.2 um / 0.5 urad, distances
0.3 um + 0.3 um/m, artifact 0.5 um; tracker points without ``--tracker``: :data:`
TRACKER_U_UM`); the JSON's ``"fit"`` says which (``"u"``).

**Changes beyond a limit need consent** (the ``maxModification`` rule of Heidenhain's
KinematicsOpt cycle): ``--max-change "EX0C=20 um,EA0B=50 urad"`` (a bound per parameter; a
bare ``"20 um"`` or ``"50 urad"`` bounds every translational or angular parameter; units
required) against a reference's values; a parameter moved further is refused with one line
(:func:`require_consent`) naming it, the old and new value and the limit, until the user gives
``--accept-change``.  (The controller's own figure: HEIDENHAIN iTNC 530 HSCI technical manual,
July 2013, sec. 6.5 "Tilting and swivel axes", MP6600 "KinematicsOpt: Amount of change",
0.010 to 1.000 mm, default 0.05 mm; its newer controllers call it ``maxModification``.)
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from .errors import InputError, require, require_file
from .units import parse_number

#: p-value below which (together with :data:`RATIO_REFUSE`) a fit is refused
P_REFUSE = 1e-6
#: chi2 per degree of freedom above which (together with :data:`P_REFUSE`) a fit is refused
RATIO_REFUSE = 4.0
#: a fit is "consistent" when p >= P_CONSISTENT or chi2/dof <= RATIO_CONSISTENT
P_CONSISTENT = 1e-3
RATIO_CONSISTENT = 1.5
#: per-coordinate standard uncertainty (um) assumed for tracker points without --tracker:
#: the AT960 angle-encoder MPE at 3 m (15 um + 6 um/m) / sqrt(3)
TRACKER_U_UM = (15.0 + 6.0 * 3.0) / math.sqrt(3.0)
#: what is likely when a fit is far above its declared uncertainty
LIKELY = ("readings in the wrong unit (mm for um, a factor of 1000 or of 25.4), a sign "
          "(a reading, an offset or a whole instrument sign-flipped), swapped axis columns, "
          "the wrong layout, or an effect the model lacks (run 'volerr loop' on these files)")
#: the option that writes a refused fit anyway
FORCE_OPTION = "--accept-residual"
RULE = (f"refused when p < {P_REFUSE:g} and chi2/dof > {RATIO_REFUSE:g} (chi2 = sum (r/u)^2 "
        f"with the readings' declared standard uncertainty u); {FORCE_OPTION} writes it, "
        f"marked as forced")


@dataclass(frozen=True)
class FitQuality:
    """The residual of one fit against the readings' declared uncertainty.

    ``chi2`` (dimensionless: residuals in units of their u), ``dof`` (readings minus
    determined unknowns, >= 1), ``u`` one phrase saying which uncertainty was used (declared or
    assumed), ``forced`` True when a refused fit was written on the user's word."""

    chi2: float
    dof: int
    u: str
    forced: bool = False

    @property
    def chi2_per_dof(self) -> float:
        """The Birge ratio squared (1 for readings that agree within u)."""
        return self.chi2 / max(self.dof, 1)

    @property
    def p_value(self) -> float:
        """``P(chi2_dof >= chi2)``: small when the residual is above the declared u."""
        # scipy.stats.chi2.sf is this function (chdtrc(df, x), 1 for x <= 0); scipy.special
        # imports in a quarter of the CPU time of scipy.stats (0.2 against 0.8 s)
        from scipy.special import chdtrc

        return float(chdtrc(max(self.dof, 1), max(self.chi2, 0.0)))

    @property
    def far_above(self) -> bool:
        """The refusal rule of the module docstring."""
        return self.p_value < P_REFUSE and self.chi2_per_dof > RATIO_REFUSE

    @property
    def verdict(self) -> str:
        """consistent | above | refused | forced (module docstring)."""
        if self.far_above:
            return "forced" if self.forced else "refused"
        if self.p_value >= P_CONSISTENT or self.chi2_per_dof <= RATIO_CONSISTENT:
            return "consistent"
        return "above"

    def to_dict(self) -> dict:
        """``{"chi2_per_dof", "dof", "p_value", "verdict", "chi2", "u", "rule"}`` (JSON)."""
        return {"chi2_per_dof": round(self.chi2_per_dof, 4), "dof": int(self.dof),
                "p_value": float(f"{self.p_value:.4g}"), "verdict": self.verdict,
                "chi2": round(self.chi2, 4), "u": self.u, "rule": RULE}

    def line(self) -> str:
        """One console line: chi2/dof, dof, p and the verdict."""
        text = (f"fit: chi2/dof = {self.chi2_per_dof:.3g} (dof {self.dof}, p = "
                f"{self.p_value:.2g}; {self.u}): {self.verdict}")
        if self.verdict == "forced":
            text += (f" -- FORCED: the residual is far above the readings' uncertainty, "
                     f"written because of {FORCE_OPTION}")
        return text

    def marked(self) -> "FitQuality":
        """This fit written on the user's word (``forced`` when it is far above)."""
        return FitQuality(self.chi2, self.dof, self.u, True)


def judge(chi2: float, dof: float, u: str) -> FitQuality:
    """The :class:`FitQuality` of a fit: ``chi2`` the weighted residual sum of squares in
    units of the readings' standard uncertainty, ``dof`` its degrees of freedom, ``u`` which
    uncertainty (e.g. ``"u declared in the files"``, ``"u assumed 1 um (none declared)"``)."""
    c = float(chi2)
    require(math.isfinite(c), "the fit's residual is not finite (NaN or overflow in the "
                              "readings)")
    return FitQuality(max(c, 0.0), max(int(round(dof)), 1), u)


def require_fit(fit: FitQuality | None, accept: bool, where: str) -> FitQuality | None:
    """Refuse a fit far above its declared uncertainty (InputError, one line naming chi2/dof,
    p and what is likely) unless ``accept`` (``--accept-residual``); returns the fit, marked
    forced when it was accepted.  ``where``: the command and its files, e.g. ``"calibrate
    a.csv"``."""
    if fit is None or not fit.far_above:
        return fit
    if accept:
        return fit.marked()
    raise InputError(
        f"{where}: the fit's residual is far above the readings' declared uncertainty "
        f"(chi2/dof = {fit.chi2_per_dof:.3g}, dof {fit.dof}, p = {fit.p_value:.2g}; {fit.u}); "
        f"likely {LIKELY}; nothing written ({FORCE_OPTION} writes it, marked as forced)")


def require_writable(fit: FitQuality | None, accept: bool, what: str) -> None:
    """The API's guard before an error table or map is written: a fit the rule refuses
    (verdict ``refused``: far above and not yet accepted) is not written unless ``accept``
    (then it is marked forced by the command, :func:`gate`).  One-line InputError."""
    if fit is not None and fit.verdict == "refused" and not accept:
        raise InputError(f"{what}: not written: the fit's residual is far above the readings' "
                         f"declared uncertainty (chi2/dof = {fit.chi2_per_dof:.3g}, p = "
                         f"{fit.p_value:.2g}); accept_residual=True ({FORCE_OPTION}) writes "
                         f"it")


def forced_note(fit: FitQuality | None) -> str | None:
    """The sentence every output of a forced fit carries (None when not forced)."""
    if fit is None or fit.verdict != "forced":
        return None
    return (f"FORCED: fit residual far above the declared uncertainty (chi2/dof = "
            f"{fit.chi2_per_dof:.3g}, p = {fit.p_value:.2g}), written because of "
            f"{FORCE_OPTION}")


def gate(data: dict, fit: FitQuality | None, accept: bool, where: str,
         key: str = "fit") -> FitQuality | None:
    """:func:`require_fit` on a result's JSON ``data``: refuses (InputError) or, when
    accepted, sets ``data[key]`` to the forced verdict and ``data["forced"]`` to
    :func:`forced_note`, the sentence every output then carries (``key``: ``"fit"``;
    ``identify``, whose ``"fit"`` lists its ``--fit`` error functions: ``"fit_quality"``)."""
    fit = require_fit(fit, accept, where)
    if fit is not None:
        data[key] = fit.to_dict()
        note = forced_note(fit)
        if note:
            data["forced"] = note
    return fit


def fit_html(d: dict) -> str:
    """A result's ``d["fit"]`` (and, when forced, ``d["forced"]`` in red) as HTML
    paragraphs; "" without a fit."""
    import html

    f = d.get("fit")
    if not isinstance(f, dict) or "chi2_per_dof" not in f:
        return ""
    out = (f"<p>Fit: chi2/dof = {f['chi2_per_dof']:.3g} (dof {f['dof']}, p = "
           f"{f['p_value']:.2g}; {html.escape(f['u'])}): <b>{html.escape(f['verdict'])}</b>"
           f"</p>\n")
    if d.get("forced"):
        out += f"<p style=\"color:#b00\"><b>{html.escape(d['forced'])}</b></p>\n"
    return out


# --- changes beyond a limit ------------------------------------------------------------

#: unit -> (dimension, factor to the report unit um / urad)
_UNITS = {"um": ("length", 1.0), "mm": ("length", 1e3), "nm": ("length", 1e-3),
          "urad": ("angle", 1.0), "mrad": ("angle", 1e3), "rad": ("angle", 1e6),
          "arcsec": ("angle", math.pi / 180 / 3600 * 1e6),
          "um/mm": ("slope", 1.0), "um/m": ("slope", 1e-3), "ppm": ("slope", 1e-3)}
_REPORT = {"um": "length", "urad": "angle", "um/mm": "slope"}


def parse_max_change(text: str, option: str = "--max-change") -> dict:
    """``{NAME or "um" / "urad" / "um/mm" (a bound for every parameter of that unit): limit
    in the report unit (um, urad, um/mm)}`` of ``"EX0C=20 um,EA0B=50 urad"`` or ``"20 um"``;
    every value needs its unit (um, mm, nm; urad, mrad, rad, arcsec; um/mm, um/m, ppm) and
    must be positive; one-line InputError naming ``option``."""
    parts = [p.strip() for p in str(text).split(",") if p.strip()]
    require(parts, f"{option}: no limit given (e.g. \"EX0C=20 um,EA0B=50 urad\")")
    out: dict = {}
    for part in parts:
        name, eq, rest = part.rpartition("=") if "=" in part else ("", "", part)
        words = rest.split()
        require(len(words) == 2, f"{option} {part!r}: give the value with its unit, e.g. "
                                 f"\"EX0C=20 um\" or \"50 urad\" (a bare number is refused)")
        require(words[1] in _UNITS, f"{option} {part!r}: unit {words[1]!r} is none of "
                                    f"{', '.join(_UNITS)}")
        v = parse_number(words[0], option, repr(part))
        require(v > 0, f"{option} {part!r}: the limit must be a positive number")
        dim, f = _UNITS[words[1]]
        key = name.strip() or {"length": "um", "angle": "urad", "slope": "um/mm"}[dim]
        require(key not in out, f"{option}: {key} given twice")
        out[key] = (v * f, dim)
    return out


def changes_beyond(old: dict, new: dict, limits: dict, option: str = "--max-change") -> list:
    """``[{"parameter", "old", "new", "change", "limit", "unit"}]`` of the parameters whose
    ``|new - old|`` exceeds their limit.  ``old`` / ``new``: ``{NAME: {"value", "unit"}}``
    (report units: um, urad, um/mm, as calibrate's and check's JSON ``parameters``);
    ``limits`` from :func:`parse_max_change`.  A named limit's parameter must be in ``new``
    and its unit's dimension must match (one-line InputError)."""
    for key, (_, dim) in limits.items():
        if key in _REPORT:
            continue
        require(key in new, f"{option}: {key} is not a parameter of this result "
                            f"({', '.join(list(new)[:8])} ...)")
        unit = new[key].get("unit")
        require(_REPORT.get(unit) == dim, f"{option}: {key} is in {unit}; its limit is a "
                                          f"{dim}")
    out = []
    for name, entry in new.items():
        if name not in old:
            continue
        unit = entry.get("unit")
        lim = limits.get(name) or limits.get(unit)
        if lim is None or _REPORT.get(unit) != lim[1]:
            continue
        a, b = float(old[name]["value"]), float(entry["value"])
        if abs(b - a) > lim[0]:
            out.append({"parameter": name, "old": a, "new": b, "change": b - a,
                        "limit": lim[0], "unit": unit})
    return out


def require_consent(beyond: list, accept: bool, where: str) -> list:
    """Refuse changes beyond their limit (InputError, one line naming the parameter, old, new
    and the limit) unless ``accept`` (``--accept-change``); returns ``beyond``."""
    if not beyond or accept:
        return beyond
    c = beyond[0]
    more = f" (and {len(beyond) - 1} more)" if len(beyond) > 1 else ""
    raise InputError(
        f"{where}: {c['parameter']} moved from {c['old']:.4g} to {c['new']:.4g} {c['unit']}, "
        f"more than --max-change {c['limit']:.4g} {c['unit']}{more}; nothing written "
        f"(--accept-change accepts the change)")


def consent_block(beyond: list, limits: dict, accepted: bool) -> dict:
    """The JSON block ``{"limits", "beyond", "accepted"}`` of a run with ``--max-change``."""
    return {"limits": {k: {"value": v, "dimension": d} for k, (v, d) in limits.items()},
            "beyond": beyond, "accepted": bool(accepted and beyond)}


def against_reference(data: dict, old: dict, limits: dict | None, accept: bool,
                      where: str) -> list:
    """A result's ``data["parameters"]`` against a reference's ``old`` (both ``{NAME:
    {"value", "unit"}}``): ``data["reference_change"]`` lists every common parameter's change;
    with ``limits`` (:func:`parse_max_change`) the changes beyond them are refused unless
    ``accept`` (:func:`require_consent`) and recorded in ``data["max_change"]``."""
    new = data.get("parameters", {})
    data["reference_change"] = {
        n: {"old": float(old[n]["value"]), "new": float(v["value"]),
            "change": float(v["value"]) - float(old[n]["value"]), "unit": v.get("unit")}
        for n, v in new.items() if n in old and old[n].get("unit", v.get("unit")) == v.get("unit")}
    if not limits:
        return []
    beyond = require_consent(changes_beyond(old, new, limits), accept, where)
    data["max_change"] = consent_block(beyond, limits, accept)
    return beyond


def read_result_json(path, layout: str | None = None, option: str = "--reference") -> dict:
    """The JSON of ``volerr calibrate --json`` or ``volerr check --json`` in ``path`` (its
    ``layout`` must be ``layout`` when given): the one reader of a reference calibration
    (``check --reference``, ``calibrate --reference``); one-line InputError naming the file."""
    import json
    from pathlib import Path

    p = Path(path)
    require_file(p, f"{option} {path}: no such file", f"{option} {path}")
    try:
        doc = json.loads(p.read_text(encoding="utf-8"))
    except (UnicodeDecodeError, ValueError):
        raise InputError(f"{option} {path}: not a JSON file (give the JSON of 'volerr "
                         f"calibrate --json' or 'volerr check --json')") from None
    require(isinstance(doc, dict) and "layout" in doc and "parameters" in doc,
            f"{option} {path}: not a calibration (no 'layout' and 'parameters'; give the "
            f"JSON of 'volerr calibrate --json' or 'volerr check --json')")
    require(layout is None or doc["layout"] == layout,
            f"{option} {path}: a calibration of layout {doc['layout']}, not of {layout}")
    return doc


def read_reference_parameters(path, layout: str | None = None,
                              option: str = "--reference") -> dict:
    """``{NAME: {"value", "unit"}}`` of a calibrate or check JSON (its ``parameters``,
    :func:`read_result_json`); one-line InputError naming the file."""
    params = read_result_json(path, layout, option)["parameters"]
    require(isinstance(params, dict) and params and all(
        isinstance(v, dict) and "value" in v for v in params.values()),
        f"{option} {path}: no 'parameters' with values (give a calibrate or check --json)")
    return params
