"""Length tests in the working volume: space diagonals (Pahk 1995, sec. 4), face diagonals,
axis-parallel lines.

The box is the travel of the three linear axes (rotary axes fixed, default 0 deg).  Corners are
named by three digits, 0 = minimum and 1 = maximum of X, Y, Z: ``000-111`` is the space diagonal
from (Xmin, Ymin, Zmin) to (Xmax, Ymax, Zmax).  Lines:

* ``space``: the four space diagonals ``000-111``, ``100-011``, ``010-101``, ``110-001``;
* ``face``: the twelve face diagonals, two on each face;
* ``axis``: the twelve edges and the three centre lines (``X@centre`` ...) through the middle of
  the box parallel to the axes.

Length deviation of a line from P1 to P2 (nominal probe-tip points, unit direction u) is the
distance between the *actual* probe-tip points minus the nominal distance.  To first order in the
errors it is the projection of the error difference on the line:

    dL = u . (d(P2) - d(P1)),        d = actual - nominal (``Model.volumetric_error``)

(the neglected term is |d_perp|^2 / (2 L), below 1e-6 um for errors of 100 um over 1 m).  A CMM
that measures a gauge of true length along that line indicates ``-dL`` too much: the scales read
the nominal distance while the probe travels the actual one.  ``profile`` gives dL(s) from P1 to
the point at distance s along the line.

Random component (tables with standard deviations), first-order propagation with this
assumption: the random error of a *table* parameter is a random variable per measured position
of its axis, independent between different positions and identical (fully correlated) where both
points share the position of that axis (e.g. both ends of an edge along X have the same Y and Z,
so the Y- and Z-table random errors cancel in the length); a constant (squareness) is one
variable for the whole volume.  Hence

    u_L^2 = sum_p [ (a2_p s_p(P2))^2 + (a1_p s_p(P1))^2 ]        different positions of p's axis
          + sum_p   (a2_p - a1_p)^2 s_p^2                          same position / constants

with a_p = u . dd/dp at each end.  This is the standard uncertainty (k = 1) of dL.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np

from ..plotstyle import label, styled
from ..units import UM_PER_MM
from ..errors import require
from .volmap import fixed_positions, linear_axes

from ..choices import DIAGONAL_KINDS as KINDS  # noqa: E402  (stated once, light)


@dataclass
class Line:
    """A test line: ``start``/``end`` = positions of the linear axes (mm), in grid-axis order."""

    name: str
    kind: str
    start: tuple
    end: tuple


@dataclass
class LineResult:
    line: Line
    length_mm: float
    deviation_um: float
    exact_um: float
    random_um: float | None = None
    profile_s_mm: np.ndarray = field(default_factory=lambda: np.zeros(0))
    profile_um: np.ndarray = field(default_factory=lambda: np.zeros(0))
    profile_random_um: np.ndarray | None = None
    #: parameter -> (variance term of u(dL), mm^2; its larger u at the ends, mm or rad)
    random_terms: dict | None = None

    def as_dict(self, with_profile: bool = True) -> dict:
        d = {"name": self.line.name, "kind": self.line.kind,
             "start_mm": [float(v) for v in self.line.start],
             "end_mm": [float(v) for v in self.line.end],
             "length_mm": self.length_mm, "deviation_um": self.deviation_um,
             "exact_um": self.exact_um}
        if self.random_um is not None:
            d["random_um"] = self.random_um
        if with_profile and self.profile_s_mm.size:
            d["profile"] = {"s_mm": self.profile_s_mm.tolist(),
                            "deviation_um": self.profile_um.tolist()}
            if self.profile_random_um is not None:
                d["profile"]["random_um"] = self.profile_random_um.tolist()
        return d


def box_lines(travel: dict, axes=("X", "Y", "Z"), kinds=KINDS) -> list:
    """The test lines of the box spanned by ``travel`` (axis -> (min, max))."""
    for k in kinds:
        require(k in KINDS, f"unknown line kind {k!r} (space, face, axis)")
    lo = np.array([travel[a][0] for a in axes], dtype=float)
    hi = np.array([travel[a][1] for a in axes], dtype=float)
    mid = 0.5 * (lo + hi)

    def corner(code):
        return tuple(float(hi[i] if c == "1" else lo[i]) for i, c in enumerate(code))

    lines = []
    if "space" in kinds:
        for a in ("000", "100", "010", "110"):
            b = "".join("1" if c == "0" else "0" for c in a[:2]) + "1"
            lines.append(Line(f"{a}-{b}", "space", corner(a), corner(b)))
    if "face" in kinds:
        for fixed in range(3):  # the face has axis `fixed` at min (0) or max (1)
            u, v = [i for i in range(3) if i != fixed]
            for side in "01":
                for d in ((0, 0, 1, 1), (1, 0, 0, 1)):  # (u0, v0) -> (u1, v1)
                    a, b = ["0"] * 3, ["0"] * 3
                    a[fixed] = b[fixed] = side
                    a[u], a[v], b[u], b[v] = str(d[0]), str(d[1]), str(d[2]), str(d[3])
                    lines.append(Line(f"{''.join(a)}-{''.join(b)}", "face",
                                      corner("".join(a)), corner("".join(b))))
    if "axis" in kinds:
        for along in range(3):
            others = [i for i in range(3) if i != along]
            for c1 in "01":
                for c2 in "01":
                    a = ["0"] * 3
                    a[others[0]], a[others[1]] = c1, c2
                    b = list(a)
                    b[along] = "1"
                    lines.append(Line(f"{''.join(a)}-{''.join(b)}", "axis",
                                      corner("".join(a)), corner("".join(b))))
            s, e = mid.copy(), mid.copy()
            s[along], e[along] = lo[along], hi[along]
            lines.append(Line(f"{axes[along]}@centre", "axis", tuple(s), tuple(e)))
    return lines


def _positions(model, pts: np.ndarray, lin, fixed: dict) -> dict:
    pos = {a: pts[:, i] for i, a in enumerate(lin)}
    for a, v in fixed.items():
        pos[a] = np.full(len(pts), v)
    return {a: pos[a] for a in model.axes}


def length_random(model, funcs, pos1: dict, pos2: dict, u: np.ndarray, probe,
                  parts: dict | None = None) -> np.ndarray:
    """Standard uncertainty (mm) of u.(d(P2) - d(P1)) for paired points (module docstring).
    ``parts``, when given, receives per error parameter (variance term mm^2, its standard
    uncertainty, the larger of its values at P1 and P2): the sources of the sum of variances
    (:func:`budgets`)."""
    n = len(next(iter(pos2.values())))
    s1 = model.sensitivity(pos1, probe)          # (n, 3, n_par)
    s2 = model.sensitivity(pos2, probe)
    a1 = np.einsum("ni,nip->np", u, s1)
    a2 = np.einsum("ni,nip->np", u, s2)
    sig1, sig2 = funcs.sigmas(pos1), funcs.sigmas(pos2)
    var = np.zeros(n)
    paxis = model.parameter_axis
    for j, p in enumerate(model.parameters):
        if p not in sig2:
            continue
        g1 = np.broadcast_to(sig1[p], (n,))
        g2 = np.broadcast_to(sig2[p], (n,))
        ax = paxis.get(p)
        same = np.ones(n, bool) if ax is None else np.isclose(pos1[ax], pos2[ax], rtol=0, atol=1e-9)
        term = np.where(same, (a2[:, j] * g2 - a1[:, j] * g1) ** 2,
                        (a2[:, j] * g2) ** 2 + (a1[:, j] * g1) ** 2)
        var += term
        if parts is not None:
            parts[p] = (term, np.maximum(np.abs(g1), np.abs(g2)))
    return np.sqrt(var)


def evaluate_lines(model, funcs, lines, probe=(0.0, 0.0, 0.0), at=None,
                   profile_points: int = 21) -> list:
    """Length deviation (first order and exact), random component and profile of every line."""
    lin = linear_axes(model)
    fixed = fixed_positions(model, at)
    probe = np.asarray(probe, dtype=float)
    require(profile_points >= 2, "a profile needs at least two points")
    t = np.linspace(0.0, 1.0, profile_points)
    starts = np.array([ln.start for ln in lines], dtype=float)
    ends = np.array([ln.end for ln in lines], dtype=float)
    # all profile points of all lines at once: (n_lines * n_t, 3)
    pts = (starts[:, None, :] + t[None, :, None] * (ends - starts)[:, None, :]).reshape(-1, 3)
    pos = _positions(model, pts, lin, fixed)
    err = model.volumetric_error(pos, funcs(pos), probe=probe).reshape(len(lines), len(t), 3)
    nom = model.nominal_position(pos, probe=probe).reshape(len(lines), len(t), 3)
    ex = model.exact_error(pos, funcs(pos), probe=probe).reshape(len(lines), len(t), 3)
    rand = None
    if getattr(funcs, "has_random", False):
        p0 = np.repeat(starts, len(t), axis=0)
        pos0 = _positions(model, p0, lin, fixed)
        dirs = np.repeat(nom[:, -1, :] - nom[:, 0, :], len(t), axis=0)
        dirs = dirs / np.linalg.norm(dirs, axis=1, keepdims=True)
        parts = {}
        rand = length_random(model, funcs, pos0, pos, dirs, probe, parts).reshape(
            len(lines), len(t))
        rand[:, 0] = 0.0  # zero length: the same point
    out = []
    for i, ln in enumerate(lines):
        vec = nom[i, -1] - nom[i, 0]
        length = float(np.linalg.norm(vec))
        require(length > 0, f"line {ln.name} has zero length")
        u = vec / length
        prof = (err[i] - err[i, 0]) @ u
        actual = (nom[i, -1] + ex[i, -1]) - (nom[i, 0] + ex[i, 0])
        out.append(LineResult(ln, length, float(prof[-1] * UM_PER_MM),
                              float((np.linalg.norm(actual) - length) * UM_PER_MM),
                              None if rand is None else float(rand[i, -1] * UM_PER_MM),
                              t * length, prof * UM_PER_MM,
                              None if rand is None else rand[i] * UM_PER_MM,
                              None if rand is None else
                              {p: (float(v.reshape(len(lines), len(t))[i, -1]),
                                   float(np.broadcast_to(g, v.shape).reshape(
                                       len(lines), len(t))[i, -1]))
                               for p, (v, g) in parts.items()}))
    return out


def budgets(results) -> dict:
    """The GUM budget (:mod:`volerr.report.budget`, um) of every line's random part u(dL),
    keyed by its row ``dL(name)``: one source per error parameter with a standard
    uncertainty in the tables (mm or rad, the larger at the line's two ends, as um or urad),
    its sensitivity
    the term's square root over it -- the terms :func:`length_random` sums (a parameter of
    the same axis position at both ends enters once, as the difference of its two
    effects)."""
    from ..machine.iso_names import is_angle
    from ..report.budget import budget, source

    out = {}
    for r in results:
        if r.random_um is None or not r.random_terms:
            continue
        srcs = []
        for p, (var, g) in r.random_terms.items():
            try:
                f, unit = (1e6, "urad") if is_angle(p) else (1e3, "um")
            except Exception:          # a parameter of no ISO name: as a length
                f, unit = 1e3, "um"
            c = np.sqrt(max(var, 0.0)) * UM_PER_MM
            if c > 0:
                srcs.append(source(p, g * f, unit, c / (g * f) if g else 0.0))
        row = f"dL({r.line.name})"
        out[row] = budget(row, "um", srcs, 2.0)
    return out


def format_table(results) -> str:
    """Plain-text table of the results (um)."""
    has_r = any(r.random_um is not None for r in results)
    head = f"{'line':12s} {'kind':5s} {'from (mm)':>22s} {'to (mm)':>22s} {'L (mm)':>9s} {'dL (um)':>8s}"
    if has_r:
        head += f" {'u(dL) (um)':>10s}"
    rows = [head, "-" * len(head)]
    for r in results:
        f = " ".join(f"{v:g}" for v in r.line.start)
        t = " ".join(f"{v:g}" for v in r.line.end)
        row = f"{r.line.name:12s} {r.line.kind:5s} {f:>22s} {t:>22s} {r.length_mm:9.2f} {r.deviation_um:8.2f}"
        if has_r:
            row += f" {r.random_um:10.2f}"
        rows.append(row)
    return "\n".join(rows)


@styled
def plot_lines(results, path, title: str = "", inputs=()) -> None:
    """Profiles of the space diagonals (top; +-2 u band, k = 2, with uncertainty columns) and
    all deviations (below, bars +-2 u)."""
    import matplotlib

    from ..plotstyle import figure
    from .volmap import save_figure

    fig, (a1, a2) = figure(2, 1, height=8.5, height_ratios=[1, 1.15])
    space = [r for r in results if r.line.kind == "space"] or results[:4]
    for i, r in enumerate(space):
        c = f"C{i}"
        a1.plot(r.profile_s_mm, r.profile_um, color=c,
                label=f"{r.line.name}: {r.deviation_um:+.1f} \u00b5m")
        if r.profile_random_um is not None:
            a1.fill_between(r.profile_s_mm, r.profile_um - 2 * r.profile_random_um,
                            r.profile_um + 2 * r.profile_random_um, color=c, alpha=0.15)
    a1.axhline(0, color="0.5", lw=0.6)
    a1.set_xlabel(label("distance along the diagonal", "mm"))
    a1.set_ylabel(label("length deviation", "um"))
    a1.set_title("space diagonals" + (" (band: \u00b12 u, k = 2)" if space and
                                      space[0].profile_random_um is not None else ""))
    a1.legend()
    colors = {"space": "C3", "face": "C0", "axis": "C2"}
    x = np.arange(len(results))
    a2.bar(x, [r.deviation_um for r in results], color=[colors[r.line.kind] for r in results],
           yerr=[2 * r.random_um for r in results] if all(r.random_um is not None for r in results)
           else None, capsize=2)
    a2.set_xticks(x, [r.line.name for r in results], rotation=90)
    a2.set_ylabel(label("length deviation", "um"))
    a2.axhline(0, color="0.5", lw=0.6)
    handles = [matplotlib.patches.Patch(color=c, label=k) for k, c in colors.items()
               if any(r.line.kind == k for r in results)]
    a2.legend(handles=handles)
    a2.set_title("all lines" + (" (error bars: \u00b12 u, k = 2)" if results and
                                results[0].random_um is not None else ""))
    if title:
        fig.suptitle(title)
    save_figure(fig, path, inputs)
