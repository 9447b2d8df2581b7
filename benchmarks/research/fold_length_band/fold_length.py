"""Research version of RULE.md's rule (not the package), patched into the CLI's process by
``sitecustomize.py`` when ``FOLD_LENGTH=1``.

On top of ``../nested_band/``'s candidate 2 (imported, not copied: the nested choice of the
lag model, ``q`` the scale at which one more fold's expected coverage is 95 %,
:func:`nested_band.expected_q`), the band's scale ``q`` is calibrated on CV residuals of the
chosen family from *long folds*: ``K_L = max(2, round(n_train / n_test))`` contiguous
stretches of every training run (:func:`long_folds`), so that a fold is about as long as the
held-out stretch (FL_THERMAL's 20 % windows: 4 folds of 20 %; the publication split, 60 %
training and 40 % held out: 2 folds of 30 %).  The chosen family's procedure is rerun on
them: the constant, the static regression and the lag model (its terms as selected today,
not reselected) by :func:`volerr.loop.drift.family.cv_residuals`, the regularised fit by
:func:`volerr.loop.drift.shrink.fit` (its lambda chosen again on the long folds); the
leverage of the CV readings under the long folds' fits by ``fit._leverage``.  ``q`` =
``expected_q`` of those scores over the long folds; the held-out ``sigma`` (the fit on all
training readings) unchanged.  Folds of whole runs (``runs`` / ``environments``) are kept
as they are (a fold is a run already).

``FOLD_LENGTH_LOG=FILE``: one JSON line per channel: {"json", "label", "family", "K_long",
"q_c2", "q_long", "n_test", "inside_c2", "inside_long"} (inside: held-out readings with
abs(y - pred) <= q sigma, before the room / kept-out widenings; FL_THERMAL has none)."""
import dataclasses
import json
import os
import sys

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "nested_band"))
os.environ.setdefault("NESTED_BAND", "2")
import nested_band  # noqa: E402  (candidate 2 of ../nested_band, reused as it is)

from volerr.loop.drift import basis, family, fit, shrink  # noqa: E402
from volerr.loop.drift import interval as band  # noqa: E402

_q_long = {}


def long_folds(ch) -> tuple:
    """(fold (N,), K_L): every training run cut into ``K_L = max(2, round(n_train /
    n_test))`` contiguous stretches of nearly equal reading counts (``basis.folds``' rule
    with ``K_L`` for ``K_FOLDS``); today's folds where they are whole runs."""
    tr = ch.fold >= 0
    n_test = int(np.sum(ch.fold < 0))
    if basis.whole_runs(ch.rule) or n_test == 0:
        return ch.fold, int(ch.fold.max()) + 1
    K = max(2, int(round(tr.sum() / n_test)))
    f = np.full(len(ch.fold), -1)
    for r in np.unique(ch.s.run[tr]):
        idx = np.flatnonzero(tr & (ch.s.run == r))
        f[idx] = np.minimum(np.arange(len(idx)) * K // len(idx), K - 1)
    return f, K


MODE = os.environ.get("FOLD_LENGTH", "")


def long_scores(ch, out, cols, Z) -> tuple:
    """(cv_resid, sigma, fold, K, diagnostics) of the chosen family on the long folds (module
    docstring); ``FOLD_LENGTH=2`` (RULE.md addendum 1): the regularised fit's lambda and the
    autocorrelation factor ``c`` kept at today's (the six folds'), those of the held-out
    readings' ``sigma``."""
    fold, K = long_folds(ch)
    lams = shrink.LAMBDAS
    if MODE == "2":
        shrink.LAMBDAS = np.array([out["shrink"]["lambda_rel"]])
    chl = dataclasses.replace(ch, fold=fold)
    fam = out["choice"]["family"]
    designs = {"constant": ch.R, "static": fit._static_design(ch), "lag": out["fit"]["design"]}
    cache = {}
    keep = out["shrink"]["keep"]
    try:
        reg = shrink.fit(ch.s, ch.y, Z, keep, [cols[j - ch.n_runs] for j in keep], fold,
                         ch.rule, cache)
    finally:
        shrink.LAMBDAS = lams
    reg["keep"] = keep
    r = reg["cv_resid"] if fam == "regularised" else family.cv_residuals(chl, designs[fam])
    lev = fit._leverage(chl, fam, designs, reg, Z, cache)
    rho_long = band.autocorrelation(r, fold)
    rho_today = band.autocorrelation(out["choice"]["cv_resid"], ch.fold)
    rho = rho_today if MODE == "2" else rho_long
    sigma = np.sqrt(1.0 + (1.0 + rho) / (1.0 - rho) * np.nan_to_num(lev, nan=0.0))
    tr = fold >= 0
    diag = {"lambda_today": out["shrink"]["lambda_rel"], "lambda_long": reg["lambda_rel"],
            "rho_today": rho_today, "rho_long": rho_long,
            "cv_rms_long": float(np.sqrt(np.nanmean(r[tr] ** 2))),
            "cv_rms_today": float(np.sqrt(np.nanmean(out["choice"]["cv_resid"][ch.fold >= 0] ** 2))),
            "median_sigma_long": float(np.nanmedian(sigma[tr]))}
    return r, sigma, fold, K, diag


_c2_channel = nested_band._channel


def _channel(ch, cols, Z, cands, cache):
    """Candidate 2's channel (the nested choice), then ``q`` on the long folds."""
    out = _c2_channel(ch, cols, Z, cands, cache)
    label = next((l for l, v in ch.s.channels.items() if v is ch.y), "?")
    r, sigma, fold, K, diag = long_scores(ch, out, cols, Z)
    _q_long[label] = (nested_band.expected_q(r, sigma, fold), K, diag)
    return out


_c2_interval = nested_band.interval


def interval(cv_resid, y, pred, fold, test, lev=None) -> dict:
    """Candidate 2's interval with ``q`` replaced by the long folds' (the same sigma)."""
    iv = _c2_interval(cv_resid, y, pred, fold, test, lev)
    label = nested_band._state["label"]
    if label not in _q_long:
        return iv
    q_long, K, diag = _q_long[label]
    q_c2 = iv["q"]
    hw = np.asarray(iv["per_reading"]) * (q_long / q_c2)
    e = np.abs((y - pred)[test])
    path = os.environ.get("FOLD_LENGTH_LOG")
    if path:
        argv = sys.argv
        with open(path, "a") as f:
            f.write(json.dumps({"json": argv[argv.index("--json") + 1] if "--json" in argv else "",
                                "label": label, "family": nested_band._state["family"],
                                "K_long": K, "q_c2": q_c2, "q_long": q_long,
                                "n_test": int(len(e)),
                                "inside_c2": int(np.sum(e <= iv["per_reading"][test])),
                                "inside_long": int(np.sum(e <= hw[test])),
                                "median_sigma_test": float(np.median(iv["per_reading"][test]) / q_c2),
                                **diag}) + "\n")
    at = hw[test] if np.any(test) else hw
    iv.update({"half_width_um": float(np.median(at)),
               "half_width_um_range": [float(np.min(at)), float(np.max(at))], "q": q_long,
               "coverage_test": float(np.mean(e <= hw[test])) if len(e) else None,
               "method": iv["method"].replace("one more fold's expected coverage",
                                              "one more long fold's (as long as the held-out "
                                              "stretch) expected coverage"),
               "per_reading": hw})
    return iv


def install():
    nested_band.install()          # candidate 2: nested choice, expected-coverage q
    band.interval = interval
    fit._channel = _channel
