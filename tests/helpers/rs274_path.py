"""An independent path checker for the NC programs ``volerr plan`` writes (issue 36 item 3).

The programs are read by LinuxCNC's stand-alone RS274NGC interpreter (``rs274 -g -t TOOLS
PROGRAM``, package ``linuxcnc-uspace``), whose canonical commands are followed as a controller
would move the axes:

* ``STRAIGHT_TRAVERSE`` / ``STRAIGHT_FEED`` / ``STRAIGHT_PROBE`` (``G0`` / ``G1`` / ``G38.x``):
  a straight line in the axis positions, every axis (rotary ones too) interpolated linearly
  with the others, as a control without TCPM moves them;
* ``ARC_FEED`` (``G2`` / ``G3``): a circle in the selected plane about the centre given,
  ``rotation`` > 0 counter-clockwise about the plane's normal with ``|rotation| - 1`` extra
  whole turns (the RS274NGC canonical interface, Kramer et al., NIST IR 6556, 2000, sec. 4.3.5),
  the normal axis and the rotary axes interpolated linearly with the angle;
* ``DWELL`` (``G4``): a reading at a stop at the current position.

rs274 reports positions in the program's length units (checked: ``G20`` programs come back in
inches) and in the work coordinates (the ``G5x`` / ``G92`` / tool-length offsets taken off), so a
program is first required to be metric; the tool table handed to it gives every tool length 0,
so the canonical positions are the programmed axis positions.  Axis order of the canonical
commands: X Y Z A B C.  Nothing here imports ``volerr.plan``: the checks read the plan's files
(CSV and JSON) with their own readers and use only the layout's nominal forward kinematics
(``volerr.load(LAYOUT).forward``) to put the tool point into the workpiece frame.
"""

from __future__ import annotations

import dataclasses
import math
import re
import shutil
import subprocess
import tempfile
from pathlib import Path

import numpy as np

AXES = "XYZABC"
#: the line limit LinuxCNC's interpreter reads ("Command too long" from 255 characters on)
LINE_LIMIT = 254
_CANON = re.compile(r"^\s*\d+\s+N(\S+)\s+([A-Z_]+)\((.*)\)\s*$")
_NUMBER = re.compile(r"[-+]?\d+(?:\.\d*)?(?:[eE][-+]?\d+)?")


def rs274() -> str | None:
    """Path of the rs274 executable, or None."""
    return shutil.which("rs274")


SKIP_REASON = ("rs274 (LinuxCNC's stand-alone interpreter, Debian package linuxcnc-uspace) is "
               "not installed: .ci/run installs it with apt-get; apt could not reach the "
               "package archive here")


