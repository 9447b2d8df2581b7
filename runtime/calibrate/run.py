"""``volerr calibrate``: identify a layout's parameters from the files of any instruments, mixed
in one campaign, by weighted least squares on the layout's derived observation model.

Steps (:func:`calibrate`):

1. read every file as :class:`volerr.instruments.Observations` (its kind from its columns or
   ``KIND:FILE``) and stack them: one design, each file with its own set-up unknowns;
2. choose the parameters fitted (``--parameters``; the others are held at zero) and, for
   component errors, the degree of their Legendre series by cross-validation;
3. fix the gauge by convention (:func:`volerr.estimate.design.gauge_mask`: what no
   measurement of the chain can determine, e.g. the offsets of translational errors against
   the instruments' positions);
4. accumulate the weighted normal equations (weights ``1 / u^2`` of each reading) per file, on
   all readings and on the training readings (a random ``test_fraction`` of the points is
   held out);
5. estimability of every parameter from the stacked Gram matrix and which file sees it
   (:mod:`volerr.calibrate.estimability`); the solution takes the columns in the gauge order
   and leaves out those in the span of the ones before (their value 0);
6. the covariance ``max(s0^2, 1) (A^T W A)^-1`` with the a-posteriori variance factor ``s0^2``
   (weighted residual sum of squares per degree of freedom): a factor above 1 widens the
   stated uncertainties, one below 1 never shrinks them (GUM practice: the a-priori
   uncertainties are kept, JCGM 100 4.2, Birge 1932); set-up estimates per file / placement,
   residual RMS per file on all readings and on the held-out ones.

Units: readings mm inside; reports um, urad, um/mm ... (:mod:`volerr.calibrate.terms`).
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .. import instruments
from ..errors import require
from ..estimate import blocks
from ..estimate.design import data_ranges, declared_design, gauge_mask, identifiability_gram
from ..estimate.steps import choose_degree, split_points
from ..fit_quality import FitQuality, judge
from ..machine.model import Model, load
from ..results import ResultMixin
from . import estimability, terms

#: relative eigenvalue below which the solution leaves a direction out (unit-scaled columns)
SOLVE_TOL = 1e-12


@dataclass(repr=False)
class Calibration(ResultMixin):
    """Result of :func:`calibrate`: ``data`` the JSON report (INTERFACE.md keys first) and what
    the error tables and the HTML page need.

    The JSON keys are attributes too (``cal.parameters``: name -> ``{"value", "std", "unit"}``
    with the standard uncertainty ``std`` at k = 1); :meth:`summary` is what ``volerr
    calibrate`` prints, :meth:`table` one row per identified parameter, :meth:`figures` the
    report's figures."""

    data: dict
    model: Model
    ranges: dict
    degree: int
    labels: list                 # design columns (set-up first)
    coef: np.ndarray             # mm / rad per column (0 where left out)
    std: np.ndarray              # standard uncertainty per column (0 where left out)
    residuals: dict = field(default_factory=dict)   # file -> (positions, residual um, rows)
    solution: "Solution | None" = None
    parts: list = field(default_factory=list)       # the files' Observations
    quality: "FitQuality | None" = None              # the residual rule (volerr.fit_quality)

    @property
    def written(self) -> np.ndarray:
        """(p,) bool: the columns written into error tables, maps and ISO 10360 numbers: those
        determined on their own and those carrying a determined combination
        (``combinations``, ``written_as``); every other column is written as 0."""
        sol = self.solution
        if sol is None:
            return np.ones(len(self.labels), bool)
        out = np.asarray(sol.estimable, bool).copy()
        out[list(sol.mixes)] = True
        out[[j for j, lab in enumerate(self.labels) if lab[0] == "setup"]] = False
        return out

    @property
    def coef_written(self) -> np.ndarray:
        """:attr:`coef` with the columns not :attr:`written` set to 0."""
        return np.where(self.written, self.coef, 0.0)

    def combination(self, weights: dict) -> tuple[float, float] | None:
        """Value and standard uncertainty (k = 1) of a linear combination of the fitted
        parameters.

        Parameters
        ----------
        weights : dict
            ``{name: w}``: a parameter's report name (``"EY0B"``, ``"EXX@slope"``, as in
            :attr:`parameters` and :attr:`unidentifiable`) or its design label (a tuple, as in
            :attr:`labels`) -> its weight ``w`` (dimensionless).

        Returns
        -------
        (value, std) : tuple of float or None
            ``sum w * coefficient`` in the coefficients' natural units (mm for translational
            parameters, rad for angular ones; mm/mm or rad/mm for slopes), or None when the
            campaign does not determine that combination (or a name is unknown).

        Examples
        --------
        ``cal.combination({"EY0B": 1, "EY0C": 1})``: the sum of two location errors that only
        a combination of set-ups determines.
        """
        c = self.combination_vector(weights)
        if c is None:
            return None
        ck = c[self.solution.kept]
        return float(c @ self.coef), float(np.sqrt(max(ck @ self.solution.cov @ ck, 0.0)))

    def combination_vector(self, weights: dict) -> np.ndarray | None:
        """The weights of :meth:`combination` over the design columns (:attr:`labels`), or
        None when the campaign does not determine that combination."""
        sol = self.solution
        names = self._label_names()
        c = np.zeros(len(self.labels))
        for lab, w in weights.items():
            j = names.get(lab) if isinstance(lab, str) else (
                self.labels.index(lab) if lab in self.labels else None)
            if j is None:
                return None
            c[j] = w
        d = np.where(sol.norms > 0, sol.norms, 1.0)
        if np.linalg.norm(sol.null.T @ (c / d)) > 1e-6 * np.linalg.norm(c / d):
            return None
        return c

    def _label_names(self) -> dict:
        """report name -> design column (parameters only)."""
        name_of = terms.namer(self.model, self.ranges)
        return {name_of(lab): j for j, lab in enumerate(self.labels) if lab[0] != "setup"}

    def __getitem__(self, key):
        return self.data[key]

    def figures(self) -> dict:
        """``{"parameters", "residuals"}``: the identified values with +-2 u bars (k = 2) and
        the residual of every reading per file (:class:`matplotlib.figure.Figure`)."""
        from .report import parameter_figure, residual_figure

        out = {}
        if self.data["parameters"]:
            out["parameters"] = parameter_figure(self.data["parameters"])
        if self.residuals:
            out["residuals"] = residual_figure(self)
        return out

    def error_tables(self, n_grid: int = 41):
        """The identified error functions as error tables over the measured range and the
        constants: ``({axis: ErrorTable}, {name: value}, {name: std})``, mm / rad.  An axis
        none of whose component errors was fitted gets no table (zero errors everywhere, no
        range); columns left out (not determined) are zero."""
        from ..estimate.design import series_basis
        from ..tables.table import ErrorTable

        from .mapping import function_std

        model, ranges, deg = self.model, self.ranges, self.degree
        index = {lab: j for j, lab in enumerate(self.labels)}
        coef, std_all = self.coef_written, np.where(self.written, self.std, 0.0)
        tables, constants, cstd = {}, {}, {}
        for a in model.axes:
            q = np.linspace(*ranges[a], n_grid)
            P = series_basis(model, a, q, ranges, deg)
            vals, std = {}, {}
            if not any((p, k) in index for p in model.parameters
                       if model.parameter_axis.get(p) == a for k in range(deg + 1)):
                continue
            for p in model.parameters:
                if model.parameter_axis.get(p) != a:
                    continue
                js = [(k, index[(p, k)]) for k in range(deg + 1) if (p, k) in index]
                vals[p] = sum((P[:, k] * coef[j] for k, j in js), np.zeros(n_grid))
                std[p] = function_std(self, P, js)
            if vals:
                tables[a] = ErrorTable(a, q, vals, std=std)
        self._write_reversals(tables, index, coef, n_grid)
        for p in model.parameters:
            j = index.get((p, None))
            if j is not None:
                constants[p] = float(coef[j])
                cstd[p] = float(std_all[j])
        return tables, constants, cstd

    def _write_reversals(self, tables: dict, index: dict, coef, n_grid: int) -> None:
        """Each determined reversal ``RV_<axis>`` into its axis' table as the ISO 230-2
        reversal column (constant over the measured range, mm; the table's errors are the
        bidirectional mean, as the ``dir_<axis>/2`` term of the fit makes them), so that
        ``compensate`` and ``map --approach`` apply it; an undetermined one is not written."""
        from ..tables.table import ErrorTable

        for a in self.model.axes:
            j = index.get((f"RV_{a}", "extra"))
            if j is None or not self.written[j]:
                continue
            if a not in tables:
                tables[a] = ErrorTable(a, np.linspace(*self.ranges[a], n_grid), {})
            tables[a].reversal = np.full(len(tables[a].positions), float(coef[j]))

    def _write_own(self, outs, options: dict, inputs: list) -> None:
        """``volerr calibrate``'s ``--errors-out DIR`` (:meth:`write_error_tables`) and
        ``--map-out MAP.csv`` (:meth:`write_map`, ``map_grid`` nodes per axis)."""
        super()._write_own(outs, options, inputs)
        if options.get("map_out"):
            self.write_map(outs.path("--map-out"), options.get("map_grid", 9), inputs=inputs)

    def write_error_tables(self, directory, inputs=(), accept_residual: bool = False,
                           accept_implausible: bool = False, shown=None) -> Path:
        """The error directory (``X.csv`` ... ``constants.csv``); refused for a fit far above
        the readings' uncertainty unless ``accept_residual`` (:mod:`volerr.fit_quality`), and
        for values beyond what a machine of the layout's travel can have unless
        ``accept_implausible`` (:mod:`volerr.tables.plausible`; a refusal names ``shown``,
        default ``directory``)."""
        from ..fit_quality import forced_note, require_writable
        from ..tables.table import write_error_dir

        require_writable(self.quality, accept_residual, f"error tables {directory}")
        comments = self.table_comments()
        note = None if self.data.get("forced") or not accept_residual \
            or self.quality is None else forced_note(self.quality.marked())
        if note:            # a refused fit written on the caller's word (not changed here)
            for where in ["constants", *self.model.axes]:
                comments.setdefault(where, []).insert(0, note)
        tables, constants, cstd = self.error_tables()
        return write_error_dir(directory, tables, constants or None, cstd or None,
                               inputs=list(inputs), comments=comments, machine=self.model,
                               accept_implausible=accept_implausible, shown=shown)

    def table_comments(self) -> dict:
        """``{axis or "constants": [line ...]}``: what the error directory holds under a name
        that is not determined on its own (a combination's ``written_as``), and that every
        other undetermined name is written as 0."""
        out: dict = {}
        if self.data.get("forced"):
            for where in ["constants", *self.model.axes]:
                out.setdefault(where, []).append(self.data["forced"])
        for c in self.data.get("combinations", []):
            name = c["written_as"].split("@")[0]
            if name not in self.model.parameters:
                continue            # a reversal RV_<axis>: a column of its axis' table
            axis = self.model.parameter_axis.get(name)
            where = "constants" if axis is None else axis
            out.setdefault(where, []).append(
                f"{c['written_as']} holds the combination {c['expression']} = "
                f"{c['value']:.4g} +- {c['std']:.2g} {c['unit']} (the campaign does not "
                f"determine its terms one by one)")
        zero = [n for n in self.data.get("unidentifiable", [])
                if n not in {c["written_as"] for c in self.data.get("combinations", [])}
                and n.split("@")[0] in self.model.parameters]
        if zero:
            for where in ["constants", *self.model.axes]:
                out.setdefault(where, []).append(
                    f"not determined, written as 0: {', '.join(zero)}")
        return out

    def write_json(self, path, inputs=()) -> Path:
        from ..fileio import json_text, write_text

        return write_text(path, json_text(self.data), inputs=list(inputs))

    def write_html(self, path, inputs=()) -> Path:
        from ..fileio import write_text
        from .report import render_html

        return write_text(path, render_html(self), inputs=list(inputs))

    def summary(self) -> str:
        """What ``volerr calibrate`` prints: the headline, each identified value with its
        standard uncertainty (k = 1), the inconsistent files and what is not determined."""
        lines = [self.headline(), *self.console_lines()]
        if self.quality is not None:
            lines.insert(1, "  " + self.quality.line())
        beyond = self.data.get("max_change", {}).get("beyond")
        if beyond:          # written on the caller's word (accept_change)
            lines.append("  changes beyond --max-change, accepted (--accept-change): " + ", ".join(
                f"{c['parameter']} {c['old']:.4g} -> {c['new']:.4g} {c['unit']}" for c in beyond))
        return "\n".join(lines)

    def write_map(self, path, grid: int = 9, inputs=()) -> Path:
        """The ``--map-out`` CSV: the identified volumetric error map over the measured range
        with its standard uncertainty (k = 1), ``grid`` points per linear axis (2 .. 60)
        (:func:`volerr.calibrate.mapping.write_csv`: positions mm / deg, errors um)."""
        from .mapping import grid_counts, write_csv

        return write_csv(path, self, grid_counts(grid), inputs=list(inputs))

    def console_lines(self) -> list:
        """The lines ``volerr calibrate`` prints below :meth:`headline`."""
        out, hidden = [], []
        if self.data.get("variance_factor", 1.0) < 1.0:
            out.append(f"  a-posteriori variance factor {self.data['variance_factor']:.3g} < 1: "
                       f"the readings scatter less than their stated uncertainty; the stated "
                       f"(a-priori) uncertainties are kept, not shrunk")
        for name, v in self.data["parameters"].items():
            if "@" not in name or name.endswith("@slope"):
                out.append(f"  {name} = {v['value']:.4g} +- {v['std']:.2g} {v['unit']} "
                           f"(u, k = 1)")
            else:
                hidden.append(name)
        if hidden:
            out.append(f"  and {len(hidden)} higher series terms ({', '.join(hidden[:6])}"
                       f"{' ...' if len(hidden) > 6 else ''}: in --json and --html)")
        bad = self.data.get("consistency", {}).get("inconsistent")
        if bad:
            worst = {e["file"]: e for e in self.data["consistency"]["files"]}
            out.append("  inconsistent with the rest (leave-one-file-out test): " + ", ".join(
                f"{f} (p = {worst[f]['p_value']:.2g}, Birge ratio {worst[f]['birge_ratio']})"
                for f in bad))
        return out + self.undetermined_lines()

    def headline(self) -> str:
        """The first line of :meth:`summary`: layout, counts, RMS residual per file."""
        d = self.data
        files = "; ".join(f"{i['file']} ({i['kind']}, {i['n']} rows): RMS "
                          f"{i['rms_residual']:.3f} um, held-out {i['heldout_rms']:.3f} um"
                          for i in d["instruments"])
        combos = (f" ({len(d['combinations'])} of them in a determined combination)"
                  if d.get("combinations") else "")
        return (f"{d['layout']}: {len(d['parameters'])} parameters identified, "
                f"{len(d['unidentifiable'])} not determined one by one{combos}; {files}")

    def undetermined_lines(self) -> list:
        """Console lines: the combinations written under one of their names, and the names
        written as 0 (what the error directory, the map and the ISO 10360 numbers hold)."""
        d = self.data
        out = [f"  determined only in combination: {c['expression']} = {c['value']:.4g} +- "
               f"{c['std']:.2g} {c['unit']} (u, k = 1; written as {c['written_as']})"
               for c in d.get("combinations", [])]
        written = {c["written_as"] for c in d.get("combinations", [])}
        zero = [n for n in d["unidentifiable"] if n not in written]
        if zero:
            out.append(f"  not determined by these data (written as 0 in the error directory, "
                       f"the map and the ISO 10360 numbers): {', '.join(zero[:12])}"
                       f"{' ...' if len(zero) > 12 else ''} (see the report)")
        return out


