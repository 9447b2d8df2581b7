"""A virtual machine: measured volumetric deviations of any layout, computed with the exact chain.

The machine's error parameters are smooth random polynomials of their own axis position (one
seed fixes them all), squareness and rotary location errors random constants.  Undeclared
effects of every kind the loop looks for can be switched on; they are coded here directly
(not through the loop's effect terms) so that a round trip simulate -> loop is an independent
check.  The measuring instrument sits at an unknown rigid placement (exact rotation), and
every coordinate carries Gaussian noise.

Units: positions mm / deg, probe offsets mm, deviations written in um (``dx_um`` ...).

Effects (``effects=[{...}, ...]``, magnitudes in um, um/m/K, um/h, urad):

* ``{"kind": "thermal", "axis": "X", "ppm_per_K": 11.5}``: scale of X grows with T_C - 20.
* ``{"kind": "drift", "direction": "x", "um_per_h": 3}``: the instrument drifts with time.
* ``{"kind": "reversal", "axis": "X", "um": 4}``: positioning differs by 4 um between approach
  directions (``dir_X`` = +1 / -1).
* ``{"kind": "coupling", "component": "EZX", "axis": "Y", "um": 6}``: straightness of X in Z
  twists with Y: ``EZX += um * x * y`` (x, y normalised to [-1, 1] over the travel).
* ``{"kind": "periodic", "component": "EXX", "period_mm": 25, "um": 2}``: cyclic error.
* ``{"kind": "higher_order", "component": "EYZ", "um": 3, "degree": 10}``: a Legendre term of
  high degree in the component's own axis position.
* ``{"kind": "probe_direction", "um": 2}``: the probe tip is off by 2 um along the probing
  direction (``nx, ny, nz``).
* ``{"kind": "setup", "um": 8, "urad": 15}``: the instrument is re-placed between rounds
  (``setup`` = round number): every round after the first has its own rigid placement.
* ``{"kind": "thermal_lag", "sensor": "T_motorX", "tau_min": 40, "axis": "X",
  "ppm_per_K": 2}``: the scale of X follows a logged sensor through a first-order lag
  (``component`` + ``um_per_K``: another error, an offset); needs ``sensors``
  (:mod:`volerr.loop.thermal`: sensors, duty cycles).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from ..errors import InputError, require
from ..machine.iso_names import along_component
from ..machine.model import Model, load
from . import thermal

#: effect kind -> the keys it accepts (besides "kind")
EFFECT_KEYS = {"thermal": {"axis", "ppm_per_K"}, "drift": {"direction", "um_per_h"},
               "reversal": {"axis", "um"}, "coupling": {"component", "axis", "um"},
               "periodic": {"component", "period_mm", "um", "phase"},
               "higher_order": {"component", "um", "degree"}, "probe_direction": {"um"},
               "setup": {"um", "urad"},
               "thermal_lag": {"sensor", "tau_s", "tau_min", "axis", "ppm_per_K", "component",
                               "um_per_K"}}
KINDS = tuple(EFFECT_KEYS)


def _rotation(ex, ey, ez) -> np.ndarray:
    """Exact rotation Rz(ez) Ry(ey) Rx(ex) (rad), shape (3, 3): scipy's extrinsic x-y-z."""
    from scipy.spatial.transform import Rotation

    return Rotation.from_euler("xyz", [ex, ey, ez]).as_matrix()


def _unit(lo, hi, q):
    """Position normalised to [-1, 1] over [lo, hi]."""
    return (2.0 * np.asarray(q, dtype=float) - (lo + hi)) / (hi - lo)


@dataclass
class Campaign:
    """A simulated measurement campaign (all arrays of length N)."""

    layout: str
    positions: dict            # axis -> (N,) mm | deg
    probe: np.ndarray          # (N, 3) mm
    deviation: np.ndarray      # (N, 3) mm, measured actual minus nominal
    covariates: dict           # name -> (N,)
    truth: dict = field(default_factory=dict)

    @property
    def n_points(self) -> int:
        return len(self.deviation)

    def columns(self) -> dict:
        """Column name -> values, in the measured-deviation CSV format (um for deviations)."""
        cols = {a: v for a, v in self.positions.items()}
        cols.update({"Xp": self.probe[:, 0], "Yp": self.probe[:, 1], "Zp": self.probe[:, 2]})
        for i, c in enumerate(("dx_um", "dy_um", "dz_um")):
            cols[c] = self.deviation[:, i] * 1e3
        cols.update(self.covariates)
        return cols

    def csv_text(self) -> str:
        """The measured-deviation CSV (INTERFACE.md)."""
        cols = self.columns()
        names = list(cols)
        lines = [",".join(names)]
        arr = np.column_stack([np.asarray(cols[n], dtype=float) for n in names])
        for row in arr:
            lines.append(",".join(_fmt(v) for v in row))
        return "\n".join(lines) + "\n"

    def write_csv(self, path, inputs=()) -> Path:
        """Write :meth:`csv_text` atomically; returns the path."""
        from ..fileio import write_text

        return write_text(path, self.csv_text(), inputs=list(inputs))


