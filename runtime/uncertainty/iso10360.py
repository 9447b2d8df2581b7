"""Simulated ISO 10360-2 length measuring test (E0) on a virtual CMM.

Geometry (``length_test``): the box of the three linear axes; 7 positions = the 4 space
diagonals and 3 lines parallel to X, Y, Z, all through the box centre; on each line 5 test
lengths ``fractions`` (default 0.1 0.25 0.4 0.55 0.7) of the line's length inside the box,
centred on the box centre (the longest is >= 66 % of the line, as the standard asks for the
space diagonals; on the axis lines the travel limits the length); each measured
``repetitions`` (default 3) times.  Bidirectional (gauge block / step gauge faces): the near
end is probed along -u, the far end along +u, u the unit vector of the line.

Sign convention: the model's error e = actual - nominal probe tip.  The probe touches the
gauge face at the actual position s; the CMM reads the nominal one, m = s - e(q) (+ noise
along the probing direction).  The length error is E = (m_far - m_near) . u - L
= -(e_far - e_near) . u (+ noise): a pure scale error EXX = s * X (s > 0: the machine moves
further than it indicates) gives E = -s L on the X line (|E| = s L).
MPE line: MPE_E0 = A + L / K, A in um, L in mm, K dimensionless (E0 in um).
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field

import numpy as np

from ..errors import require
from ..plotstyle import figure, label, png, styled
from ..units import MM_PER_UM, UM_PER_MM

from .tasks import check_travel

FRACTIONS = (0.1, 0.25, 0.4, 0.55, 0.7)


@dataclass(frozen=True)
class Spec:
    """ISO 10360-2 specification: MPE_E0 = A + L/K (um, L in mm); optional MPE_PFTU (um)."""

    A_um: float
    K: float
    pftu_um: float | None = None

    def mpe_um(self, length_mm):
        return self.A_um + np.asarray(length_mm, dtype=float) / self.K

    def text(self) -> str:
        s = f"E0 = {self.A_um:g} + L/{self.K:g} \u00b5m"
        return s + (f", PFTU = {self.pftu_um:g} \u00b5m" if self.pftu_um is not None else "")


_NUM = r"([0-9]*\.?[0-9]+(?:[eE][-+]?[0-9]+)?)"
#: a number with an optional length unit (um when bare)
_LEN = r"([0-9]*\.?[0-9]+(?:[eE][-+]?[0-9]+)?(?:um|µm|μm|nm|mm)?)"


def parse_spec(text: str, option: str = "--spec") -> Spec:
    """``"E0=A+L/K"`` (A um, K dimensionless), optionally ``",PFTU=P"`` (um).  ``option``:
    the command-line option the text came from, named in the messages.  A and P may carry
    a length unit (``"E0=1.5 um+L/333"``, ``"E0=0.0015mm+L/333"``; bare: um)."""
    from ..units import check_tolerance_um, convert, parse_quantity

    t = str(text).replace(" ", "")
    m = re.fullmatch(r"(?:MPE_?)?E0?=" + _LEN + r"\+L/" + _NUM + r"(?:[,;](?:MPE_?)?PFTU=" + _LEN
                     + r")?", t, re.IGNORECASE)
    require(m is not None or not re.search(r"[=+/]-", t),
            f"{option} {text!r}: A, K and PFTU must be positive (a minus sign)")
    require(m is not None, f"{option} {text!r}: expected \"E0=A+L/K\" (A in um, L in mm, K "
                           f"dimensionless), optionally \",PFTU=P\" (um)")

    def um(cell):
        v, unit = parse_quantity(cell, f"{option} {text!r}", default_unit="um",
                                 kinds=("length",), positive=False)
        return convert(v, unit, "um")

    a, k = um(m.group(1)), float(m.group(2))
    require(a > 0 and k > 0, f"{option} {text!r}: A and K must be positive")
    check_tolerance_um(a, f"{option} {text!r}: the constant A",
                       "mm" if "mm" in m.group(1).lower() else "um")
    p = um(m.group(3)) if m.group(3) else None
    require(p is None or p > 0, f"{option} {text!r}: PFTU must be positive")
    return Spec(a, k, p)


@dataclass
class LengthTest:
    """The test's measurements.  ``names``: line name per position (7,); ``lengths`` (7, 5)
    mm; ``u`` (7, 3) unit vectors; ``targets`` (7, 5, 2, 3) nominal probe-tip points of the
    near and far gauge face, mm; ``positions``: axis -> (7*5*2,) axis positions (mm, module
    units) of those points in C order; ``probe`` (3,) mm; ``directions`` (7, 5, 2, 3)."""

    names: tuple
    lengths: np.ndarray
    u: np.ndarray
    targets: np.ndarray
    positions: dict
    probe: np.ndarray
    directions: np.ndarray
    repetitions: int = 3
    box: dict = field(default_factory=dict)


def linear_box(model, box=None) -> dict:
    lin = tuple(a for a in model.axes if a not in model.rotary_axes)
    require(len(lin) == 3 and set(lin) == {"X", "Y", "Z"},
            f"{model.name}: the length test needs three linear axes X Y Z")
    box = dict(model.travel if box is None else box)
    return {a: tuple(map(float, box[a])) for a in ("X", "Y", "Z")}


def row_name(position: str, length_mm: float) -> str:
    """The name of the result row of E0 at ``position`` and ``length_mm``:
    ``E0(diagonal +X+Y+Z, L=114.0)``."""
    return f"E0({position.strip()}, L={float(length_mm):.1f})"


def axis_positions(model, targets, probe) -> dict:
    """Axis positions (module units) that put the nominal probe tip at ``targets`` (N, 3) mm,
    for the linear axes (nominal position affine in them); rotary axes at 0."""
    targets = np.asarray(targets, dtype=float).reshape(-1, 3)
    n = targets.shape[0]
    zero = {a: np.zeros(1) for a in model.axes}
    p = {"Xp": float(probe[0]), "Yp": float(probe[1]), "Zp": float(probe[2])}

    def nominal(pos):
        return np.array([np.broadcast_to(c, (1,))[0] for c in model.module.nominal_position(**pos, **p)])

    n0 = nominal(zero)
    J = np.empty((3, 3))
    for j, a in enumerate(("X", "Y", "Z")):
        J[:, j] = nominal({**zero, a: np.ones(1)}) - n0
    q = np.linalg.solve(J, (targets - n0).T)
    out = {a: np.zeros(n) for a in model.axes}
    for j, a in enumerate(("X", "Y", "Z")):
        out[a] = q[j]
    return out


def length_test(model, box=None, probe=(0.0, 0.0, 0.0), fractions=FRACTIONS,
                repetitions: int = 3) -> LengthTest:
    """The ISO 10360-2 test geometry inside ``box`` (default the travel); see module doc."""
    box = linear_box(model, box)
    probe = np.asarray(probe, dtype=float)
    require(probe.shape == (3,) and np.all(np.isfinite(probe)), "probe offset: three numbers")
    require(repetitions >= 1, "repetitions must be >= 1")
    lo = np.array([box[a][0] for a in "XYZ"])
    hi = np.array([box[a][1] for a in "XYZ"])
    require(np.all(hi > lo), "the box is empty")
    # the box of axis positions -> the box of nominal probe-tip points (CMM: shifted by probe)
    p0 = axis_positions(model, np.zeros((1, 3)), probe)
    shift = -np.array([p0[a][0] for a in "XYZ"])
    centre = 0.5 * (lo + hi) + shift
    half = 0.5 * (hi - lo)
    names, dirs, extents = [], [], []
    for sx, sy, sz in ((1, 1, 1), (-1, 1, 1), (1, -1, 1), (1, 1, -1)):
        d = np.array([sx, sy, sz]) * half
        names.append(f"diagonal {'+' if sx > 0 else '-'}X{'+' if sy > 0 else '-'}Y"
                     f"{'+' if sz > 0 else '-'}Z")
        extents.append(2 * np.linalg.norm(d))
        dirs.append(d / np.linalg.norm(d))
    for j, a in enumerate("XYZ"):
        e = np.zeros(3)
        e[j] = 1.0
        names.append(f"axis {a}")
        dirs.append(e)
        extents.append(2 * half[j])
    u = np.array(dirs)
    fr = np.asarray(fractions, dtype=float)
    require(fr.ndim == 1 and fr.size >= 1 and np.all((fr > 0) & (fr <= 1)),
            "length fractions must lie in (0, 1]")
    lengths = np.array(extents)[:, None] * fr[None, :]
    near = centre - 0.5 * lengths[..., None] * u[:, None, :]
    far = centre + 0.5 * lengths[..., None] * u[:, None, :]
    targets = np.stack([near, far], axis=2)  # (7, 5, 2, 3)
    directions = np.stack([np.broadcast_to(-u[:, None, :], near.shape),
                           np.broadcast_to(u[:, None, :], far.shape)], axis=2)
    pos = axis_positions(model, targets.reshape(-1, 3), probe)
    check_travel(model, {a: (np.rad2deg(v) if a in model.rotary_axes else v)
                         for a, v in pos.items()}, "ISO 10360-2 test point")
    return LengthTest(tuple(names), lengths, u, targets, pos, probe, directions, repetitions, box)


def length_errors(test: LengthTest, e, noise=None) -> np.ndarray:
    """E (S, 7, 5, R) mm from volumetric errors ``e`` (S, 7*5*2, 3) at the test points and
    ``noise`` (S, 7, 5, R, 2) along the probing directions (None: no noise)."""
    e = np.asarray(e).reshape((-1,) + test.targets.shape)
    de = np.einsum("sflk,fk->sfl", e[:, :, :, 1] - e[:, :, :, 0], test.u)
    E = -de[..., None] * np.ones(test.repetitions)
    if noise is not None:
        # m = s + n * direction: far end +u, near end -u -> length + n_far + n_near
        E = E + noise[..., 1] + noise[..., 0]
    return E


def evaluate_errors(model, test: LengthTest, errors: dict) -> np.ndarray:
    """Volumetric errors (S, 70, 3) mm at the test points for ``errors``: name -> array
    broadcastable to (S, 70) (mm / rad)."""
    n = len(next(iter(test.positions.values())))
    full = {p: errors.get(p, 0.0) for p in model.parameters}
    p = test.probe
    comp = model.module.volumetric_error(**test.positions, Xp=float(p[0]), Yp=float(p[1]),
                                         Zp=float(p[2]), **full)
    shape = np.broadcast_shapes(*(np.shape(c) for c in comp), (n,))
    return np.stack([np.broadcast_to(c, shape) for c in comp], axis=-1).reshape(-1, n, 3)


@dataclass(frozen=True)
class TestUncertainty:
    """Expanded uncertainty U(L) (k = 2) of the length test, the *test uncertainty* ISO
    10360-2 (clause 6, with ISO/TS 23165 / ISO 14253-5) tells the verdict to account for: the
    calibration of the reference lengths (a step gauge or gauge blocks, U_cal = A + L/K, k = 2,
    um with L in mm), their expansion coefficient (u(alpha), ppm/K) at a temperature T away
    from 20 degC and the reading of that temperature (u(T), K)::

        U(L) = 2 sqrt((U_cal / 2)^2 + (L |T - 20| u(alpha))^2 + (L alpha u(T))^2)

    (L mm, alpha ppm/K: products in nm, shown in um)."""

    cal_A_um: float = 0.1
    cal_K: float = 2000.0
    cte_ppm_per_K: float = 11.5
    cte_u_ppm_per_K: float = 1.0
    temperature_C: float = 20.0
    temperature_u_K: float = 0.2

    def U_um(self, length_mm):
        L = np.asarray(length_mm, dtype=float)
        u_cal = 0.5 * (self.cal_A_um + L / self.cal_K)
        u_cte = L * abs(self.temperature_C - 20.0) * self.cte_u_ppm_per_K * 1e-3
        u_T = L * self.cte_ppm_per_K * self.temperature_u_K * 1e-3
        return 2.0 * np.sqrt(u_cal ** 2 + u_cte ** 2 + u_T ** 2)

    def budget(self, length_mm: float) -> dict:
        """The GUM budget of the test uncertainty at ``length_mm`` (the three terms of
        :meth:`U_um` as sources: u(x_i) in its unit, sensitivity, contribution in um)."""
        from ..report.budget import budget, source

        L = float(length_mm)
        return budget(f"E0 at L = {L:.1f} mm (test uncertainty)", "um", [
            source("reference length calibration (U_cal / 2)",
                   0.5 * (self.cal_A_um + L / self.cal_K), "um"),
            source("expansion coefficient u(alpha)", self.cte_u_ppm_per_K, "ppm/K",
                   L * abs(self.temperature_C - 20.0) * 1e-3),
            source("temperature reading u(T)", self.temperature_u_K, "K",
                   L * self.cte_ppm_per_K * 1e-3)], k=2.0)

    def text(self) -> str:
        return (f"U(L) = 2 \u221a((U_cal/2)\u00b2 + (L |T \u2212 20| u(\u03b1))\u00b2 + (L \u03b1 "
                f"u(T))\u00b2), U_cal = {self.cal_A_um:g} + L/{self.cal_K:g} \u00b5m, \u03b1 = "
                f"{self.cte_ppm_per_K:g} ppm/K, u(\u03b1) = {self.cte_u_ppm_per_K:g} ppm/K, "
                f"T = {self.temperature_C:g} \u00b0C, u(T) = {self.temperature_u_K:g} K")

    def as_dict(self) -> dict:
        return {"calibration_um": f"{self.cal_A_um:g}+L/{self.cal_K:g}",
                "cte_ppm_per_K": self.cte_ppm_per_K, "cte_u_ppm_per_K": self.cte_u_ppm_per_K,
                "temperature_C": self.temperature_C, "temperature_u_K": self.temperature_u_K,
                "coverage_factor": 2, "formula": self.text()}


def artefact_uncertainty(artefact_u: str = "0.1+L/2000", cte_ppm_per_K: float = 11.5,
                     cte_u_ppm_per_K: float = 1.0, temperature_C: float = 20.0,
                     temperature_u_K: float = 0.2) -> TestUncertainty:
    """:class:`TestUncertainty` of the command's options (each checked finite and in range:
    one line naming the option otherwise)."""
    import math

    a, k = parse_calibration(artefact_u)
    for value, option, low, high in (
            (cte_ppm_per_K, "--artefact-cte-ppm-per-K", -100.0, 100.0),
            (cte_u_ppm_per_K, "--artefact-cte-u-ppm-per-K", 0.0, 100.0),
            (temperature_C, "--temperature-C", -50.0, 100.0),
            (temperature_u_K, "--temperature-u-K", 0.0, 100.0)):
        require(math.isfinite(value) and low <= value <= high,
                f"{option} must be a number between {low:g} and {high:g}, got {value:g}")
    return TestUncertainty(a, k, cte_ppm_per_K, cte_u_ppm_per_K, temperature_C,
                           temperature_u_K)


def console_lines(res, doc: dict) -> list:
    """What ``volerr iso10360`` prints for the result ``res`` and its JSON ``doc``: E0 per
    position and length (um), max |E0| and U (k = 2), the verdict against the MPE."""
    from ..units import num

    out = [f"{doc['layout']}: simulated ISO 10360-2 length test, E0 = measured - true length, "
           "um"]
    for i, name in enumerate(res.names):
        cells = "  ".join(f"L={L:7.1f}: " + " ".join(num(e, "+7.3f") for e in res.E_um[i, j])
                          for j, L in enumerate(res.lengths[i]))
        out.append(f"  {name:16s} {cells}")
    out.append(f"  max |E0| = {num(doc['max_abs_E_um'], '.3f')} um; test uncertainty U <= "
               f"{num(doc['uncertainty_um']['E0'], '.3f')} um (k = 2)")
    if res.spec is not None:
        c = doc["verdict_counts"]
        out.append(f"  MPE {res.spec.text()}: max |E0| / MPE = "
                   f"{num(doc['max_ratio_to_mpe'], '.3f')} -> {doc['verdict'].upper()} (ISO "
                   f"14253-1: {c['pass']} pass, {c['undecided']} undecided, {c['fail']} fail)")
    return out


def parse_calibration(text: str, option: str = "--artefact-u") -> tuple[float, float]:
    """``"A+L/K"`` (um, L in mm) -> (A, K)."""
    t = str(text).replace(" ", "")
    m = re.fullmatch(r"(?:U=)?" + _NUM + r"\+L/" + _NUM, t, re.IGNORECASE)
    require(m is not None, f"{option} {text!r}: expected \"A+L/K\" (A in um, L in mm)")
    a, k = float(m.group(1)), float(m.group(2))
    require(0 <= a <= 1e3 and 0 < k <= 1e9, f"{option} {text!r}: A must lie in 0..1000 um and "
                                             f"K be positive")
    return a, k


@dataclass
class TestResult:
    """Simulated E0 values: ``E_um`` (7, 5, R), ``lengths`` (7, 5) mm, line names, MPE."""

    names: tuple
    lengths: np.ndarray
    E_um: np.ndarray
    spec: Spec | None
    uncertainty: TestUncertainty = field(default_factory=TestUncertainty)

    def U_um(self) -> np.ndarray:
        """Test uncertainty U (k = 2) at every test length, (7, 5) um."""
        return self.uncertainty.U_um(self.lengths)

    def verdicts(self) -> np.ndarray | None:
        """ISO 14253-1 verdict of every E value against the MPE with U, (7, 5, R) strings
        (None without a specification)."""
        if self.spec is None:
            return None
        from ..conformance import verdict

        mpe, U = self.spec.mpe_um(self.lengths), self.U_um()
        out = np.empty(self.E_um.shape, dtype=object)
        for idx in np.ndindex(self.E_um.shape):
            out[idx] = verdict(abs(float(self.E_um[idx])), float(mpe[idx[:2]]),
                               float(U[idx[:2]]))
        return out

    def as_dict(self) -> dict:
        """JSON: E values per position (um), ``uncertainty_um`` {"E0": largest U}, the test
        uncertainty, and with a specification the ``verdict`` per ISO 14253-1 (with the
        verdict of every value and the counts)."""
        from ..conformance import RULE, overall

        U = self.U_um()
        v = self.verdicts()
        out = {"positions": []}
        for i, name in enumerate(self.names):
            pos = {"line": name, "lengths_mm": [round(float(x), 6) for x in self.lengths[i]],
                   # + 0.0: no negative zero in the JSON
                   "E_um": [[round(float(x), 4) + 0.0 for x in row] for row in self.E_um[i]],
                   "U_um": [round(float(x), 4) for x in U[i]]}
            if v is not None:
                pos["verdicts"] = [list(row) for row in v[i]]
            out["positions"].append(pos)
        out["max_abs_E_um"] = float(np.max(np.abs(self.E_um)))
        out["uncertainty_um"] = {"E0": float(U.max())}
        out["test_uncertainty"] = self.uncertainty.as_dict()
        b = self.uncertainty.budget(float(self.lengths.flat[U.argmax()]))
        b["rows"] = [row_name(n, L) for i, n in enumerate(self.names) for L in self.lengths[i]]
        b["notes"] = ["Every E0 row states this u: the test uncertainty at the longest length, "
                      "the largest of the test (a conservative u for the shorter lengths)."]
        out["budgets"] = {"E0": b}
        if self.spec is not None:
            mpe = self.spec.mpe_um(self.lengths)[..., None]
            ratio = np.abs(self.E_um) / mpe
            out["mpe"] = self.spec.text()
            out["max_ratio_to_mpe"] = float(ratio.max())
            out["passes"] = bool(np.all(ratio <= 1.0))
            flat = list(v.ravel())
            out["verdict"] = overall(flat)
            out["verdict_counts"] = {k: flat.count(k) for k in ("pass", "undecided", "fail")}
            out["decision_rule"] = RULE
        return out


def simulate(model, funcs=None, probe=(0.0, 0.0, 0.0), box=None, repetitions: int = 3,
             noise_um: float = 0.0, seed: int = 0, spec: Spec | None = None,
             uncertainty: TestUncertainty | None = None) -> TestResult:
    """The length test on the machine of error functions ``funcs`` (None: perfect machine),
    with probing noise ``noise_um`` (standard deviation along each probing direction) and the
    test uncertainty ``uncertainty`` (default :class:`TestUncertainty`)."""
    require(noise_um >= 0 and np.isfinite(noise_um), "--noise-um must be >= 0")
    test = length_test(model, box, probe, repetitions=repetitions)
    errors = {}
    if funcs is not None:
        pos_deg = {a: (np.rad2deg(v) if a in model.rotary_axes else v)
                   for a, v in test.positions.items()}
        errors = funcs(pos_deg)
    e = evaluate_errors(model, test, errors)
    noise = None
    if noise_um > 0:
        rng = np.random.default_rng(seed)
        noise = rng.standard_normal((1,) + test.lengths.shape + (repetitions, 2)) * noise_um * MM_PER_UM
    E = length_errors(test, e, noise)[0]
    return TestResult(test.names, test.lengths, E * UM_PER_MM, spec,
                      uncertainty or TestUncertainty())


#: colours of the verdict marks
_MARK = {"fail": "#c62828", "undecided": "#e08a00"}


def plot(result: TestResult, path, title: str, inputs=()) -> None:
    """Write :func:`plot_png` to ``path`` (never over an input)."""
    from ..fileio import write_bytes

    write_bytes(path, plot_png(result, title), inputs)


@styled
def plot_png(result: TestResult, title: str) -> bytes:
    """E0 against L for every position and repetition, with the MPE lines and the
    conformance zone (MPE reduced by the test uncertainty U, k = 2); values whose verdict is
    fail (red) or undecided (amber) are marked (the certificate picture).  PNG bytes."""
    fig, ax = figure(height=5.6)
    markers = "os^vD<>"
    for i, name in enumerate(result.names):
        L = np.repeat(result.lengths[i][:, None], result.E_um.shape[-1], axis=1)
        ax.plot(L.ravel(), result.E_um[i].ravel(), markers[i % 7], ms=5, label=name, alpha=0.8)
    lmax = float(result.lengths.max()) * 1.05
    if result.spec is not None:
        L = np.linspace(0, lmax, 50)
        mpe, U = result.spec.mpe_um(L), result.uncertainty.U_um(L)
        ax.plot(L, mpe, "r-", lw=1.5, label=f"MPE {result.spec.text()}")
        ax.plot(L, -mpe, "r-", lw=1.5)
        ax.fill_between(L, mpe - U, mpe + U, color="tab:red", alpha=0.12, lw=0,
                        label="MPE \u00b1 U (k = 2): undecided zone")
        ax.fill_between(L, -mpe - U, -mpe + U, color="tab:red", alpha=0.12, lw=0)
        v = result.verdicts()
        for kind in ("undecided", "fail"):
            idx = np.argwhere(v == kind)
            if len(idx):
                ax.plot(result.lengths[idx[:, 0], idx[:, 1]], result.E_um[tuple(idx.T)], "o",
                        ms=13, mfc="none", mec=_MARK[kind], mew=2.2,
                        label=f"{kind} ({len(idx)} value{'s' if len(idx) > 1 else ''})")
    ax.axhline(0, color="k", lw=0.5)
    ax.set_xlim(0, lmax)
    ax.set_xlabel(label("test length L", "mm"))
    ax.set_ylabel(label("length error E0", "um"))
    ax.set_title(title)
    ax.legend(ncol=2, fontsize=9)
    return png(fig)