def campaign_kinds(obs) -> list:
    """The instrument kinds of the stacked files (``deviations`` for bare observations)."""
    return list(dict.fromkeys(f.kind for f in obs.files)) or ["deviations"]


def moving_axes(model, ranges: dict) -> set:
    """The axes the campaign moves: a measured range wider than 1 deg (rotary) or 1 mm."""
    return {a for a, (lo, hi) in ranges.items() if hi - lo > 1.0}


def declared_parameters(obs) -> str | None:
    """The files' declared ``# parameters:`` (a ``volerr plan`` request), or None; files
    declaring different requests are refused."""
    declared = {f.parameters for f in obs.files if f.parameters}
    require(len(declared) <= 1, "the files declare different '# parameters:' lines; give "
                                "--parameters")
    return declared.pop() if declared else None


def reading_weights(obs) -> tuple[np.ndarray, float]:
    """Relative weights (N,) of the points' readings, ``(u_ref / u)^2``, and ``u_ref`` (mm)."""
    return obs.point_weights(), obs.reference_sigma()


def calibrate(layout, files, *, parameters: str | None = None, degree: int | None = None,
              max_degree: int = 8, seed: int = 0, test_fraction: float = 0.25,
              extra_terms=(), plan: bool = True, progress=None, accept_residual: bool = False,
              reference=None, max_change=None, accept_change: bool = False) -> Calibration:
    """Identify ``layout``'s parameters from measurement files of any instruments, mixed in
    one campaign, by weighted least squares (``volerr calibrate``; ``volerr.calibrate(...)``).

    Parameters
    ----------
    layout : str or path
        Layout name (``volerr.layouts()``) or layout file.
    files : str, path, list of them, or volerr.instruments.Observations
        Measurement files (one string is one file) (``KIND:FILE`` names the kind: deviations, ballbar, sphere,
        artifact, interferometer, distances; 'volerr formats NAME').  Each file states its
        reading's sign and frame in its format; readings in um / urad, positions mm / deg.
    parameters : str, optional
        The parameters fitted (the others held at zero), as ``--parameters``: names
        (``EC0Y``), terms (``EXX@slope``), reversals (``RV_X``), axes (``X``) and groups
        (``all``, ``squareness`` ...); default: what each instrument kind is used for.
    degree : int, optional
        Degree of the component errors' Legendre series (default: by cross-validation,
        1 .. ``max_degree``).
    seed : int
        Seed of the held-out split (a random ``test_fraction`` of the points).
    extra_terms : sequence, optional
        More columns ``(name, target, basis, (factor, unit))``: a parameter ``name`` that
        adds ``name * basis`` to the declared parameter ``target`` (e.g. a reversal
        ``("RV_X", "EXX", "dir_X/2", (1e3, "um"))``); the basis is an expression in the axis
        positions (rad for rotary axes) and the covariates of the files.
    plan : bool
        Suggest the plan extensions that would determine what the campaign does not.
    progress : bool, optional
        Progress bar on stderr (None: when stderr is a terminal).
    accept_residual : bool
        ``--accept-residual``: a fit far above the readings' declared uncertainty
        (:mod:`volerr.fit_quality`) is returned marked forced (``fit["verdict"] == "forced"``,
        ``data["forced"]`` the sentence every output carries) instead of refused.
    reference : str, path, dict or Calibration, optional
        ``--reference``: a calibrate / check JSON of the same layout (the file, its document,
        its ``parameters`` ``{NAME: {"value", "unit"}}``, or an earlier :class:`Calibration`);
        the result's ``reference_change`` lists every common parameter's change (report
        units).
    max_change : str or dict, optional
        ``--max-change`` (needs ``reference``): ``"EX0C=20 um,EA0B=50 urad"`` or ``"20 um"``
        (units required; :func:`volerr.fit_quality.parse_max_change`); a parameter moved
        further than its limit is refused unless ``accept_change`` (``--accept-change``).

    Returns
    -------
    Calibration
        ``to_dict()`` is ``--json``: ``parameters`` name -> ``{"value", "std", "unit"}``
        (std a standard uncertainty, k = 1; translational parameters in um, angular in urad,
        slopes um/mm ...; signs per ISO 230-1, 'volerr formats calibrate-json'),
        ``unidentifiable``, ``combinations``, set-ups, residuals, consistency.  The
        covariance is scaled by the a-posteriori variance factor only when it exceeds 1.

    Raises
    ------
    volerr.InputError
        Bad input, with the command's one-line message; a fit far above its declared
        uncertainty (unless ``accept_residual``), a change beyond ``max_change`` (unless
        ``accept_change``).
    """
    from .. import fit_quality as fq

    require(reference is not None or not max_change, "--max-change needs --reference CAL.json")
    limits = fq.parse_max_change(max_change) if isinstance(max_change, str) else max_change
    model = layout if isinstance(layout, Model) else load(layout)
    old = None if reference is None else _reference_parameters(reference, model.name)
    report, fields = fit_campaign(model, files, parameters=parameters, degree=degree,
                                  max_degree=max_degree, seed=seed,
                                  test_fraction=test_fraction, extra_terms=extra_terms,
                                  plan=plan, progress=progress, built=False)
    where = f"calibrate {campaign_names(files)}"
    quality = fq.gate(report, fields[-1], accept_residual, where)
    if old is not None:
        fq.against_reference(report, old, limits, accept_change, where)
    return Calibration(report, *fields[:-1], quality)


