"""``volerr.loop(...)``: the Python API of ``volerr loop`` (:mod:`volerr.results`)."""

from __future__ import annotations

import os
from dataclasses import dataclass

from ..errors import require
from ..selection.rules import SIG_K, significant  # noqa: F401  (SIG_K: former name here)
from . import candidates
from .drift.report import K_PRINT
from .run import Report, run_loop


@dataclass(repr=False)
class Loop(Report):
    """Result of :func:`loop`: a :class:`volerr.loop.Report` whose :meth:`summary` is the
    whole console text of ``volerr loop``; ``plot_data`` is the data behind the report's
    figures (:class:`volerr.loop.run.Figures`), :meth:`figures` draws them."""

    def headline(self) -> str:
        """The first line: points, held-out RMS and max before -> after (um), effects."""
        return Report.summary(self)

    def summary(self) -> str:
        """What ``volerr loop`` prints (warnings first, then :meth:`headline` ...)."""
        return "\n".join(console_lines(self))

    def _headline(self) -> str:
        return self.headline()

    def _rows(self) -> list:
        from ..results import Row

        out = []
        for e in self.data["effects"]:
            std = e.get("std") or {}
            for k, v in e["parameters"].items():
                out.append(Row(f"{e['name']}:{k}", v, std.get(k) if isinstance(std, dict)
                               else None, e["units"][k], 1.0))
        return out

    def written_in(self, folder) -> "Loop":
        """A new result whose ``augmented_layout`` and ``generated_module`` name the files in
        ``folder`` (where the command moves them from its staging folder); this one unchanged."""
        from dataclasses import replace
        from pathlib import Path

        moved = {k: str(Path(folder) / Path(v).name) for k, v in self.data.items()
                 if k in ("augmented_layout", "generated_module") and v}
        return replace(self, data={**self.data, **moved}) if moved else self

    def write_predictions(self, path, inputs=()):
        """Not written for measured deviations: the predictions CSV is the drift loop's."""
        require(False, "loop: --predictions-out (write_predictions) is for drift runs "
                       "(drift:FILE)")


def effect_terms(e: dict) -> str:
    """The effect's parameters with their expanded uncertainty (k = 2); a term that is not
    significant (|value| < 2 u) is said to be so, apart from the effect's terms."""
    std = e.get("std") or {}
    shown, weak = [], []
    for k, v in e["parameters"].items():
        u = std.get(k)
        text = f"{k} = {v:.4g} {e['units'][k]}"
        if u is not None:
            text += f" +- {K_PRINT * u:.2g} (k = {K_PRINT:g})"
        (shown if significant(v, u) else weak).append(text)
    out = ", ".join(shown) or "no significant term"
    if weak:
        out += f"; not significant, not part of the effect: {', '.join(weak)}"
    return out


def lag_lines(e: dict) -> list:
    """Console lines of an effect's lag and of the explanations the data cannot tell from it."""
    out = []
    lag = e.get("lag_s")
    if lag:
        std = f" +- {lag['std']:.0f}" if lag.get("std") is not None else ""
        out.append(f"through a first-order lag of {e['covariate']}: tau = {lag['value']:.0f}"
                   f"{std} s ({lag['value'] / 60:.1f} min)")
    for a in e.get("alternatives") or []:
        lag_a = f" through a lag of {a['lag_s']:.0f} s" if a.get("lag_s") else ""
        out.append(f"these data cannot tell it from {a['parameter']} x {a['covariate']}"
                   f"{lag_a} (held-out RMS {a['held_out_rms_um']:.3f} um)")
    if e.get("separate_by"):
        out.append(f"would separate them: {e['separate_by']}")
    return out


def console_lines(report: Report) -> list:
    """What ``volerr loop`` prints for ``report``."""
    out = [f"  warning: {w}" for w in report["warnings"]]
    out.append(Report.summary(report))
    for e in report.effects:
        out.append(f"  {e['kind']} {e['name']}: {effect_terms(e)}")
        out += [f"    {line}" for line in lag_lines(e)]
    if report["augmented_layout"]:
        out.append(f"  augmented layout: {report['augmented_layout']}; generated module: "
                   f"{report['generated_module']}")
    if report["residual_note"]:
        out.append(f"  {report['residual_note']}")
    if getattr(report, "quality", None) is not None:
        out.append("  " + report.quality.line())
    hidden = [u["parameters"][0] for u in report["unidentifiable"]
              if not (u["parameters"][0].startswith("setup.") and u.get("no_sensitivity"))]
    if hidden:
        out.append(f"  not separable by these data: {', '.join(hidden)} (see the report)")
    return out


def is_drift(specs) -> bool:
    """Whether the files ``specs`` (``KIND:FILE`` or paths) are drift runs: all of them
    (``drift:FILE`` or detected as such), or none; a mixture is refused (one line)."""
    from pathlib import Path

    from ..instruments import detect, split_spec

    kinds = []
    for d in specs:
        kind, path = split_spec(str(d))
        kinds.append(kind or (detect(path) if Path(path).is_file() else None))
    drift = [k == "drift" for k in kinds]
    require(all(drift) or not any(drift), "loop: drift runs and other measurements in one "
            "call; give the drift files alone")
    return bool(drift) and all(drift)


