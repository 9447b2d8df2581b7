"""Error functions fitted to identified error motions, with their fit residuals.

The thesis (ch. 3.4, Listing 3.1) fits each error motion with a polynomial whose degree (4-8)
was picked by eye.  Here the degree is chosen by leave-one-out cross-validation with the
one-standard-error rule (``volerr.tables.functions.choose_degree``), or a cubic smoothing spline whose
smoothing is chosen by generalised cross-validation (``scipy.interpolate.
make_smoothing_spline``), or the interpolating methods of ``volerr.tables.table`` (linear, cubic).
Every fit reports its residual (RMS and maximum at the measured positions) and, for the
smoothing methods, the leave-one-out prediction error.  Evaluating a fit outside the measured
range raises :class:`InputError` unless ``extrapolate=True``.

With ``weights`` from the Type A standard deviations (``1/std``) the polynomial and the
smoothing spline are weighted fits; the reference position (std 0) then gets the largest
finite weight of the table.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..units import UM_PER_MM, URAD_PER_RAD
from ..errors import InputError, require
from . import legendre
from .functions import make_function
from .table import ErrorTable, parameter_kind

METHODS = ("poly", "smooth", "linear", "cubic")


@dataclass
class Fit:
    """One fitted error function (mm or rad of a position in mm or deg)."""

    name: str
    method: str
    lo: float
    hi: float
    func: object
    degree: int | None
    rms_residual: float
    max_residual: float
    loo_rms: float | None

    def __call__(self, q, extrapolate: bool = False):
        q = np.asarray(q, dtype=float)
        if not extrapolate:
            span = self.hi - self.lo
            tol = 1e-9 * max(span, 1.0)
            bad = (q < self.lo - tol) | (q > self.hi + tol)
            if np.any(bad):
                v = q[bad].flat[0]
                raise InputError(f"{self.name}: position {v:g} is outside the measured range "
                                 f"[{self.lo:g}, {self.hi:g}]; extrapolation needs an explicit "
                                 f"flag")
        return np.asarray(self.func(q), dtype=float)

    def report(self) -> dict:
        """Residuals in um or urad."""
        k = UM_PER_MM if parameter_kind(self.name) == "length" else URAD_PER_RAD
        return {"name": self.name, "method": self.method, "degree": self.degree,
                "rms_residual": self.rms_residual * k, "max_residual": self.max_residual * k,
                "loo_rms": None if self.loo_rms is None else self.loo_rms * k,
                "unit": "um" if k == UM_PER_MM else "urad"}


def _smooth(x, y, w):
    from scipy.interpolate import make_smoothing_spline

    require(x.size >= 5, "a smoothing spline needs at least five positions")
    return make_smoothing_spline(x, y, w=None if w is None else w ** 2)


def fit(name: str, x, y, method: str = "poly", degree: int | None = None,
        max_degree: int | None = None, weights=None) -> Fit:
    """Fit one error function; see the module docstring."""
    require(method in METHODS, f"unknown fit method {method!r} ({', '.join(METHODS)})")
    x = np.asarray(x, dtype=float)
    y = np.asarray(y, dtype=float)
    require(x.size >= 2 and np.all(np.diff(x) > 0), f"{name}: positions must increase")
    w = None if weights is None else np.asarray(weights, dtype=float)
    if w is not None:
        require(w.shape == x.shape and np.all(w > 0) and np.all(np.isfinite(w)),
                f"{name}: weights must be positive and finite, one per position")
        w = w / np.mean(w)
    loo = None
    if method == "poly":
        require(degree is None or 0 <= degree < x.size,
                f"polynomial degree {degree} needs more than {degree} positions, the table "
                f"has {x.size}")
        f = legendre.fit(x, y, degree, w, max_degree)
        degree = f.degree
        loo = float(np.sqrt(np.mean(legendre.loo_errors(x, y, degree, w) ** 2)))
    elif method == "smooth":
        f = _smooth(x, y, w)
        degree = None
    else:
        f = make_function(x, y, method)
        degree = None
    res = y - np.asarray(f(x))
    return Fit(name, method, float(x[0]), float(x[-1]), f, degree,
               float(np.sqrt(np.mean(res ** 2))), float(np.max(np.abs(res))), loo)


def fit_table(table: ErrorTable, method: str = "poly", degree: int | None = None,
              max_degree: int | None = None, weighted: bool = False) -> dict:
    """Fit every error motion of a table -> name -> :class:`Fit`.

    ``weighted``: weights ``1 / std`` from the table's Type A standard deviations (zero std,
    e.g. at the reference position, gets the largest finite weight)."""
    out = {}
    for name, y in table.values.items():
        w = None
        if weighted and name in table.std:
            s = np.asarray(table.std[name], dtype=float)
            pos = s[s > 0]
            if pos.size:
                w = 1.0 / np.where(s > 0, s, pos.min())
        out[name] = fit(name, table.positions, y, method, degree, max_degree, w)
    return out