def _reference_parameters(reference, layout: str) -> dict:
    """``{NAME: {"value", "unit"}}`` of a reference: a calibrate / check JSON file, a
    :class:`Calibration`, its JSON document or its ``parameters``."""
    from ..fit_quality import read_reference_parameters

    if isinstance(reference, Calibration):
        reference = reference.data
    if isinstance(reference, dict):
        require(reference.get("layout", layout) == layout, f"reference: a calibration of "
                f"layout {reference.get('layout')}, not of {layout}")
        params = reference.get("parameters", reference)
        require(isinstance(params, dict) and all(
            isinstance(v, dict) and "value" in v for v in params.values()),
            "reference: no parameters with values (give a calibrate or check JSON)")
        return dict(params)
    return read_reference_parameters(reference, layout)


def campaign_names(files) -> str:
    """The campaign's files as the command names them (``KIND:`` dropped), for messages."""
    if isinstance(files, instruments.Observations):
        return " ".join(f.name for f in files.files)
    from ..results import file_list

    return " ".join(instruments.split_spec(str(f))[1] for f in file_list(files))


def fit_campaign(layout, files, *, parameters: str | None = None, degree: int | None = None,
                 max_degree: int = 8, seed: int = 0, test_fraction: float = 0.25,
                 extra_terms=(), plan: bool = True, progress=None, built: bool = True):
    """:func:`calibrate` without the residual rule's gate and the reference: the fit as it
    is, judged (``quality``) but neither refused nor forced -- for a capability that
    decides itself what a refused fit means (``ballbar evaluate`` withholds its diagnosis).
    ``built``: the :class:`Calibration`; False: ``(report, fields)`` to build it from."""
    from threadpoolctl import threadpool_limits

    with threadpool_limits(limits=1, user_api="blas"):
        report, fields = _run(layout, files, parameters, degree, max_degree, seed,
                              test_fraction, list(extra_terms), plan, progress)
    return Calibration(report, *fields) if built else (report, fields)