@dataclasses.dataclass
class Segment:
    """One motion: ``kind`` rapid | feed | probe | arc; ``start``, ``end`` (6,) X Y Z A B C;
    ``line`` the program's line number (1-based, None when unknown); for an arc ``plane``
    (first, second, normal axis indices), ``centre`` (2,) in the plane, ``rotation``."""

    kind: str
    start: np.ndarray
    end: np.ndarray
    line: int | None
    plane: tuple = (0, 1, 2)
    centre: np.ndarray | None = None
    rotation: int = 0

    def sweep(self) -> float:
        """Signed angle of an arc, rad (counter-clockwise positive about the plane's normal)."""
        i, j, _ = self.plane
        a0 = math.atan2(self.start[j] - self.centre[1], self.start[i] - self.centre[0])
        a1 = math.atan2(self.end[j] - self.centre[1], self.end[i] - self.centre[0])
        turns = abs(self.rotation) - 1
        if self.rotation > 0:
            d = (a1 - a0) % (2 * math.pi)
            d = d if d > 1e-12 else 2 * math.pi
            return d + 2 * math.pi * turns
        d = (a0 - a1) % (2 * math.pi)
        d = d if d > 1e-12 else 2 * math.pi
        return -(d + 2 * math.pi * turns)

    def at(self, t) -> np.ndarray:
        """(len(t), 6) positions at the parameters ``t`` in [0, 1]."""
        t = np.atleast_1d(np.asarray(t, float))[:, None]
        q = self.start + t * (self.end - self.start)
        if self.kind != "arc":
            return q
        i, j, _ = self.plane
        r0 = math.hypot(self.start[i] - self.centre[0], self.start[j] - self.centre[1])
        r1 = math.hypot(self.end[i] - self.centre[0], self.end[j] - self.centre[1])
        a0 = math.atan2(self.start[j] - self.centre[1], self.start[i] - self.centre[0])
        ang = a0 + t[:, 0] * self.sweep()
        r = r0 + t[:, 0] * (r1 - r0)
        q[:, i] = self.centre[0] + r * np.cos(ang)
        q[:, j] = self.centre[1] + r * np.sin(ang)
        return q

    def length(self) -> float:
        """Path length in the linear axes (mm) plus the rotary travel (deg), for sampling."""
        d = np.abs(self.end - self.start)
        lin = float(np.linalg.norm(d[:3]))
        if self.kind == "arc":
            i, j, k = self.plane
            r = math.hypot(self.start[i] - self.centre[0], self.start[j] - self.centre[1])
            lin = math.hypot(abs(self.sweep()) * r, d[k])
        return lin, float(d[3:].max())

    def samples(self, step_mm: float = 0.5, step_deg: float = 0.1) -> np.ndarray:
        """Parameters of points along the segment no farther apart than the steps."""
        lin, rot = self.length()
        n = max(2, int(math.ceil(max(lin / step_mm, rot / step_deg))) + 1)
        if self.kind == "arc":
            n = max(n, int(abs(self.sweep()) / math.radians(1.0)) + 2)
        return np.linspace(0.0, 1.0, n)

    def locate(self, q, tol: float) -> float | None:
        """Parameter of the point of this segment at ``q`` (6,) within ``tol`` (mm / deg in each
        axis), or None."""
        q = np.asarray(q, float)
        if self.kind != "arc":
            d = self.end - self.start
            dd = float(d @ d)
            t = 0.0 if dd == 0 else float(np.clip((q - self.start) @ d / dd, 0.0, 1.0))
        else:
            t = self._locate_arc(q)
            if t is None:
                return None
        return t if np.max(np.abs(self.at(t)[0] - q)) <= tol else None

    def _locate_arc(self, q):
        i, j, _ = self.plane
        a0 = math.atan2(self.start[j] - self.centre[1], self.start[i] - self.centre[0])
        a = math.atan2(q[j] - self.centre[1], q[i] - self.centre[0])
        sw = self.sweep()
        best = None
        for k in range(-abs(self.rotation) - 1, abs(self.rotation) + 2):
            t = ((a + 2 * math.pi * k) - a0) / sw
            if -1e-9 <= t <= 1 + 1e-9:
                t = min(max(t, 0.0), 1.0)
                err = np.max(np.abs(self.at(t)[0] - q))
                if best is None or err < best[1]:
                    best = (t, err)
        return None if best is None else best[0]


@dataclasses.dataclass
class Event:
    """A reading or a stop: ``kind`` dwell | stop | end; ``position`` (6,); ``after`` the number
    of segments before it; ``line``; ``value`` (dwell seconds)."""

    kind: str
    position: np.ndarray
    after: int
    line: int | None
    value: float = 0.0


@dataclasses.dataclass
class Trace:
    """The followed program: segments, events, the canonical units and the raw canon."""

    segments: list
    events: list
    units: list
    canon: list

    def dwells(self):
        return [e for e in self.events if e.kind == "dwell"]


class Rejected(Exception):
    """rs274 refused the program (its message, the offending line)."""


def _tool_table(program_text: str, folder: Path) -> Path:
    tools = {1} | {int(t) for t in re.findall(r"\bT(\d+)", program_text.upper())}
    path = folder / "tools.tbl"
    path.write_text("".join(f"T{t} P{t} Z0 D0 ;\n" for t in sorted(tools)))
    return path


def _numbered(text: str) -> str:
    """The program with ``N<line>`` in front of every block that has none (for line numbers in
    rs274's canon); comment-only, ``%`` and empty lines as they are."""
    out = []
    for k, line in enumerate(text.splitlines(), 1):
        s = line.strip()
        if not s or s.startswith(("%", "(", ";", "/", "N", "n", "O", "o")):
            out.append(line)
        else:
            out.append(f"N{k} {line}")
    return "\n".join(out) + "\n"