def _fmt(v: float) -> str:
    if float(v).is_integer() and abs(v) < 1e12:
        return str(int(v))
    return f"{v:.6f}".rstrip("0").rstrip(".") if abs(v) >= 1e-3 else f"{v:.9g}"


def random_errors(model: Model, rng: np.random.Generator, magnitude_um: float = 5.0,
                  degree: int = 4, shape: str = "poly") -> dict:
    """Random smooth error functions: name -> callable(q) (mm or rad) or constant.

    ``shape="poly"``: component errors are Legendre series of degree ``degree`` in the axis
    position normalised over the travel, coefficients decaying as 1/(k+1).  ``"smooth"``: sums
    of four sinusoids with wavelengths between 4 and 1 times the travel (not polynomials:
    what a fitted basis can only approximate).  Translational errors are of about
    ``magnitude_um``, angular ones ``magnitude_um`` over half the largest linear travel."""
    require(shape in ("poly", "smooth"), f"error shape must be poly or smooth, not {shape!r}")
    lin = [model.travel[a][1] - model.travel[a][0] for a in model.axes
           if a not in model.rotary_axes] or [500.0]
    arm = 0.5 * max(lin)
    out = {}
    for p in model.parameters:
        axis = model.parameter_axis.get(p)
        scale = magnitude_um * 1e-3 * (1.0 if p[1] in "XYZ" else 1.0 / arm)
        if axis is None:
            out[p] = float(rng.normal(0.0, 1.5 * scale))
            continue
        lo, hi = model.travel[axis]
        if shape == "smooth":
            amp = rng.normal(0.0, 1.0, 4) * scale / np.sqrt(2.0)
            k = rng.uniform(0.25, 1.0, 4) * 2 * np.pi          # rad per normalised travel
            ph = rng.uniform(0, 2 * np.pi, 4)
            out[p] = (lambda q, a=amp, k=k, ph=ph, lo=lo, hi=hi:
                      np.sin(np.multiply.outer(_unit(lo, hi, q), k) + ph) @ a)
            continue
        coef = rng.normal(0.0, 1.0, degree + 1) * scale / (1.0 + np.arange(degree + 1))
        out[p] = (lambda q, c=coef, lo=lo, hi=hi:
                  np.polynomial.legendre.legval(_unit(lo, hi, q), c))
    return out


def make_plan(model: Model, n_points: int, rng: np.random.Generator, probes=None,
              rounds: int = 1) -> tuple[dict, np.ndarray, np.ndarray]:
    """Random positions over the travel, cycled probe offsets, repeated in ``rounds``.

    Returns (positions dict, probe (N, 3), round index (N,) starting at 1)."""
    probes = np.atleast_2d(np.asarray(probes if probes is not None else [(0.0, 0.0, 0.0)],
                                      dtype=float))
    require(probes.shape[1] == 3, "probe offsets must be (x, y, z) triples")
    require(rounds >= 1 and n_points >= rounds, "need at least one point per round")
    per = n_points // rounds
    pos = {a: rng.uniform(*model.travel[a], per) for a in model.axes}
    pr = probes[np.arange(per) % len(probes)]
    positions = {a: np.tile(v, rounds) for a, v in pos.items()}
    return positions, np.tile(pr, (rounds, 1)), np.repeat(np.arange(1, rounds + 1), per)