def _progress(total: int, enabled):
    import sys

    from tqdm import tqdm

    disable = (not sys.stderr.isatty()) if enabled is None else not enabled
    return tqdm(total=total, file=sys.stderr, disable=disable, desc="volerr calibrate",
                bar_format="{desc}: {n}/{total} {postfix}")


def _run(layout, files, parameters, degree, max_degree, seed, test_fraction, extra_terms,
         plan, progress):
    t0 = time.perf_counter()
    require(0.05 <= test_fraction <= 0.5, "test fraction must be between 0.05 and 0.5")
    if degree is not None:
        require(1 <= degree <= 12, "degree must be between 1 and 12")
    model = layout if isinstance(layout, Model) else load(layout)
    bar = _progress(4, progress)
    bar.set_postfix_str("read")
    if isinstance(files, instruments.Observations):
        parts, obs = [files], files
    else:
        from ..results import file_list

        parts = instruments.read_parts(file_list(files), model)
        obs = instruments.stack(parts)
    from .defaults import default_parameters

    ranges = data_ranges(model, obs)
    declared = parameters if parameters is not None else declared_parameters(obs)
    req = terms.request(declared, model, default_parameters(
        model, campaign_kinds(obs), moving_axes(model, ranges)))
    chosen = req.parameters
    obs = with_directions(obs, parts, req.reversals)
    extra_terms = extra_terms + reversal_terms(model, obs, req, explicit=parameters is not None)
    spl = split_points(obs.n, seed, test_fraction, None)
    w, u_ref = reading_weights(obs)
    degree, degree_scores = _degree(model, obs, spl, ranges, req, degree, max_degree, w)
    bar.update()
    bar.set_postfix_str("degree")
    keep, gauge = gauge_mask(model, obs, degree, ranges, chosen, constants=False)
    keep &= np.array([req.fits(lab) for lab in
                      declared_design(model, obs.subset(np.arange(1)), degree, ranges).labels])
    gauge = [g for g in gauge if req.fits(g)]
    design = blocks.Design(model, obs, degree, ranges, keep)
    labels = list(design.labels)
    require(extra_terms or any(lab[0] != "setup" for lab in labels),
            f"--parameters {parameters!r}: nothing left to fit (fixed by the gauge: "
            f"{', '.join(terms.namer(model, ranges)(g) for g in gauge) or 'none'})")
    if extra_terms:
        design = design.plus([extra_columns(model, obs, extra_terms)])
        labels += [(name, "extra") for name, *_ in extra_terms]
    bar.update()
    bar.set_postfix_str("normal equations")
    fit = _normal_equations(design, obs, spl, np.sqrt(w))
    bar.update()
    bar.set_postfix_str("solve, residuals")
    prefer = _preferred(model, obs, labels, ranges)
    out = _solve(design, labels, obs, spl, fit, np.sqrt(w), u_ref, prefer)
    bar.update()
    bar.close()
    units = {name: unit for name, _, _, unit in extra_terms}
    report = _report(model, obs, labels, ranges, degree, degree_scores, chosen, gauge, out, spl,
                     u_ref, units)
    report["fitted_terms"] = _fitted_terms(req, terms.namer(model, ranges))
    if plan:
        from .plan import suggest

        report["plan"] = suggest(model, parts, design, labels, fit.G, report["unidentifiable"],
                                 u_ref, report["identifiability"])
    std = np.zeros(design.p)
    std[out.kept] = out.std
    fields = (model, ranges, degree, labels, out.coef, std, out.residuals, out, parts,
              fit_quality(out, u_ref))
    report["fit"] = fields[-1].to_dict()
    # the lab report and the covariance are computed from a draft of the result, then the
    # result is built once with the whole report (nothing written back into it afterwards)
    draft = Calibration(report, *fields)
    report = _lab_report(draft, fit, obs, u_ref)
    report["covariance"] = covariance_block(draft)
    from .budget import budgets
    report["budgets"] = budgets(draft, fit, u_ref)
    report["seconds"] = round(time.perf_counter() - t0, 2)
    return report, fields