def loop(layout, files, *, out_dir=None, seed: int = 0, folds: int | None = None,
         test_fraction: float = 0.25, degree: int | None = None, families=None,
         progress=None, holdout_time: str | None = None, holdout_files=(),
         differences: bool = False, inputs=(), accept_residual: bool = False):
    """Close the loop on measured deviations (``volerr loop``): fit the declared model, trace
    the residual to candidate effects "parameter P varies with covariate C", augment the
    layout, report the error before and after on held-out points.

    Parameters
    ----------
    layout : str or path
        Layout name or layout file (an augmented ``*_aug.toml`` of an earlier run too).
    files : str, path or list
        Measurement files of one campaign (deviations, ballbar, sphere; ``KIND:FILE`` names
        the kind); deviations in um, positions in mm / deg, covariates as in 'volerr formats
        loop'.  A :class:`volerr.loop.simulate.Campaign` is taken as well.
    out_dir : path, optional
        Folder for the augmented layout and its generated module; None: not written (the
        texts are in the result: ``augmented_text``, ``generated_text``).
    seed : int
        Seed of the held-out split and of the folds.
    folds : int, optional
        k-fold cross-validation with this k (2 .. 20); default: leave-one-point-out.
    test_fraction : float
        Fraction of the points held out for before / after (0.05 .. 0.5).
    degree : int, optional
        Degree of the component series; default: by cross-validation.
    families : str or list of str, optional
        Candidate families to search (comma list or list; default: all,
        :data:`volerr.loop.candidates.FAMILIES`).
    progress : bool, optional
        Progress bar on stderr (None: when stderr is a terminal).

    holdout_time : str, optional
        ``"A:B"`` (units s, min, h; an open end allowed: ``"100035s:"``): hold out the
        readings (points) with A <= t < B.
    holdout_files : list, optional
        Drift runs: every run of these files held out (read beside ``files``).
    differences : bool
        Drift runs: try differences of two sensors as well.
    inputs : list, optional
        Files the outputs (``out_dir``) must not overwrite.
    accept_residual : bool
        ``--accept-residual``: a fit far above the readings' declared uncertainty
        (:mod:`volerr.fit_quality`) is returned marked forced instead of refused (InputError).

    Returns
    -------
    Loop
        ``to_dict()`` is ``volerr loop --json``: RMS / max before and after (um), the effects
        with their parameters (their units in ``units``) and standard uncertainties (k = 1).
    DriftReport
        For drift runs (``drift:FILE`` or files detected as drift; 'volerr formats
        loop-lags'): ``data`` / ``["channels"]`` / ``effects`` the JSON of ``volerr loop
        --json``, ``summary()`` the console text, ``write_json``, ``write_html``,
        ``write_predictions``, ``table()``, ``figures()``
        (:class:`volerr.loop.drift.report.DriftReport`).
    """
    specs = list(files) if isinstance(files, (list, tuple)) else [files]
    if specs and all(isinstance(f, (str, os.PathLike)) for f in specs) and is_drift(specs):
        return _drift(layout, specs, out_dir, holdout_time, holdout_files, differences,
                      progress)
    require(not holdout_files, "loop: holdout_files (--holdout-files) is for drift runs "
            "(drift:FILE)")
    from ..instruments import split_spec

    chosen = candidates.FAMILIES
    if families:
        parts = families.split(",") if isinstance(families, str) else list(families)
        chosen = tuple(f.strip() for f in parts if f.strip())
        bad = [f for f in chosen if f not in candidates.FAMILIES]
        require(not bad, f"unknown family {bad[0] if bad else ''!r}; families are "
                f"{' '.join(candidates.FAMILIES)}")
    if isinstance(files, (list, tuple)):
        files = files[0] if len(files) == 1 else list(files)
    r = run_loop(layout, files, seed=seed, folds=folds, test_fraction=test_fraction,
                 degree=degree, out_dir=out_dir, families=chosen, progress=progress,
                 holdout_time=holdout_time, inputs=inputs, accept_residual=accept_residual,
                 where=" ".join(["loop"] + [split_spec(str(f))[1] for f in specs
                                            if isinstance(f, (str, os.PathLike))]))
    return Loop(r.data, r.plot_data, r.augmented_text, r.generated, r.quality)


def _drift(layout, specs, out_dir, holdout_time, holdout_files, differences, progress):
    """The loop on drift runs (:func:`volerr.loop.drift.run.loop_drift`)."""
    from ..instruments import split_spec
    from .drift.run import loop_drift

    require(out_dir is None, "loop: out_dir (--out-dir) is not written for drift runs (their "
            "effects are per channel, not in the layout)")
    held = [split_spec(str(d))[1] for d in (holdout_files or [])]
    return loop_drift(layout, [split_spec(str(d))[1] for d in specs], window=holdout_time,
                      files=held, differences=differences,
                      progress=progress if callable(progress) else None)
