"""The result of a check (:class:`CheckResult`): what changed, the verdict, the volumetric
change, the values and covariance after the check (the same ``covariance`` block as
calibrate's, so that a check can be the reference of the next and ``volerr history add``
stores it); ``to_dict()`` is the JSON of ``volerr check --json`` (``volerr formats check``)."""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..results import ResultMixin
from . import _volume

METHOD = ("the readings against the reference's prediction by generalised least squares, the "
          "reference's covariance as a measurement of its parameters; the smallest set of "
          "changed parameters by forward selection (BIC gain > 10 and the chi-square "
          "quantile of 1 - 0.05/p, and a cross-validated improvement with paired t above "
          "min(3, the one-sided 5 % Student quantile)), "
          "then a backward pass; uncertainties of a change hold the reference's covariance "
          "and the check's readings")


@dataclass(repr=False)
class CheckResult(ResultMixin):
    """Result of :func:`volerr.check.check` (module docstring): ``to_dict()`` the ``--json``
    document, ``summary()`` what ``volerr check`` prints, ``table()`` every reference
    parameter after the check (value, standard uncertainty k = 1, the reference's unit)."""

    model: object
    reference: object
    selection: object
    system: object
    indistinguishable: list
    not_seen: list
    J: np.ndarray
    tool: np.ndarray
    files: list
    date: str | None = None
    misfit: dict = field(default_factory=dict)
    tolerance: dict | None = None
    quality: object = None       # the residual rule (volerr.fit_quality.FitQuality)
    consent: dict | None = None  # --max-change: {"limits", "beyond", "accepted"}

    @property
    def verdict(self) -> str:
        return "changed" if self.selection.changed or self.misfit.get("unexplained") \
            else "unchanged"

    def changes(self) -> list:
        """``[{"parameter", "change", "unit", "std", ...}]`` in the order of entry."""
        ref, sel = self.reference, self.selection
        delta, std = sel.fit.change()
        after, cov = self.after()
        out = []
        for k, j in enumerate(sel.changed):
            name = ref.names[j]
            alias = sorted({b for a, b in self.indistinguishable if a == name}
                           | {a for a, b in self.indistinguishable if b == name})
            entry = {"parameter": name, "change": float(delta[k]), "unit": ref.units[j],
                     "std": float(std[k]), "reference": float(ref.values[j]),
                     "value": float(after[j]), "z": float(delta[k] / std[k]) if std[k] else None}
            if alias:
                entry["indistinguishable_from"] = alias
            alts = self.alternatives(j)
            if alts:
                entry["alternatives"] = alts
                entry["separate_by"] = separate_by(name, [a["parameter"] for a in alts])
            if name in ref.combinations:
                entry["combination"] = ref.combinations[name]
            out.append(entry)
        return out

    def alternatives(self, j: int) -> list:
        """``[{"parameter", "change", "unit", "std", "delta_bic", "cv_paired_t"}]``: the
        parameters that explain the readings in place of the changed parameter ``j`` about as
        well (:func:`volerr.check._select.alternatives`): this check cannot tell them apart;
        ``change`` / ``std`` the change of the alternative in that place."""
        ref = self.reference
        return [{"parameter": ref.names[a["parameter"]], "change": a["change"],
                 "unit": ref.units[a["parameter"]], "std": a["std"],
                 "delta_bic": round(a["delta_bic"], 3),
                 "cv_paired_t": round(a["cv_paired_t"], 3)}
                for a in self.selection.alternatives.get(j, [])]

    def parameters(self) -> dict:
        """``{NAME: {"value", "unit", "std", "reference", "status", "change", "change_std"}}``
        of every reference parameter: ``value`` / ``std`` after the check (the reference
        updated by its readings), ``reference`` the reference's value, ``status`` changed |
        unchanged; ``change`` / ``change_std``: for a changed parameter its stated change,
        for an unchanged one the change the check measures with it free beside the changed
        ones (below the threshold: :func:`volerr.check._select.freed`) and its standard
        uncertainty, the check's uncertainty of "no change" (both ``None`` for a parameter
        the check does not see)."""
        from . import _select

        ref, sel = self.reference, self.selection
        values, cov = self.after()
        std = np.sqrt(np.maximum(np.diag(cov), 0.0))
        delta, dstd = sel.fit.change()
        measured = {j: (float(delta[k]), float(dstd[k])) for k, j in enumerate(sel.changed)}
        if not hasattr(self, "_freed"):
            self._freed = _select.freed(self.system, sel.changed)
        measured.update({j: v for j, v in self._freed.items()
                         if ref.names[j] not in self.not_seen and np.isfinite(v[1])})
        out = {}
        for j, (n, u) in enumerate(zip(ref.names, ref.units)):
            c, s = measured.get(j, (None, None))
            out[n] = {"value": float(values[j]), "unit": u, "std": float(std[j]),
                      "reference": float(ref.values[j]),
                      "status": "changed" if j in sel.changed else "unchanged",
                      "change": c, "change_std": s}
        return out

    def combinations(self) -> list:
        """``[{"written_as", "expression", "status", "value", "unit", "std"}]``: the
        reference's combinations (determined only as a whole) after the check; they are
        listed here and not under ``unchanged`` (a changed one is under ``changed`` too, with
        its ``combination``)."""
        ref = self.reference
        values, cov = self.after()
        changed = {ref.names[j] for j in self.selection.changed}
        out = []
        for name, expr in ref.combinations.items():
            j = ref.names.index(name)
            out.append({"written_as": name, "expression": expr,
                        "status": "changed" if name in changed else "unchanged",
                        "value": float(values[j]), "unit": ref.units[j],
                        "std": float(np.sqrt(max(cov[j, j], 0.0)))})
        return out

    def budgets(self) -> dict:
        """The GUM budget (:mod:`volerr.report.budget`) of every parameter after the check:
        its covariance is N^-1 of the fit's normal matrix N = N_readings + N_reference (the
        check's weighted readings with their set-ups, and the reference calibration's
        information), so it splits exactly into N^-1 N_readings N^-1 (the readings' stated
        u propagated) plus N^-1 N_reference N^-1 (the reference's covariance propagated);
        both sources in the parameter's unit, sensitivity 1."""
        from ..report.budget import budget, source

        ref, fit, sysm = self.reference, self.selection.fit, self.system
        G, _, _ = sysm.normal()
        n_ref = sysm.matrix(np.zeros_like(G), fit.changed)
        n_all = sysm.matrix(G, fit.changed)
        d = slice(fit.ns, fit.ns + fit.p)
        terms = [np.einsum("ij,jk,ik->i", fit.Ni, m, fit.Ni)[d] for m in (n_all - n_ref, n_ref)]
        files = ", ".join(_file_name(f.get("file", "") if isinstance(f, dict) else f)
                          for f in self.files) or "the check's files"
        out = {}
        for j, (n, u) in enumerate(zip(ref.names, ref.units)):
            out[n] = budget(n, u, [
                source(f"readings of {files} (their stated u, set-ups)",
                       np.sqrt(max(terms[0][j], 0.0)), u),
                source(f"reference {_file_name(ref.path)} (its covariance)",
                       np.sqrt(max(terms[1][j], 0.0)), u)], 2.0)
        return out

    def after(self) -> tuple[np.ndarray, np.ndarray]:
        """(values, covariance) of the reference's parameters after the check, report units."""
        d, C = self.selection.fit.delta()
        return self.reference.values + d, 0.5 * (C + C.T)

    def volumetric_change(self) -> dict:
        delta, _ = self.selection.fit.change()
        full = np.zeros(len(self.reference.names))
        full[self.selection.changed] = delta
        return _volume.change_um(self.J, full)

    def _document(self) -> dict:
        """The ``--json`` document (:meth:`to_dict` is its plain-JSON copy)."""
        ref = self.reference
        values, cov = self.after()
        std = np.sqrt(np.maximum(np.diag(cov), 0.0))
        changed = {ref.names[j] for j in self.selection.changed}
        out = {"verdict": self.verdict, "changed": self.changes(),
               "unchanged": [n for n in ref.names
                             if n not in changed and n not in ref.combinations],
               "volumetric_change_um": self.volumetric_change()}
        if self.date:
            out["date"] = self.date
        out.update({
            "layout": self.model.name, "kind": "check",
            "reference": {"file": str(ref.path), "sha256": _sha(ref.path),
                          "date": ref.data.get("date")},
            "files": self.files, "combinations": self.combinations(),
            "indistinguishable": self.indistinguishable, "not_seen": self.not_seen,
            "misfit": self.misfit, "threshold_chi2": round(self.selection.threshold, 4),
            "selection": [{"parameter": ref.names[s["parameter"]],
                           "dchi2": round(s["dchi2"], 4),
                           "cv_t": None if s["cv_t"] != s["cv_t"] else round(s["cv_t"], 3),
                           "accepted": s["accepted"]} for s in self.selection.steps],
            "parameters": self.parameters(),
            "covariance": {"names": list(ref.names), "units": list(ref.units),
                           "values": [float(v) for v in values],
                           "matrix": [[float(x) for x in row] for row in cov],
                           "degree": ref.degree,
                           "ranges": {a: [lo, hi] for a, (lo, hi) in ref.ranges.items()},
                           "note": "values and covariance after the check (the reference "
                                   "updated by the check's readings), report units"},
            "volume": {"tool_mm": [float(v) for v in self.tool],
                       "note": "every linear axis in 5 steps over its travel, every rotary "
                               "axis in 5 steps (at most one turn); length of the change of "
                               "the volumetric error, um"},
            "method": METHOD, "budgets": self.budgets()})
        if self.tolerance is not None:
            out["tolerance"] = self.tolerance
        return self._fit_entries(out)

    def _fit_entries(self, out: dict) -> dict:
        """``"fit"`` (:mod:`volerr.fit_quality`), ``"forced"`` and ``"max_change"``."""
        from ..fit_quality import forced_note

        if self.quality is not None:
            out["fit"] = self.quality.to_dict()
            if forced_note(self.quality):
                out["forced"] = forced_note(self.quality)
        if self.consent is not None:
            out["max_change"] = self.consent
        return out

    def gated(self, accept_residual: bool, limits: dict | None, accept_change: bool,
              where: str) -> "CheckResult":
        """The residual rule (refused far above the readings' uncertainty unless
        ``accept_residual``) and, with ``limits``
        (:func:`volerr.fit_quality.parse_max_change`), the parameters moved beyond them
        against the reference (refused unless ``accept_change``); a ``"map"`` limit (um)
        bounds the largest volumetric change.  One-line InputError; else a new result with
        the verdict (forced when accepted) and the consent block (this one is not changed)."""
        from dataclasses import replace

        from .. import fit_quality as fq

        quality = fq.require_fit(self.quality, accept_residual, where)
        if not limits:
            return replace(self, quality=quality)
        limits = dict(limits)
        beyond = []
        if "map" in limits:
            lim, dim = limits.pop("map")
            fq.require(dim == "length", "--max-change: map is a length (um)")
            v = float(self.volumetric_change()["max"])
            if v > lim:
                beyond.append({"parameter": "map (largest volumetric change)", "old": 0.0,
                               "new": v, "change": v, "limit": lim, "unit": "um"})
        params = self.parameters()
        old = {n: {"value": e["reference"], "unit": e["unit"]} for n, e in params.items()}
        beyond += fq.changes_beyond(old, params, limits)
        fq.require_consent(beyond, accept_change, where)
        return replace(self, quality=quality,
                       consent=fq.consent_block(beyond, limits, accept_change))

    def summary(self) -> str:
        """What ``volerr check`` prints."""
        d = self.to_dict()
        v = d["volumetric_change_um"]
        lines = [f"{d['layout']}: {d['verdict']} against {_file_name(self.reference.path)} "
                 f"({sum(f['n_readings'] for f in self.files)} readings); volumetric change "
                 f"max {v['max']:.3g} um, RMS {v['rms']:.3g} um"]
        for c in d["changed"]:
            also = (f" (indistinguishable by this check from "
                    f"{', '.join(c['indistinguishable_from'])})"
                    if c.get("indistinguishable_from") else "")
            lines.append(f"  {c['parameter']} changed by {c['change']:+.4g} +- {c['std']:.2g} "
                         f"{c['unit']}{also}")
            for a in c.get("alternatives", []):
                lines.append(f"    or {a['parameter']} by {a['change']:+.4g} +- {a['std']:.2g} "
                             f"{a['unit']}: this check cannot tell it apart (BIC "
                             f"{a['delta_bic']:+.3g}, cross-validated t {a['cv_paired_t']:+.2f})")
            if c.get("alternatives"):
                lines.append(f"    separate by: {c['separate_by']}")
        if self.misfit.get("unexplained"):
            lines.append(f"  the readings hold a change none of the reference's parameters "
                         f"explains (Birge ratio {self.misfit['birge_ratio']:.3g})")
        if self.indistinguishable:
            lines.append("  this check cannot tell apart: " + "; ".join(
                f"{a} and {b}" for a, b in self.indistinguishable))
        if self.tolerance is not None:
            lines.append(f"  tolerance: {self.tolerance['verdict']}")
        if self.quality is not None:
            lines.append("  " + self.quality.line())
        if self.consent and self.consent["beyond"]:
            lines.append("  changes beyond --max-change, accepted (--accept-change): " + ", ".join(
                f"{c['parameter']} {c['old']:.4g} -> {c['new']:.4g} {c['unit']}"
                for c in self.consent["beyond"]))
        return "\n".join(lines)

    def __repr__(self) -> str:
        return f"<CheckResult {self.model.name}: {self.verdict}, " \
               f"{len(self.selection.changed)} changed>"

    def write_html(self, path, inputs=()):
        from ..fileio import write_text
        from ._html import check_html

        return write_text(path, check_html(self.to_dict()), inputs=list(inputs))


def separate_by(name: str, others: list) -> str:
    """One sentence: what would tell ``name`` from its alternatives ``others``."""
    return (f"a check whose readings move {name} and {', '.join(others)} differently: a second "
            f"placement of the instrument (another position on the table or tool length), "
            f"or a calibration")


def _file_name(path) -> str:
    from pathlib import Path

    return Path(str(path)).name


def _sha(path) -> str | None:
    import hashlib
    from pathlib import Path

    p = Path(str(path))
    return hashlib.sha256(p.read_bytes()).hexdigest() if p.is_file() else None