def fit_quality(sol, u_ref: float) -> FitQuality:
    """The residual of the fit against the readings' declared uncertainty
    (:mod:`volerr.fit_quality`): ``chi2 = s0^2 dof = sum (r / u)^2`` over all readings."""
    return judge(sol.s0 ** 2 * sol.dof, sol.dof,
                 f"u of each reading as declared in its file, else its instrument's default; "
                 f"median {1e3 * u_ref:.3g} um")


def covariance_block(cal) -> dict | None:
    """``{"names", "units", "values", "matrix", "degree", "ranges", "note"}``: the written
    model parameters (determined ones and the carriers of determined combinations, not the
    set-up unknowns nor extra terms), their values and covariance (scaled by the a-posteriori
    variance factor) in the units the report gives them (um, urad, um/mm ...), and the degree
    and measured ranges (mm, deg) their series terms refer to -- what ``volerr check`` and
    ``volerr history`` need of a reference calibration; None without a solution."""
    sol = cal.solution
    if sol is None:
        return None
    name_of = terms.namer(cal.model, cal.ranges)
    where = {int(j): i for i, j in enumerate(sol.kept)}
    cols, names, units, factors, values = [], [], [], [], []
    for j, lab in enumerate(cal.labels):
        if lab[0] == "setup" or lab[1] == "extra" or not cal.written[j] or j not in where:
            continue
        rep = terms.report(lab, 1.0, 0.0, cal.model, cal.ranges)
        cols.append(where[j])
        names.append(name_of(lab))
        units.append(rep["unit"])
        factors.append(rep["value"])
        values.append(float(cal.coef[j]) * rep["value"])
    f = np.array(factors, float)
    C = sol.cov[np.ix_(cols, cols)] * np.outer(f, f) if cols else np.zeros((0, 0))
    return {"names": names, "units": units, "values": values,
            "matrix": [[float(v) for v in row] for row in C], "degree": int(cal.degree),
            "ranges": {a: [float(lo), float(hi)] for a, (lo, hi) in cal.ranges.items()},
            "note": "covariance of the written parameters in their report units (the "
                    "a-posteriori variance factor applied); series terms refer to the degree "
                    "and measured ranges given (mm, deg)"}


def _degree(model, obs, spl, ranges, req, degree, max_degree, w) -> tuple[int, dict]:
    """Degree of the component series and the cross-validation scores (``{}`` when none ran):
    ``degree`` when given (at least the highest term requested), else the highest term
    requested when every series fitted is a term request (``EXX@slope``), else by
    cross-validation (:func:`volerr.estimate.steps.choose_degree`) and at least that."""
    need = req.max_term()
    if degree is not None:
        require(degree >= need, f"--degree {degree} is below the term requested in "
                                f"--parameters (degree {need})")
        return degree, {}
    series = [p for p in req.parameters if model.parameter_axis.get(p)]
    if not series or all(p in req.only for p in series):
        return max(1, need), {}
    found, scores = choose_degree(model, obs, spl.train, None, ranges, max_degree, weights=w,
                                  parameters=req.parameters)
    return max(found, need), scores


def with_directions(obs, parts, axes):
    """``obs`` with the direction covariates ``dir_<axis>`` of ``axes`` over all files: a
    file where the axis does not move (a circle in YZ for X) has none of its own and gets 0
    (no reversal acts); stacking keeps only the covariates every file has."""
    if len(parts) < 2:
        return obs
    for axis in axes:
        name = f"dir_{axis}"
        if name in obs.covariates or not any(name in p.covariates for p in parts):
            continue
        obs.covariates[name] = np.concatenate([np.asarray(p.covariates.get(name, np.zeros(p.n)),
                                                          float) for p in parts])
    return obs