def _run(exe: str, program: Path, tools: Path) -> tuple:
    proc = subprocess.run([exe, "-g", "-t", str(tools), str(program)], capture_output=True,
                          text=True, timeout=120, stdin=subprocess.DEVNULL)
    return proc.returncode, proc.stdout, proc.stderr


def interpret(program: Path) -> list:
    """rs274's canonical commands of ``program``: [(name, args text, line or None)].  Raises
    :class:`Rejected` with rs274's message when it refuses the program."""
    exe = rs274()
    if exe is None:
        raise RuntimeError(SKIP_REASON)
    text = Path(program).read_text()
    with tempfile.TemporaryDirectory() as tmp:
        tmp = Path(tmp)
        tools = _tool_table(text, tmp)
        numbered = tmp / "numbered.ngc"
        numbered.write_text(_numbered(text))
        rc, out, err = _run(exe, numbered, tools)
        with_lines = rc == 0
        if rc != 0:                      # maybe only because the N words made a line too long
            rc, out, err = _run(exe, Path(program), tools)
        if rc != 0:
            msg = " | ".join(x.strip() for x in err.splitlines() if x.strip() != "executing")
            raise Rejected(f"rs274 exit {rc}: {msg[:300]}")
    canon = []
    for row in out.splitlines():
        m = _CANON.match(row)
        if m:
            n = m.group(1)
            line = int(n) if with_lines and n.isdigit() else None
            canon.append((m.group(2), m.group(3), line))
    return canon


def _numbers(args: str) -> list:
    return [float(x) for x in _NUMBER.findall(args)]


_PLANES = {"CANON_PLANE_XY": (0, 1, 2), "CANON_PLANE_XZ": (2, 0, 1),
           "CANON_PLANE_YZ": (1, 2, 0)}


def follow(canon: list) -> Trace:
    """The path of a canon list (rs274 starts at 0 in every axis)."""
    pos = np.zeros(6)
    plane = _PLANES["CANON_PLANE_XY"]
    segments, events, units = [], [], []
    kinds = {"STRAIGHT_TRAVERSE": "rapid", "STRAIGHT_FEED": "feed", "STRAIGHT_PROBE": "probe"}
    for name, args, line in canon:
        if name in kinds:
            end = np.array(_numbers(args)[:6])
            segments.append(Segment(kinds[name], pos.copy(), end, line))
            pos = end
        elif name == "ARC_FEED":
            v = _numbers(args)
            i, j, k = plane
            end = pos.copy()
            end[i], end[j], end[k] = v[0], v[1], v[5]
            end[3:6] = v[6:9]
            segments.append(Segment("arc", pos.copy(), end, line, plane,
                                    np.array([v[2], v[3]]), int(v[4])))
            pos = end
        elif name == "SELECT_PLANE":
            plane = _PLANES[args.strip()]
        elif name == "DWELL":
            events.append(Event("dwell", pos.copy(), len(segments), line, _numbers(args)[0]))
        elif name in ("PROGRAM_STOP", "OPTIONAL_PROGRAM_STOP"):
            events.append(Event("stop", pos.copy(), len(segments), line))
        elif name == "PROGRAM_END":
            events.append(Event("end", pos.copy(), len(segments), line))
        elif name == "USE_LENGTH_UNITS":
            units.append(args.strip())
    return Trace(segments, events, units, canon)


def load(program: Path) -> Trace:
    """rs274's reading of ``program``, followed (raises :class:`Rejected`)."""
    return follow(interpret(program))


# ---------------------------------------------------------------------------------------------
# the plan's files, read here (not with volerr's readers)

def read_csv(path: Trace) -> tuple:
    """(header comment lines without '# ', {column: list of str}) of a plan file."""
    comments, rows = [], []
    for line in Path(path).read_text().splitlines():
        if line.startswith("#"):
            comments.append(line[1:].strip())
        elif line.strip():
            rows.append(line.split(","))
    names = rows[0]
    cols = {n: [r[k] for r in rows[1:]] for k, n in enumerate(names)}
    return comments, cols