def simulate(layout="MB1", n_points: int = 600, seed: int = 0, probes=None, rounds: int = 1,
             effects=(), noise_um: float = 0.3, magnitude_um: float = 5.0, degree: int = 4,
             setup_um: float = 20.0, setup_urad: float = 20.0, temperature_K: float = 4.0,
             duration_h: float = 8.0, errors=None, shape: str = "poly", sensors=None,
             duty: str | None = None) -> Campaign:
    """Simulate a campaign on a virtual machine of ``layout`` (name or layout file).

    The covariate columns ``T_C`` (deg C), ``t_s`` (s), ``dir_<axis>`` (+1 / -1, linear axes),
    ``nx ny nz`` (probing direction) and ``setup`` (round number) are always written, so that
    a loop has every candidate family to consider whether or not an effect is present.
    ``shape``: ``"poly"`` or ``"smooth"`` error functions (:func:`random_errors`).
    ``errors``: {name: constant or callable(position)} replacing random error functions
    (mm / rad; a callable of a component error gets its own axis' positions, mm | deg).
    ``sensors`` (a number or names, :func:`volerr.loop.thermal.sensor_names`): logged
    temperatures in place of ``T_C``, heated by the duty cycle ``duty`` (``on:6h,off:4h``;
    :mod:`volerr.loop.thermal`), over ``duration_h``."""
    model = load(layout)
    rng = np.random.default_rng(seed)
    effects = [dict(e) for e in effects]
    for e in effects:
        require(e.get("kind") in KINDS, f"unknown effect kind {e.get('kind')!r}; "
                f"kinds are {' '.join(KINDS)}")
        bad = sorted(set(e) - {"kind"} - EFFECT_KEYS[e["kind"]])
        require(not bad, f"effect {e['kind']}: unknown key {bad[0] if bad else ''!r} "
                f"(keys: {' '.join(sorted(EFFECT_KEYS[e['kind']]))})")
    funcs = random_errors(model, rng, magnitude_um, degree, shape)
    for p, f in dict(errors or {}).items():
        require(p in model.parameters, f"{model.name}: unknown error parameter {p!r}")
        funcs[p] = f
    positions, probe, rnd = make_plan(model, n_points, rng, probes, rounds)
    n = len(rnd)
    linear = [a for a in model.axes if a not in model.rotary_axes]
    t = np.sort(rng.uniform(0.0, duration_h * 3600.0, n))
    order = rng.permutation(n)                       # time order of the points within rounds
    order = order[np.argsort(rnd[order], kind="stable")]
    t_s = np.empty(n)
    t_s[order] = t
    phase = 2 * np.pi * t_s / (duration_h * 3600.0)
    temp = 20.0 + 0.5 * temperature_K * (np.sin(phase - 1.0) + 0.3 * np.sin(3.1 * phase))
    n_dir = rng.normal(size=(n, 3))
    n_dir /= np.linalg.norm(n_dir, axis=1, keepdims=True)
    cov = {"T_C": np.round(temp, 3), "t_s": np.round(t_s, 1)}
    for a in linear:
        cov[f"dir_{a}"] = rng.choice([-1.0, 1.0], n)
    cov.update({"nx": n_dir[:, 0], "ny": n_dir[:, 1], "nz": n_dir[:, 2], "setup": rnd.astype(float)})
    log = _sensors(sensors, duty, duration_h, seed, cov)

    values = {}
    for p, f in funcs.items():
        axis = model.parameter_axis.get(p)
        values[p] = f(positions[axis]) if callable(f) else np.full(n, f)
    extra_dev = np.zeros((n, 3))
    placements = {}
    for e in effects:
        if e["kind"] == "thermal_lag":
            require(log is not None, "a thermal_lag effect needs logged sensors (--sensors)")
            thermal.thermal_lag(e, log, positions, values, cov["t_s"],
                                {a: along_component(model.layout, a) for a in linear})
            continue
        _apply(e, model, positions, cov, values, extra_dev, placements, rng)
    dev = model.exact_error(positions, values, probe)
    nominal = model.nominal_position(positions, probe)
    actual = nominal + dev
    # instrument placement: one global rigid transform, plus one per later round ("setup")
    g = (rng.normal(0, setup_urad * 1e-6, 3), rng.normal(0, setup_um * 1e-3, 3))
    for r in np.unique(rnd):
        m = rnd == r
        rot, shift = _rotation(*g[0]), g[1]
        if r in placements:
            rot, shift = _rotation(*placements[r][0]) @ rot, _rotation(*placements[r][0]) @ shift \
                + placements[r][1]
        actual[m] = actual[m] @ rot.T + shift
    dev = actual - nominal + extra_dev + rng.normal(0.0, noise_um * 1e-3, (n, 3))
    truth = {"errors": {p: (None if callable(f) else f) for p, f in funcs.items()},
             "functions": funcs, "effects": effects, "global_setup": g,
             "setup_placements": placements, "noise_um": noise_um, "seed": seed}
    return Campaign(model.name if str(layout) == model.name else str(layout),
                    positions, probe, dev, cov, truth)