def reversal_terms(model, obs, req, explicit: bool) -> list:
    """Extra terms (see :func:`calibrate`) of the reversals ``RV_<axis>`` requested: the
    positioning error of the axis plus ``RV/2`` approaching in the positive direction, minus
    ``RV/2`` in the negative one (``dir_<axis>`` of the readings).  A reversal the readings
    cannot show (one direction only) is refused when asked for explicitly, skipped when it
    comes from the defaults."""
    from ..machine.iso_names import along_component

    out = []
    for axis in req.reversals:
        d = obs.covariates.get(f"dir_{axis}")
        both = d is not None and len(np.unique(np.sign(np.asarray(d)[np.asarray(d) != 0]))) == 2
        if not both:
            require(not explicit, f"--parameters: RV_{axis} needs readings approaching in "
                                  f"both directions of {axis} (dir_{axis} +1 and -1)")
            continue
        comp = along_component(model.layout, axis)
        if comp in model.parameters:
            out.append((f"RV_{axis}", comp, f"dir_{axis}/2", (1e3, "um")))
    return out


def _fitted_terms(req, name_of) -> list:
    """The request as names: whole parameters, the terms of term requests (``name_of`` a
    :func:`volerr.calibrate.terms.namer`), ``RV_<axis>``."""
    out = []
    for p in req.parameters:
        if p in req.only:
            out += [name_of((p, k)) for k in sorted(req.only[p])]
        else:
            out.append(p)
    return out + [f"RV_{a}" for a in req.reversals]


def _preferred(model, obs, labels, obs_ranges) -> np.ndarray:
    """(p,) bool: the columns the campaign's instruments are used for
    (:func:`volerr.calibrate.defaults.default_parameters`); where the requested set is
    rank-deficient the solution keeps them before the others."""
    from .defaults import default_parameters

    req = terms.request(None, model, default_parameters(model, campaign_kinds(obs),
                                                         moving_axes(model, obs_ranges)))
    return np.array([lab[0] != "setup" and (lab[1] == "extra" or req.fits(lab))
                     for lab in labels])


def _lab_report(cal, fit, obs, u_ref) -> dict:
    """``cal.data`` (not changed) with what a calibration laboratory reports beside the
    parameters: the consistency of the files with each other
    (:mod:`volerr.calibrate.consistency`), the instruments' own results (artifact poses,
    station positions), the volumetric error map with its uncertainty
    (:mod:`volerr.calibrate.mapping`) and the ISO 10360-2 length errors of the identified
    model beside the measured step-gauge lengths (:mod:`volerr.calibrate.lengths`)."""
    from . import consistency, lengths, mapping

    report = dict(cal.data)
    report["consistency"] = consistency.check(fit, cal.solution, obs, u_ref)
    flags = {e["file"]: e for e in report["consistency"]["files"]}
    report["instruments"] = [
        {**entry, "birge_ratio": flags.get(entry["file"], {}).get("birge_ratio"),
         "consistent": flags.get(entry["file"], {}).get("consistent", True)}
        for entry in report["instruments"]]
    kinds = instruments.kinds()
    for part in cal.parts:
        kind = part.files[0].kind if part.files else "deviations"
        maker = getattr(kinds.get(kind), "results", None)
        if maker is not None:
            for key, value in maker(part, report["setup"]).items():
                report[key] = {**report.get(key, {}), **value}
    summary = mapping.summary(cal)
    if summary is not None:
        report["volumetric_map"] = summary
    iso = lengths.report(cal)
    if iso is not None:
        report["iso10360"] = iso
    return report


def extra_columns(model, obs, extra_terms) -> np.ndarray:
    """(N, 3, m) columns of ``extra_terms`` (see :func:`calibrate`): the readings'
    sensitivity to the target parameter times the basis."""
    from ..estimate.design import rotary_rad
    from ..machine.expressions import evaluate

    sens = obs.sensitivity(model)
    values = {**rotary_rad(model, obs.positions), **obs.covariates}
    out = np.zeros((obs.n, 3, len(extra_terms)))
    for k, (name, target, basis, _) in enumerate(extra_terms):
        require(target in model.parameters, f"{name}: {target} is not a parameter of "
                                            f"{model.name}")
        b = np.broadcast_to(evaluate(basis, values), (obs.n,))
        out[:, :, k] = sens[:, :, model.parameters.index(target)] * b[:, None]
    return out


@dataclass
class Normal:
    """Weighted normal equations of the design: all readings (``G``, ``b``), training readings
    (``G_tr``, ``b_tr``), and per file (``G_files`` with the priors of its set-up columns,
    ``b_files``, ``yy_files`` the weighted sum of squares of its readings, ``priors_files``
    the number of its priors)."""

    G: np.ndarray
    b: np.ndarray
    G_tr: np.ndarray
    b_tr: np.ndarray
    G_files: list
    scale: np.ndarray
    b_files: list = field(default_factory=list)
    yy_files: list = field(default_factory=list)
    priors_files: list = field(default_factory=list)


def _normal_equations(design, obs, spl, sw) -> Normal:
    p = design.p
    n_files = max(len(obs.files), 1)
    file_of = obs.file if obs.file is not None else np.zeros(obs.n, int)
    is_test = np.zeros(obs.n, bool)
    is_test[spl.test] = True
    G_files = [np.zeros((p, p)) for _ in range(n_files)]
    b_files = [np.zeros(p) for _ in range(n_files)]
    G_te, b_te = np.zeros((p, p)), np.zeros(p)
    yy_files = [0.0] * n_files
    y = obs.deviation.ravel()
    ss = np.zeros(p)
    for f in range(n_files):
        pts = np.flatnonzero(file_of == f)
        for s, idx in blocks.blocks(pts):
            At = design.block(idx)
            ss += np.einsum("ij,ij->i", At, At)
            wr = blocks.wrows(sw[idx])
            At *= wr
            yw = blocks.yrows(y, idx) * wr
            G_files[f] += At @ At.T
            b_files[f] += At @ yw
            yy_files[f] += float(yw @ yw)
            te = np.tile(is_test[idx], 3)
            if te.any():
                G_te += At[:, te] @ At[:, te].T
                b_te += At[:, te] @ yw[te]
    # columns the readings do not see at all (numerically): zeroed before any test
    off = np.zeros(p, bool)
    off[:len(design.labels)] = estimability.negligible(
        design.model, obs, design.labels, design.degree, design.ranges,
        ss[:len(design.labels)], obs.n_readings)
    if off.any():
        for M in G_files + [G_te]:
            M[off, :] = 0.0
            M[:, off] = 0.0
        for v in b_files + [b_te]:
            v[off] = 0.0
        ss[off] = 0.0
    # known set-up values (a calibrated bar length): a prior 0 +- u on the column
    u_ref = _u_ref(sw, obs)
    priors = dict(zip(obs.setup_labels, obs.setup_priors))
    priors_files = [0] * n_files
    for j, lab in enumerate(design.labels):
        u = priors.get(lab[1]) if lab[0] == "setup" else None
        if u:
            for f, Gf in enumerate(G_files):
                if Gf[j, j] > 0:
                    Gf[j, j] += (u_ref / u) ** 2
                    priors_files[f] += 1
    G, b = sum(G_files), sum(b_files)
    scale = blocks.unit_scale(ss, obs.n_readings)
    return Normal(G, b, G - G_te, b - b_te, G_files, scale, b_files, yy_files, priors_files)