def column(cols: dict, name: str) -> np.ndarray:
    return np.array([float(x) for x in cols[name]])


def header_value(comments: list, key: str) -> str | None:
    for c in comments:
        if c.startswith(key + ":"):
            return c[len(key) + 1:].strip()
    return None


# ---------------------------------------------------------------------------------------------
# checks every program must pass: each returns a list of violations (empty: passes)

def _code_words(text: str) -> list:
    """Per line: the upper-case text with comments removed."""
    out = []
    for line in text.splitlines():
        line = re.sub(r"\([^)]*\)", "", line).split(";")[0]
        out.append(line.upper())
    return out


def program_text_checks(program: Path) -> list:
    """Lines < 254 characters; G21, G90, a work offset G54..G59, the tool length compensation
    (G43 on or G49 off) and M30 stated (ISO 6983 / RS274NGC words outside comments)."""
    text = Path(program).read_text()
    bad = []
    for k, line in enumerate(text.splitlines(), 1):
        if len(line) >= LINE_LIMIT:
            bad.append(f"line {k}: {len(line)} characters (limit {LINE_LIMIT - 1})")
    code = " ".join(_code_words(text))
    for word, what in (("G21", "metric"), ("G90", "absolute"), ("G5[4-9]", "work offset"),
                       ("G4[39]", "tool length compensation"), ("M30", "program end")):
        if not re.search(rf"(?<![A-Z0-9.]){word}(?![0-9.])", code):
            name = word.replace("[4-9]", "4..G59").replace("4[39]", "43 / G49")
            bad.append(f"no {name} ({what}) in the program")
    return bad


def path_checks(path: Trace, clearance_z: float) -> list:
    """Metric canon; the first motion a retract: only Z moves, up, to the clearance height
    ``clearance_z`` (the top of the Z travel, ISO 841 +Z away from the workpiece)."""
    bad = []
    if not path.units or any(u != "CANON_UNITS_MM" for u in path.units):
        bad.append(f"length units {path.units}: not metric throughout")
    if not path.segments:
        return bad + ["no motion at all"]
    s = next((s for s in path.segments if np.any(s.end != s.start)), path.segments[0])
    d = s.end - s.start
    others = [AXES[k] for k in range(6) if k != 2 and abs(d[k]) > 1e-9]
    if others or d[2] <= 0 or abs(s.end[2] - clearance_z) > 1e-3:
        bad.append(f"line {s.line}: the first motion ({s.kind}) is not a retract to Z"
                   f"{clearance_z:g} alone: it moves {others or ''} Z {s.start[2]:g} -> "
                   f"{s.end[2]:g}")
    if not any(e.kind == "end" for e in path.events):
        bad.append("rs274 read no program end")
    return bad


# ---------------------------------------------------------------------------------------------
# where the readings are

def locate(path: Trace, targets: np.ndarray, tol: float = 2e-3, headings=None) -> list:
    """For each target (N, 6) in order: (segment index, parameter) of the first point of the
    path at or after the previous one that is within ``tol`` of it in every axis and, where
    ``headings`` (N, 6) gives a direction, where the path moves along it (the tangent's dot
    product with it positive: a point visited twice, once each way, is read on its pass in
    the reading's direction); None where there is none."""
    out, k0, t0 = [], 0, 0.0
    for i, q in enumerate(targets):
        h = None if headings is None else headings[i]
        hit = None
        for k in range(k0, len(path.segments)):
            seg = path.segments[k]
            t = seg.locate(q, tol)
            if t is None or (k == k0 and t < t0 - 1e-12):
                continue
            if h is not None and np.linalg.norm(h) > 1e-6:
                lo, hi = max(t - 1e-6, 0.0), min(t + 1e-6, 1.0)
                if (seg.at(hi)[0] - seg.at(lo)[0]) @ h <= 0:
                    continue
            hit = (k, t)
            break
        out.append(hit)
        if hit is not None:
            k0, t0 = hit
    return out


