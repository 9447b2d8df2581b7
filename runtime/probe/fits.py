"""Fits behind the probe calibration: the least-squares sphere through the stylus-ball
centres and the smooth spherical-harmonic map of the probe error (Pahk sec. 3, eq. 13).

Lengths mm, angles rad (the calibration module converts from deg).  Public names are
re-exported by :mod:`volerr.probe.calibration`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from ..errors import require
from ..units import UM_PER_MM

#: fewest points the calibration accepts: 4 sphere unknowns plus redundancy for the error map
MIN_POINTS = 6
#: robust outlier threshold: studentised residual of a bisquare map fit > k robust sigmas
OUTLIER_K = 5.0
#: floor of the robust scale (mm): below it residuals are numerical, not noise
SCALE_FLOOR_MM = 5e-5
#: points whose out-of-plane RMS spread is below this fraction of their in-plane spread lie on
#: "one plane": a sphere through them is fixed only by their noise or lobing
PLANE_RATIO = 2e-3
#: largest condition number of the sphere-fit Jacobian (a cap of ~6 deg half-angle reaches it)
MAX_CONDITION = 1e3
#: smoothness ridge of the map fit, relative to the mean diagonal of the normal matrix
RIDGE = 1e-4
#: largest map degree considered by the automatic choice
MAX_DEGREE = 8


# ---- sphere fit ------------------------------------------------------------------------------
@dataclass
class SphereFit:
    """Least-squares sphere: centre (3,) mm, radius mm, residuals |p - c| - r (n,) mm."""

    center: np.ndarray
    radius: float
    residuals: np.ndarray
    condition: float
    iterations: int
    cov_unit: np.ndarray  # inv(J'J) of (cx, cy, cz, r): covariance per unit residual variance


def check_sphere_points(points) -> np.ndarray:
    """Validate ball centres for a sphere fit (count, finiteness, not all on one plane)."""
    p = np.asarray(points, dtype=float)
    require(p.ndim == 2 and p.shape[1] == 3, f"points must be (n, 3), got shape {p.shape}")
    require(np.all(np.isfinite(p)), "points contain NaN or infinite values")
    n = len(p)
    require(n >= MIN_POINTS, f"{n} points: the calibration needs at least {MIN_POINTS} "
                             "(4 sphere unknowns plus redundancy for the probe error map)")
    s = np.linalg.svd(p - p.mean(axis=0), compute_uv=False) / math.sqrt(n)
    require(s[0] > 1e-9, "all points coincide: no sphere can be fitted")
    require(s[2] > PLANE_RATIO * s[0],
            f"all {n} points lie on one plane (a single circle, out-of-plane spread "
            f"{s[2] * UM_PER_MM:.2g} um): the sphere is undetermined; probe several latitudes")
    return p


def _algebraic_sphere(p: np.ndarray):
    """Linear (Kasa) fit |p|^2 = 2 c.p + k: the starting point of the geometric fit."""
    mu = p.mean(axis=0)
    q = p - mu
    a = np.column_stack([2 * q, np.ones(len(q))])
    b = np.sum(q * q, axis=1)
    sol, *_ = np.linalg.lstsq(a, b, rcond=None)
    c = sol[:3]
    r2 = sol[3] + c @ c
    require(r2 > 0, "the points do not lie on a sphere (algebraic fit has no real radius)")
    return c + mu, math.sqrt(r2)


def fit_sphere(points, max_iter: int = 50) -> SphereFit:
    """Geometric least-squares sphere (minimises sum(|p_i - c| - r)^2) by Gauss-Newton from
    the algebraic fit.  At the optimum r = mean |p_i - c|."""
    p = check_sphere_points(points)
    c, r = _algebraic_sphere(p)
    scale = r
    it = 0
    for it in range(1, max_iter + 1):
        d = p - c
        dist = np.linalg.norm(d, axis=1)
        require(np.all(dist > 0), "a point coincides with the fitted sphere centre")
        res = dist - r
        jac = np.column_stack([-d / dist[:, None], -np.ones(len(p))])
        step, *_ = np.linalg.lstsq(jac, -res, rcond=None)
        c = c + step[:3]
        r = r + step[3]
        if np.max(np.abs(step)) < 1e-13 * max(scale, 1.0):
            break
    d = p - c
    dist = np.linalg.norm(d, axis=1)
    jac = np.column_stack([-d / dist[:, None], -np.ones(len(p))])
    sv = np.linalg.svd(jac, compute_uv=False)
    cond = float(sv[0] / sv[-1]) if sv[-1] > 0 else math.inf
    require(cond < MAX_CONDITION,
            f"the points cover too little of the sphere to fit it (condition number "
            f"{cond:.3g}); probe a wider range of latitudes")
    return SphereFit(c, float(dist.mean()), dist - dist.mean(), cond, it,
                     np.linalg.inv(jac.T @ jac))


# ---- spherical-harmonic map -----------------------------------------------------------------
def sh_design(degree: int, phi, theta) -> np.ndarray:
    """Real orthonormal spherical harmonics Y_lm, l <= degree, at (phi, theta) rad:
    shape (n, (degree + 1)^2), column order l = 0..L, m = -l..l."""
    from scipy.special import lpmv

    phi = np.atleast_1d(np.asarray(phi, dtype=float))
    theta = np.atleast_1d(np.asarray(theta, dtype=float))
    x = np.cos(phi)
    cols = []
    for ll in range(degree + 1):
        for m in range(-ll, ll + 1):
            am = abs(m)
            norm = math.sqrt((2 * ll + 1) / (4 * math.pi)
                             * math.factorial(ll - am) / math.factorial(ll + am))
            leg = lpmv(am, ll, x)
            if m == 0:
                cols.append(norm * leg)
            elif m > 0:
                cols.append(math.sqrt(2) * norm * leg * np.cos(am * theta))
            else:
                cols.append(math.sqrt(2) * norm * leg * np.sin(am * theta))
    return np.column_stack(cols)


def _degrees_of(degree: int) -> np.ndarray:
    return np.concatenate([[ll] * (2 * ll + 1) for ll in range(degree + 1)]).astype(float)


@dataclass
class SHFit:
    """A fitted spherical-harmonic expansion (values in mm)."""

    degree: int
    coefficients: np.ndarray
    fitted: np.ndarray
    gcv: float
    dof: float
    hat: np.ndarray      # w_i q_i: diagonal of the (weighted) hat matrix
    q: np.ndarray        # x_i' A^-1 x_i
    weights: np.ndarray

    def loo_t(self, values, sigma: float = 1.0) -> np.ndarray:
        """Leave-one-out prediction residuals over their standard deviation: residual
        r / (1 - w q) over sigma sqrt(1 + q / (1 - w q)) (Sherman-Morrison), so that a point
        already down-weighted to zero is judged like any other."""
        one = np.clip(1.0 - self.weights * self.q, 1e-9, None)
        return (values - self.fitted) / one / (sigma * np.sqrt(1.0 + self.q / one))

    def __call__(self, phi, theta) -> np.ndarray:
        return sh_design(self.degree, phi, theta) @ self.coefficients


def _ridge_fit(degree: int, phi, theta, values, weights=None, ridge: float = RIDGE) -> SHFit:
    """(Weighted) least squares with the smoothness ridge ``lam * l(l+1) c_lm^2``,
    ``lam = ridge * trace(X'WX) / n_coefficients``."""
    x = sh_design(degree, phi, theta)
    n, p = x.shape
    wts = np.ones(n) if weights is None else np.asarray(weights, dtype=float)
    ll = _degrees_of(degree)
    xw = x * wts[:, None]
    xtx = x.T @ xw
    lam = ridge * np.trace(xtx) / p
    a = xtx + lam * np.diag(ll * (ll + 1))
    coef = np.linalg.solve(a, xw.T @ values)
    q = np.einsum("ij,ji->i", x, np.linalg.solve(a, x.T))  # x_i' A^-1 x_i
    hat_diag = wts * q
    fitted = x @ coef
    res = values - fitted
    dof = float(hat_diag.sum())
    gcv = n * float(res @ (wts * res)) / max(n - dof, 1e-9) ** 2
    return SHFit(degree, coef, fitted, gcv, dof, hat_diag, q, wts)


def robust_flags(degree: int, phi, theta, values, k: float = OUTLIER_K, iterations: int = 50):
    """Outlier flags from a Tukey-bisquare (IRLS) fit of the map: a point is flagged when its
    leave-one-out residual exceeds ``k`` of its standard deviations (:meth:`SHFit.loo_t`).
    Sigma is 1.4826 MAD of the studentised residuals of the plain fit (floored at
    :data:`SCALE_FLOOR_MM`), held fixed while the weights iterate.  Returns (flags, sigma)."""
    f = _ridge_fit(degree, phi, theta, values)
    t = f.loo_t(values)
    sigma = max(1.4826 * float(np.median(np.abs(t - np.median(t)))), SCALE_FLOOR_MM)
    w = np.ones(len(values))
    for _ in range(iterations):
        u = f.loo_t(values, sigma) / 4.685
        w_new = np.where(np.abs(u) < 1.0, (1.0 - u ** 2) ** 2, 0.0)
        if np.max(np.abs(w_new - w)) < 1e-6:
            break
        w = w_new
        f = _ridge_fit(degree, phi, theta, values, w)
    return np.abs(f.loo_t(values, sigma)) > k, sigma


def max_degree_for(n_points: int) -> int:
    """Largest degree the automatic choice considers: at most half the points as coefficients."""
    return int(max(0, min(MAX_DEGREE, math.floor(math.sqrt(n_points / 2.0)) - 1)))


def fit_sh(phi, theta, values, degree: int | None = None) -> SHFit:
    """Fit a real spherical-harmonic map to values (mm) at (phi, theta) rad.  ``degree=None``
    chooses it by generalised cross-validation over 0..:func:`max_degree_for`."""
    n = len(values)
    if degree is not None:
        require(degree >= 0, f"map degree must be >= 0, got {degree}")
        require((degree + 1) ** 2 <= n,
                f"map degree {degree} has {(degree + 1) ** 2} coefficients, more than the "
                f"{n} points")
        return _ridge_fit(degree, phi, theta, values)
    fits = [_ridge_fit(d, phi, theta, values) for d in range(max_degree_for(n) + 1)]
    best = min(fits, key=lambda f: f.gcv)
    # prefer the lowest degree whose GCV is within 2 % of the best (parsimony)
    for f in fits:
        if f.gcv <= 1.02 * best.gcv:
            return f
    return best  # pragma: no cover