def _u_ref(sw, obs) -> float:
    return reading_weights(obs)[1]


@dataclass
class Solution:
    kept: np.ndarray            # column indices in the solution
    cov: np.ndarray             # covariance of the kept columns (mm, rad)
    null: np.ndarray            # null space (p, k) of the unit-scaled columns
    norms: np.ndarray           # (p,) column norms (weighted)
    coef: np.ndarray            # (p,) mm / rad, 0 where left out
    coef_train: np.ndarray
    std: np.ndarray             # of the kept columns
    estimable: np.ndarray       # (p,) bool
    partners: dict
    seen: np.ndarray            # (files, p) bool
    s0: float                   # a-posteriori standard deviation of unit weight (u_ref = 1)
    dof: float
    rms_all: dict               # file index -> RMS um of all readings
    rms_test: dict              # file index -> RMS um of held-out readings
    n_test: dict
    residuals: dict
    rss_files: dict = field(default_factory=dict)   # file -> weighted residual SS (mm^2)
    Gi: np.ndarray | None = None                     # inverse of the unit-scaled kept Gram
    mixes: dict = field(default_factory=dict)        # kept column -> {left-out column: B}
    budget_terms: list | None = None   # per file its covariance term (budget.budgets)


def _solve(design, labels, obs, spl, fit: Normal, sw, u_ref: float, prefer=None) -> Solution:
    est, partners = estimability.estimable(fit.G)
    setup_idx = [j for j, lab in enumerate(labels) if lab[0] == "setup"]
    setup_of_file = [[j for j in setup_idx if Gf[j, j] > 0] for Gf in fit.G_files]
    seen = estimability.seen_by(fit.G_files, setup_of_file)
    keep_d, _ = identifiability_gram(fit.G, labels, prefer=prefer)
    kept = np.flatnonzero(keep_d)
    is_param = np.array([lab[0] != "setup" for lab in labels])
    mixes = estimability.combinations(fit.G, kept, is_param & ~est)
    sc = fit.scale[kept]
    S = np.outer(sc, sc)
    Gk = fit.G[np.ix_(kept, kept)] / S
    Gi = blocks.eig_inverse(Gk, SOLVE_TOL)
    coef = np.zeros(design.p)
    coef[kept] = Gi @ (fit.b[kept] / sc) / sc
    Gti = blocks.eig_inverse(fit.G_tr[np.ix_(kept, kept)] / S, SOLVE_TOL)
    coef_tr = np.zeros(design.p)
    coef_tr[kept] = Gti @ (fit.b_tr[kept] / sc) / sc
    # residuals, blockwise: all readings (fit on all) and held-out ones (fit on training)
    y = obs.deviation.ravel()
    file_of = obs.file if obs.file is not None else np.zeros(obs.n, int)
    is_test = np.zeros(obs.n, bool)
    is_test[spl.test] = True
    rows = obs.readings_per_point()
    rss_w = 0.0
    rms_all, rms_test, n_test, residuals, rss_files = {}, {}, {}, {}, {}
    for f in range(len(fit.G_files)):
        pts = np.flatnonzero(file_of == f)
        r_all = np.empty((len(pts), 3))
        r_tr = np.empty((len(pts), 3))
        for s, idx in blocks.blocks(pts):
            At = design.block(idx)
            yy = blocks.yrows(y, idx)
            n = len(idx)
            r_all[s] = (yy - coef @ At).reshape(3, n).T
            r_tr[s] = (yy - coef_tr @ At).reshape(3, n).T
        rss_files[f] = float(np.sum((r_all * sw[pts, None]) ** 2))
        rss_w += rss_files[f]
        k = rows[pts]
        n_read = max(int(k.sum()), 1)
        factor = unit_factor(obs, f)
        rms_all[f] = factor * math.sqrt(float(np.sum(r_all ** 2)) / n_read)
        te = is_test[pts]
        n_te = int(k[te].sum())
        n_test[f] = n_te
        rms_test[f] = (factor * math.sqrt(float(np.sum(r_tr[te] ** 2)) / n_te)
                       if n_te else float("nan"))
        residuals[f] = (pts, factor * r_all, k)
    rank = int(np.sum(np.linalg.eigvalsh(Gk) > SOLVE_TOL * np.linalg.eigvalsh(Gk)[-1]))
    dof = max(float(obs.n_readings - rank), 1.0)
    s0 = math.sqrt(rss_w / dof) / u_ref         # the a-posteriori factor, dimensionless
    # GUM practice: a scatter below the stated reading uncertainty (s0 < 1) never shrinks the
    # stated uncertainties (the a-priori covariance is kept); s0 > 1 widens them
    cov = Gi / np.outer(sc, sc) * (max(s0, 1.0) * u_ref) ** 2
    std = np.sqrt(np.maximum(np.diag(cov), 0.0))
    return Solution(kept, cov, estimability.null_space(fit.G),
                    np.sqrt(np.maximum(np.diag(fit.G), 0.0)), coef, coef_tr, std, est, partners,
                    seen, s0, dof, rms_all, rms_test, n_test, residuals, rss_files, Gi, mixes)


def unit_factor(obs, f: int) -> float:
    """Report factor of file ``f``'s readings: 1e6 (rad -> urad) for angular readings, else
    1e3 (mm -> um)."""
    files = obs.files
    return 1e6 if files and f < len(files) and files[f].unit == "urad" else 1e3