def headings(rows: np.ndarray, sense: np.ndarray) -> np.ndarray:
    """Per reading the direction towards the next reading of the same ``sense`` (from the
    previous one for the last of a run of one sense); zero where a run has one reading."""
    h = np.zeros_like(rows)
    for i in range(len(rows)):
        if i + 1 < len(rows) and sense[i + 1] == sense[i]:
            h[i] = rows[i + 1] - rows[i]
        elif i > 0 and sense[i - 1] == sense[i]:
            h[i] = rows[i] - rows[i - 1]
    return h


def sample_between(path: Trace, a: tuple, b: tuple, **steps) -> tuple:
    """Positions (M, 6) along the path from location ``a`` to ``b`` and their segments' lines."""
    pts, lines = [], []
    for k in range(a[0], b[0] + 1):
        seg = path.segments[k]
        t = seg.samples(**steps)
        lo = a[1] if k == a[0] else 0.0
        hi = b[1] if k == b[0] else 1.0
        t = np.unique(np.concatenate([[lo, hi], t[(t > lo) & (t < hi)]]))
        pts.append(seg.at(t))
        lines += [seg.line] * len(t)
    return np.vstack(pts), np.array(lines, dtype=object)


def layout_positions(q6: np.ndarray, axes) -> np.ndarray:
    """(M, n_axes) columns of the layout's axes out of X Y Z A B C positions."""
    return np.column_stack([q6[:, AXES.index(a)] for a in axes])


def to_canon(values: dict, axes, n: int) -> np.ndarray:
    """(n, 6) X Y Z A B C positions from the layout's axis columns (others 0)."""
    q = np.zeros((n, 6))
    for a in axes:
        q[:, AXES.index(a)] = values[a]
    return q


def _groups(path: Trace) -> np.ndarray:
    """Per segment: the number of program stops (``M0``, a set-up change) before it."""
    stops = [e.after for e in path.events if e.kind == "stop"]
    return np.array([sum(a <= k for a in stops) for k in range(len(path.segments))], int)


def _labels(cols: dict) -> list:
    """Set-up labels in the file's order of appearance."""
    key = "station" if "station" in cols else "placement"
    seen = []
    for x in cols[key]:
        if x not in seen:
            seen.append(x)
    return seen


def _rows(cols: dict, axes, mask=None) -> np.ndarray:
    n = len(next(iter(cols.values())))
    mask = np.ones(n, bool) if mask is None else mask
    return to_canon({a: column(cols, a)[mask] for a in axes}, axes, int(mask.sum()))


def _probe(cols: dict, mask=None) -> np.ndarray:
    p = np.column_stack([column(cols, c) for c in ("Xp", "Yp", "Zp")])
    return p if mask is None else p[mask]


# ---------------------------------------------------------------------------------------------
# the kinds' checks

def ballbar_check(path: Trace, cols: dict, model, tol_mm: float = 1.0) -> tuple:
    """Every reading on the path in order (each on a pass in its direction of the circle), and
    the bar (tool-ball centre through the layout's
    nominal forward kinematics, in the workpiece frame, to the pivot on the table) within
    ``tol_mm`` of its length along the whole path while it is mounted: from the program stop
    before the first reading of a set-up (mount the bar) to the one after its last (remove
    it), or from the first to the last reading where the program has no such stops.  Returns (violations, {set-up: worst deviation mm})."""
    bad, worst = [], {}
    label = np.array(cols["placement"])
    for lab in _labels(cols):
        m = label == lab
        rows = _rows(cols, model.axes, m)
        where = locate(path, rows, headings=headings(rows, column(cols, "direction")[m]))
        missing = [k for k, w in enumerate(where) if w is None]
        if missing:
            bad.append(f"set-up {lab}: readings {missing[:5]} (of {m.sum()}) not on the path "
                       "in the file's order")
            continue
        bad += _detours(path, where, cols, m, model, lab)
        q6, lines = sample_between(path, *_mounted(path, where[0], where[-1]))
        tip = model.forward(layout_positions(q6, model.axes), probe=_probe(cols, m)[0])[:, :3]
        pivot = np.array([column(cols, c)[m][0] for c in ("pivot_x", "pivot_y", "pivot_z")])
        length = column(cols, "length_mm")[m][0]
        dev = np.linalg.norm(tip - pivot, axis=1) - length
        k = int(np.argmax(np.abs(dev)))
        worst[lab] = float(dev[k])
        if abs(dev[k]) > tol_mm:
            bad.append(f"set-up {lab}: bar {length:g} mm {'squeezed' if dev[k] < 0 else 'pulled'}"
                       f" by {abs(dev[k]):.2f} mm at line {lines[k]} (limit {tol_mm:g} mm)")
    return bad, worst