def _sensors(sensors, duty, duration_h, seed, cov):
    """Logged sensors in place of ``T_C`` (their own random stream: campaigns without sensors
    are unchanged); the :class:`volerr.loop.thermal.SensorLog` or None."""
    if sensors is None:
        require(duty is None, "a duty cycle needs logged sensors (--sensors)")
        return None
    rng = np.random.default_rng([seed, 30])
    log = thermal.log_sensors(thermal.sensor_names(sensors), duty, duration_h * 3600.0, rng)
    del cov["T_C"]
    readings = log.at(cov["t_s"], rng)
    cov.update(readings)
    return log


def _component_axis(model: Model, component: str) -> str:
    require(component in model.parameters and model.parameter_axis.get(component),
            f"{model.name}: {component!r} is not a component error")
    return model.parameter_axis[component]


def _apply(e: dict, model: Model, positions, cov, values, extra_dev, placements, rng) -> None:
    """Add one undeclared effect to the error values (or to ``extra_dev`` / ``placements``)."""
    kind = e["kind"]
    n = len(cov["t_s"])
    along = {"X": "EXX", "Y": "EYY", "Z": "EZZ"}
    if kind == "thermal":
        a = e.get("axis", "X")
        values[along[a]] = values[along[a]] + e.get("ppm_per_K", 11.5) * 1e-6 * positions[a] * (
            cov["T_C"] - 20.0)
    elif kind == "drift":
        i = "xyz".index(e.get("direction", "x"))
        extra_dev[:, i] += e.get("um_per_h", 3.0) * 1e-3 * cov["t_s"] / 3600.0
    elif kind == "reversal":
        a = e.get("axis", "X")
        values[along[a]] = values[along[a]] + 0.5 * e.get("um", 4.0) * 1e-3 * cov[f"dir_{a}"]
    elif kind == "coupling":
        comp, b = e.get("component", "EZX"), e.get("axis", "Y")
        a = _component_axis(model, comp)
        require(b in model.axes and b != a, f"coupling axis {b!r} must be another axis")
        scale = 1e-3 if comp[1] in "XYZ" else 1e-6
        values[comp] = values[comp] + e.get("um", 6.0) * scale * _unit(
            *model.travel[a], positions[a]) * _unit(*model.travel[b], positions[b])
    elif kind == "periodic":
        comp = e.get("component", "EXX")
        a = _component_axis(model, comp)
        ph = e.get("phase", float(rng.uniform(0, 2 * np.pi)))
        values[comp] = values[comp] + e.get("um", 2.0) * 1e-3 * np.sin(
            2 * np.pi * positions[a] / e.get("period_mm", 25.0) + ph)
    elif kind == "higher_order":
        comp = e.get("component", "EYZ")
        a = _component_axis(model, comp)
        deg = int(e.get("degree", 10))
        scale = 1e-3 if comp[1] in "XYZ" else 1e-6
        values[comp] = values[comp] + e.get("um", 3.0) * scale * np.polynomial.legendre.legval(
            _unit(*model.travel[a], positions[a]), [0.0] * deg + [1.0])
    elif kind == "probe_direction":
        nvec = np.column_stack([cov["nx"], cov["ny"], cov["nz"]])
        extra_dev += e.get("um", 2.0) * 1e-3 * nvec
    elif kind == "setup":
        for r in np.unique(cov["setup"])[1:]:
            placements[r] = (rng.normal(0, e.get("urad", 15.0) * 1e-6, 3),
                             rng.normal(0, e.get("um", 8.0) * 1e-3, 3))
        require(placements, "a setup effect needs rounds >= 2")
    if n == 0:  # pragma: no cover
        raise InputError("empty plan")


def demo_probes(model: Model) -> list:
    """A plan's probe offsets: a long stylus and four styli across it (CMM) or tool lengths."""
    if model.rotary_axes:
        return [(0.0, 0.0, 100.0), (0.0, 0.0, 200.0), (30.0, 0.0, 150.0), (0.0, 30.0, 150.0)]
    return [(0.0, 0.0, -100.0), (80.0, 0.0, -150.0), (-80.0, 0.0, -150.0),
            (0.0, 80.0, -150.0), (0.0, -80.0, -150.0)]


def parse_effect(text: str) -> dict:
    """``kind[:key=value,...]`` (``volerr simulate --effect``) -> effect dict (numbers where
    they parse)."""
    kind, _, rest = text.partition(":")
    out: dict = {"kind": kind.strip()}
    for item in filter(None, (s.strip() for s in rest.split(","))):
        key, eq, value = item.partition("=")
        require(eq == "=", f"--effect {text!r}: write key=value pairs after the kind")
        try:
            out[key.strip()] = float(value)
        except ValueError:
            out[key.strip()] = value.strip()
    return out