def _report(model, obs, labels, ranges, degree, degree_scores, chosen, gauge, out, spl, u_ref,
            units) -> dict:
    name_of = terms.namer(model, ranges)
    names = [name_of(lab) for lab in labels]
    std_of = dict(zip(out.kept.tolist(), out.std.tolist()))
    files = obs.files or (instruments.FileInfo("data", "deviations"),)
    params, unident, ident = {}, [], {}
    for j, lab in enumerate(labels):
        if lab[0] == "setup":
            continue
        name = names[j]
        seen = [files[f].name for f in range(len(files)) if out.seen[f, j]]
        ident[name] = {
            "identifiable": bool(out.estimable[j]),
            "seen_by": seen,
            "not_seen_by": [fi.name for fi in files if fi.name not in seen],
            "confounded_with": [names[k] for k in out.partners.get(j, [])][:6]}
        if out.estimable[j] and j in std_of:
            params[name] = terms.report(lab, out.coef[j], std_of[j], model, ranges,
                                        units.get(lab[0]))
        else:
            unident.append(name)
    combos = [_combination(k, mix, labels, names, out, std_of, model, ranges, units)
              for k, mix in sorted(out.mixes.items())]
    setup = {}
    units = obs.setup_units
    setup_labels = obs.setup_labels
    for j, lab in enumerate(labels):
        if lab[0] != "setup":
            continue
        key = lab[1]
        i = setup_labels.index(key)
        group, _, k = key.rpartition(".") if "." in key else (files[0].name, "", key)
        factor = 1e6 if units[i] in ("urad", "ppm") else 1e3
        entry = {"value": float(out.coef[j]) * factor, "unit": units[i],
                 "std": float(std_of.get(j, 0.0)) * factor,
                 "determined": bool(out.estimable[j])}
        setup.setdefault(group, {})[k] = entry
    inst = []
    file_of = obs.file if obs.file is not None else np.zeros(obs.n, int)
    rows_in_file = obs.row if obs.row is not None else np.arange(obs.n)
    test_set = set(spl.test.tolist())
    for f, fi in enumerate(files):
        pts = np.flatnonzero(file_of == f)
        inst.append({
            "file": fi.name, "kind": fi.kind, "n": int(len(np.unique(rows_in_file[pts]))),
            "n_readings": int(obs.readings_per_point()[pts].sum()), "unit": fi.unit,
            "rms_residual": round(out.rms_all[f], 5),
            "heldout_rms": round(out.rms_test[f], 5), "n_heldout": out.n_test[f],
            "test_rows": sorted({int(rows_in_file[i]) for i in pts if int(i) in test_set}),
            "normalised_rms": round(out.rms_all[f] / (unit_factor(obs, f)
                                                      * _file_u(obs, pts, u_ref)), 4)})
    return {
        "layout": model.name,
        "parameters": params,
        "unidentifiable": unident,
        "combinations": combos,
        "setup": setup,
        "instruments": inst,
        "identifiability": ident,
        "fitted": list(chosen),
        "degree": int(degree),
        "degree_cv_rms_um": {str(k): round(1e3 * v, 4) for k, v in degree_scores.items()},
        "gauge_fixed": [name_of(g) for g in gauge],
        "variance_factor": round(out.s0 ** 2, 4),
        "uncertainty_scaled": bool(out.s0 > 1.0),
        "dof": out.dof,
        "method": ("weighted least squares (weights 1/u^2 per reading) over all files; "
                   "standard uncertainties (k = 1) from the covariance scaled by the "
                   "a-posteriori variance factor when it exceeds 1 (a factor below 1 never "
                   "shrinks the stated uncertainties: the a-priori ones are kept); held-out: a random {:.0%} of the points, fitted on the "
                   "others").format(len(spl.test) / max(obs.n, 1)),
    }


def _combination(k, mix, labels, names, out, std_of, model, ranges, units) -> dict:
    """``{"expression", "value", "unit", "std", "written_as"}`` of the combination the kept
    column ``k`` estimates (``mix`` {left-out column: coefficient}, natural units; see
    :func:`volerr.calibrate.estimability.combinations`), in the report units of ``k``."""
    def factor(j):
        return terms.report(labels[j], 1.0, 0.0, model, ranges, units.get(labels[j][0]))

    rep_k = factor(k)
    text = names[k]
    for d, b in sorted(mix.items(), key=lambda e: -abs(e[1]) * factor(e[0])["value"]):
        rep_d = factor(d)
        f, unit = _ratio_unit(rep_k["unit"], rep_d["unit"])
        c = b * rep_k["value"] / rep_d["value"] * f
        coeff = "" if abs(abs(c) - 1.0) < 1e-6 and not unit else f"{abs(c):.4g}{unit} * "
        text += f" {'-' if c < 0 else '+'} {coeff}{names[d]}"
    entry = terms.report(labels[k], out.coef[k], std_of.get(k, 0.0), model, ranges,
                         units.get(labels[k][0]))
    return {"expression": text, **entry, "written_as": names[k]}


def _ratio_unit(num: str, den: str) -> tuple[float, str]:
    """(factor, unit) of a coefficient turning a ``den`` quantity into a ``num`` one (the
    coefficient in ``num / den`` times the factor is in the unit): a lever arm in mm (um per
    urad), a length in mm (urad per urad/mm) ...; (1, "") when the units are equal."""
    n, _, n_per = num.partition("/")
    d, _, d_per = den.partition("/")
    if n_per == d_per:
        n_per = d_per = ""
    base = {("um", "urad"): (1e3, 1), ("urad", "um"): (1e-3, -1), ("um", "um"): (1.0, 0),
            ("urad", "urad"): (1.0, 0)}.get((n, d))
    if base is None or (n_per and d_per):
        return 1.0, f" {num}/({den})"
    factor, mm = base
    mm += d_per == "mm"
    mm -= n_per == "mm"
    parts = {0: [], 1: ["mm"], 2: ["mm^2"], -1: ["/mm"], -2: ["/mm^2"]}[mm]
    if d_per == "deg":
        parts.append("deg")
    if n_per == "deg":
        parts.append("/deg")
    return factor, (" " + " ".join(parts)) if parts else ""


def _file_u(obs, pts, u_ref) -> float:
    if obs.sigma is None:
        return u_ref
    u = np.asarray(obs.sigma)[pts]
    u = u[np.isfinite(u)]
    return float(np.sqrt(np.mean(u ** 2))) if len(u) else u_ref