def _detours(path: Trace, where: list, cols: dict, m, model, lab: str) -> list:
    """Between two consecutive readings of one direction the tool point travels at most
    pi/2 times their distance: the most a circular arc of half a turn or less can (an arc
    taken the long way round, or any other detour, travels more).  Readings less than 1 mm
    apart (a sweep of ISO 10791-6, the tool following the table) are left to the bar check."""
    bad, sense = [], column(cols, "direction")[m]
    probe = _probe(cols, m)[0]
    for k in range(len(where) - 1):
        if sense[k] != sense[k + 1]:
            continue
        q6, lines = sample_between(path, where[k], where[k + 1])
        tip = model.forward(layout_positions(q6, model.axes), probe=probe)[:, :3]
        run = float(np.linalg.norm(np.diff(tip, axis=0), axis=1).sum())
        chord = float(np.linalg.norm(tip[-1] - tip[0]))
        if chord >= 1.0 and run > math.pi / 2 * chord + 1e-3:
            bad.append(f"set-up {lab}: from reading {k} to {k + 1} (lines {lines[0]}-"
                       f"{lines[-1]}) the tool point travels {run:.1f} mm for {chord:.1f} mm "
                       "apart (more than half a turn round)")
    return bad


def _mounted(path: Trace, first: tuple, last: tuple) -> tuple:
    """The path locations between which a ballbar is mounted (see :func:`ballbar_check`)."""
    stops = [e.after for e in path.events if e.kind == "stop"]
    before = [a for a in stops if a <= first[0]]
    after = [a for a in stops if a > last[0]]
    if not before or not after or after[0] - 1 < before[-1]:
        return first, last
    return (before[-1], 0.0), (after[0] - 1, 1.0)


def _tips(model, q6, probe):
    out = model.forward(layout_positions(q6, model.axes), probe=probe)
    return out[:, :3], out[:, 3:]


def sphere_check(path: Trace, cols: dict, model, radius_mm: float = 30.0) -> list:
    """Within ``radius_mm`` of the mounted sphere's centre the path has no rotary motion and no
    motion off the tool axis (the tool point moves along the tool axis only); the sphere of a
    segment is the set-up of the program-stop group it is in (``M0`` between placements)."""
    bad = []
    labels, group = _labels(cols), _groups(path)
    label = np.array(cols["placement"])
    if group.max(initial=0) + 1 != len(labels):
        bad.append(f"{group.max(initial=0) + 1} stop-separated groups for {len(labels)} "
                   "placements")
    rot = [AXES.index(a) for a in model.axes if a in model.rotary_axes]
    for k, seg in enumerate(path.segments):
        lab = labels[min(group[k], len(labels) - 1)]
        m = label == lab
        c = np.array([column(cols, n)[m][0] for n in ("sphere_x", "sphere_y", "sphere_z")])
        tip, axis = _tips(model, seg.at(seg.samples()), _probe(cols, m)[0])
        near = np.linalg.norm(tip - c, axis=1) < radius_mm
        if not near.any():
            continue
        turns = np.abs(seg.end[rot] - seg.start[rot]).max(initial=0.0)
        off = np.linalg.norm(np.cross(tip[near] - tip[0], axis[0]), axis=1).max()
        if turns > 1e-9 or off > 1e-3 or seg.kind == "arc":
            d = np.linalg.norm(tip - c, axis=1).min()
            bad.append(f"line {seg.line}: {seg.kind} {d:.1f} mm from sphere {lab} turns the "
                       f"rotary axes by {turns:g} deg and leaves the tool axis by {off:.2f} mm")
    return bad


def _balls(cols: dict, mask) -> np.ndarray:
    return np.column_stack([column(cols, c)[mask] for c in ("x_nom_mm", "y_nom_mm", "z_nom_mm")])