def check_effect(e: dict, model: Model, text: str) -> dict:
    """Every value of an ``--effect`` checked against the layout: one line for a bad one."""
    import math

    for key, v in e.items():
        if key == "kind":
            continue
        if key == "axis":
            require(v in model.axes, f"--effect {text!r}: axis {v!r} is not an axis of "
                                     f"{model.name} ({' '.join(model.axes)})")
        elif key == "component":
            require(v in model.parameters, f"--effect {text!r}: component {v!r} is not an "
                                           f"error of {model.name}")
        elif key == "direction":
            require(v in ("x", "y", "z"), f"--effect {text!r}: direction must be x, y or z")
        elif key == "sensor":
            require(isinstance(v, str), f"--effect {text!r}: sensor must be a sensor's name")
        else:
            require(isinstance(v, float), f"--effect {text!r}: {key} = {v!r} is not a number")
            require(math.isfinite(v) and abs(v) <= 1e6,
                    f"--effect {text!r}: {key} = {v:g} must be a finite number of at most 1e6")
            if key == "degree":
                require(v == int(v) and 1 <= v <= 30,
                        f"--effect {text!r}: degree must be an integer 1..30")
            if key == "period_mm":
                require(v > 0, f"--effect {text!r}: period_mm must be positive")
    return e


def check_options(points: int, noise_um: float, magnitude_um: float) -> None:
    """The numbers of ``volerr simulate`` checked before any computing."""
    import math

    require(10 <= points <= 10_000_000, "--points must be between 10 and 10^7")
    require(all(math.isfinite(v) and 0 <= v <= 1e6 for v in (noise_um, magnitude_um)),
            "--noise-um and --magnitude-um must be finite, between 0 and 1e6 um")


def simulate_options(layout, *, points: int = 600, seed: int = 0, probes=None,
                     rounds: int = 1, effects=(), noise_um: float = 0.3,
                     magnitude_um: float = 5.0, hours: float = 8.0, sensors=None, duty=None):
    """``volerr simulate`` (the deviations campaign) from its options: every option checked
    (``effects`` as the ``--effect`` texts ``kind:key=value,...``; ``probes`` mm, default
    :func:`demo_probes`), then :func:`simulate`.  Returns the :class:`Campaign` and the
    machine's name."""
    import math

    check_options(points, noise_um, magnitude_um)
    model = layout if isinstance(layout, Model) else load(layout)
    found = [check_effect(parse_effect(e), model, e) for e in effects]
    probes = [tuple(v) for v in probes] if probes else demo_probes(model)
    require(math.isfinite(hours) and 0.1 <= hours <= 1000,
            "--hours must be between 0.1 and 1000")
    require(duty is None or sensors, "--duty needs --sensors")
    return simulate(layout, n_points=points, seed=seed, probes=probes, rounds=rounds,
                    effects=found, noise_um=noise_um, magnitude_um=magnitude_um,
                    duration_h=hours, sensors=sensors, duty=duty), model.name


def simulated_file(layout, instrument: str = "deviations", *, probe=None, effect=(),
                   points: int = 600, seed: int = 0, rounds: int = 1, noise_um: float = 0.3,
                   magnitude_um: float = 5.0, hours: float = 8.0, sensors=None, duty=None,
                   plant: str | None = None, errors=None, steps: int | None = None,
                   radius: float | None = None, accept_implausible: bool = False) -> tuple:
    """``volerr simulate``: ``(text, line)``, the file's text and the line the command prints
    (without its ``-> FILE`` tail).  ``instrument`` deviations: the measured deviations of
    :func:`simulate_options` (``probe``: the probe offsets, mm; ``effect``: the ``--effect``
    texts; ``points`` ... ``duty``); else the file of that instrument
    (:func:`volerr.instruments.simulated_files.instrument_file`: ``plant`` ... ``radius``,
    ``noise_um``, ``seed``, ``accept_implausible``).  Options a file does not use:
    :func:`volerr.instruments.simulated_files.refuse_unused`."""
    if instrument != "deviations":
        from ..instruments.simulated_files import instrument_file

        return instrument_file(layout, instrument, plant=plant, errors=errors, steps=steps,
                               radius=radius, noise_um=noise_um, seed=seed,
                               accept_implausible=accept_implausible)
    camp, name = simulate_options(layout, points=points, seed=seed, probes=probe,
                                  rounds=rounds, effects=effect, noise_um=noise_um,
                                  magnitude_um=magnitude_um, hours=hours, sensors=sensors,
                                  duty=duty)
    return camp.csv_text(), f"{camp.n_points} points of {name}"