def artifact_check(path: Trace, cols: dict, model, clear_mm: float = 10.0) -> list:
    """Ball plate: no motion but a probing move within ``clear_mm`` of a ball centre of the
    mounted placement (its ``M0`` group); every probing move radial (its line through the
    centre of the ball it ends nearest, within 2 um: the touch normal to the surface), from
    outside (starting ``clear_mm`` or more from every centre, ending nearer its own), and passing
    no other ball; every ball probed at the points a centre needs (4 or more radial moves whose
    directions are not coplanar); and never behind the plate (:func:`plate_check`)."""
    bad, labels, group = [], _labels(cols), _groups(path)
    label = np.array(cols["placement"])
    hits = {(lab, b): [] for lab in labels for b in range(int((label == lab).sum()))}
    for k, seg in enumerate(path.segments):
        lab = labels[min(group[k], len(labels) - 1)]
        m = label == lab
        centres, probe = _balls(cols, m), _probe(cols, m)[0]
        tip, _ = _tips(model, seg.at(seg.samples()), probe)
        dist = np.linalg.norm(tip[:, None, :] - centres[None], axis=2)
        if seg.kind != "probe":
            if dist.min() < clear_mm:
                b = int(np.argmin(dist.min(axis=0)))
                bad.append(f"line {seg.line}: {seg.kind} passes {dist.min():.1f} mm from ball "
                           f"{b} of {lab} (limit {clear_mm:g})")
            continue
        own = int(np.argmin(dist[-1]))
        d = tip[-1] - tip[0]
        u = d / max(np.linalg.norm(d), 1e-12)
        w = centres[own] - tip[0]
        miss = float(np.linalg.norm(w - (w @ u) * u))
        others = np.delete(dist, own, axis=1)
        if (dist[0].min() < clear_mm or dist[-1, own] >= dist[0, own] or miss > 2e-3
                or (others.size and others.min() < clear_mm)):
            bad.append(f"line {seg.line}: probing move towards ball {own} of {lab} not radial "
                       f"from outside (starts {dist[0].min():.1f} mm from a centre, misses the "
                       f"centre by {miss:.3f} mm)")
        else:
            hits[(lab, own)].append(u)
    bad += plate_check(path, cols, model)
    for (lab, b), dirs in hits.items():
        rank = (np.linalg.matrix_rank(np.array(dirs[1:]) - dirs[0], tol=1e-3)
                if len(dirs) > 1 else 0)
        if len(dirs) < 4 or rank < 3:
            bad.append(f"ball {b} of {lab}: {len(dirs)} radial probing moves, directions of "
                       f"affine rank {rank} (a centre needs 4 not coplanar)")
    return bad


def plate_check(path: Trace, cols: dict, model, margin_mm: float = 25.0,
                behind_mm: float = 1.0) -> list:
    """The probe never goes behind a mounted plate: the plane of the placement's ball centres
    (fitted here), its free side the one the probe is on when it starts the placement's first
    probing move; inside the outline (the centres' extent along the plate's rows and columns,
    ball 0 to its nearest neighbour the first, widened by ``margin_mm``) the tool point stays on that side, at most ``behind_mm`` behind the plane
    (the plate and the balls' stems are there).  Placements of fewer than 3 balls out of one
    line are left out."""
    bad, labels, group = [], _labels(cols), _groups(path)
    label = np.array(cols["placement"])
    for g, lab in enumerate(labels):
        m = label == lab
        centres, probe = _balls(cols, m), _probe(cols, m)[0]
        mid = centres.mean(axis=0)
        _, sv, vt = np.linalg.svd(centres - mid)
        segs = [s for k, s in enumerate(path.segments) if group[k] == g]
        first = next((s for s in segs if s.kind == "probe"), None)
        if len(centres) < 3 or sv[1] < 1e-6 or first is None:
            continue
        n = vt[2]                            # the plate's rows: ball 0 to its nearest ball
        d = np.linalg.norm(centres[1:] - centres[0], axis=1)
        e1 = centres[1 + int(np.argmin(d))] - centres[0]
        e1 = e1 - (e1 @ n) * n
        e1 /= np.linalg.norm(e1)
        e2 = np.cross(n, e1)
        side = np.sign((_tips(model, first.start[None], probe)[0][0] - mid) @ n)
        uv = (centres - mid) @ np.column_stack([e1, e2])
        lo, hi = uv.min(axis=0) - margin_mm, uv.max(axis=0) + margin_mm
        for seg in segs:
            tip, _ = _tips(model, seg.at(seg.samples()), probe)
            w = (tip - mid) @ np.column_stack([e1, e2])
            inside = np.all((w >= lo) & (w <= hi), axis=1)
            depth = side * ((tip - mid) @ n)
            if inside.any() and depth[inside].min() < -behind_mm:
                bad.append(f"line {seg.line}: {seg.kind} goes {-depth[inside].min():.1f} mm "
                           f"behind plate {lab} (its free side {np.round(side * n, 3).tolist()})")
    return bad


def interferometer_check(path: Trace, comments: list, cols: dict, model,
                         overshoot_mm: float = 1.0) -> tuple:
    """Laser-interferometer line: one dwell per row, at the row's target (the line's axis) and
    the line's ``at`` position; each reached from its declared direction (the last motion
    before the dwell moves the line's axis alone, in the sign of ``direction``); before every
    reversal the axis travels beyond both targets by ``overshoot_mm`` or more (ISO 230-2:2014
    cl. 3.1: each target approached from one direction, so a reversal needs an overrun).
    Returns (violations, [overshoots mm])."""
    bad, shoots = [], []
    axis = AXES.index(header_value(comments, "axis"))
    at = {a.split("=")[0].strip(): float(a.split("=")[1]) for a in
          header_value(comments, "at").split(",") if "=" in a}
    target, sense = column(cols, "target_mm"), column(cols, "direction")
    dwells = path.dwells()
    if len(dwells) != len(target):
        return [f"{len(dwells)} dwells for {len(target)} readings"], shoots
    for i, e in enumerate(dwells):
        want = {axis: target[i], **{AXES.index(a): v for a, v in at.items()}}
        off = max(abs(e.position[j] - v) for j, v in want.items())
        if off > 1e-3:
            bad.append(f"line {e.line}: reading {i} at {e.position[axis]:g} not at the plan's "
                       f"{target[i]:g} / {at} (off by {off:.4f})")
        moved = [s for s in path.segments[:e.after] if np.any(s.end != s.start)]
        d = moved[-1].end - moved[-1].start if moved else np.zeros(6)
        if np.abs(np.delete(d, axis)).max() > 1e-9 or np.sign(d[axis]) != sense[i]:
            bad.append(f"line {e.line}: reading {i} ({target[i]:g}, direction {sense[i]:+g}) "
                       f"reached by a motion of {np.round(d, 4).tolist()}")
    for i in range(len(dwells) - 1):
        if sense[i] == sense[i + 1]:
            continue
        segs = path.segments[dwells[i].after:dwells[i + 1].after]
        x = np.concatenate([s.at(s.samples())[:, axis] for s in segs]) if segs else np.zeros(1)
        s = sense[i]
        shoot = float(np.max(s * x) - max(s * target[i], s * target[i + 1]))
        shoots.append(shoot)
        if shoot < overshoot_mm:
            bad.append(f"line {dwells[i + 1].line}: reversal after reading {i} with an "
                       f"overshoot of {shoot:.3f} mm (at least {overshoot_mm:g})")
    return bad, shoots


def dwell_check(path: Trace, cols: dict, axes) -> list:
    """Readings at a stop (sphere / R-test, tracking interferometer): the dwells, in order, are
    exactly at the plan's rows (every axis within 1 um / 0.001 deg)."""
    rows, dw = _rows(cols, axes), path.dwells()
    if len(dw) != len(rows):
        return [f"{len(dw)} dwells for {len(rows)} readings"]
    idx = [AXES.index(a) for a in axes]
    bad = []
    for i, (e, q) in enumerate(zip(dw, rows)):
        off = np.abs(e.position[idx] - q[idx]).max()
        if off > 1e-3:
            bad.append(f"line {e.line}: dwell {i} off the plan's row by {off:.4f}")
    return bad
