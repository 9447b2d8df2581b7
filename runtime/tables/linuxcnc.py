"""LinuxCNC joint compensation files (``[JOINT_n] COMP_FILE``, "lead screw compensation").

Sources: LinuxCNC documentation, INI Configuration, ``[JOINT_<num>]`` section, ``COMP_FILE``
and ``COMP_FILE_TYPE`` (docs/src/config/ini-config.adoc, LinuxCNC 2.9); the motion module
that applies them: ``usrmotLoadComp`` (src/emc/motion/usrmotintf.cc), ``EMCMOT_COMP_SIZE``
(src/emc/motion/motion.h) and ``compute_screw_comp`` / ``output_to_hal``
(src/emc/motion/control.c).

A compensation file is one joint's table, one line per point, three numbers separated by
blanks, the first the nominal (commanded) joint position, nominals strictly increasing, at
most :data:`MAX_POINTS` (256) lines; machine units (volerr: mm, deg for an angular joint):

* ``COMP_FILE_TYPE = 0``: ``nominal forward reverse`` -- the actual positions the joint
  reaches when commanded to ``nominal`` while moving in the positive (forward) and the
  negative (reverse) direction.  volerr writes ``nominal + E_fwd`` and ``nominal + E_rev``.
* ``COMP_FILE_TYPE = 1``: ``nominal forward_trim reverse_trim`` -- the corrections the motion
  module adds to the commanded position.  ``usrmotLoadComp`` turns a type-0 line into
  exactly these (``trim = nominal - actual``), so volerr writes ``-E_fwd`` and ``-E_rev``.

Sign, as the source applies it: the joint's motor is commanded at ``pos_cmd + trim``
(``motor_pos_cmd = pos_cmd + backlash_filt + motor_offset``, the trim interpolated linearly
between the points from the forward column while ``vel_cmd > 0`` and from the reverse one
while ``vel_cmd < 0``, the last one kept while the joint stands still), so a joint whose
actual position is ``nominal + E`` ends at ``nominal``: the table's trims are the negated
errors.  Beyond the first and last point the end values hold (the table's guard entries at
``-HUGE_VAL`` / ``+HUGE_VAL``).  When ``COMP_FILE`` is given, ``BACKLASH`` is not used: the
reversal goes into the two columns.

What volerr writes from an error directory (``volerr controller export ... --format linuxcnc
--out DIR``): per axis with a positioning error ``E<A><A>`` one file ``DIR/<A>.comp`` on
equally spaced points over the error table's range (a rotary joint over the table's range
in deg, not wrapped: LinuxCNC's table has no modulo), ``E_fwd = E + RV/2``, ``E_rev = E -
RV/2`` where the error table carries a reversal column ``RV_<A>_um`` (ISO 230-2 ``B``: the
positive-approach mean minus the negative-approach one), both ``E`` otherwise; values to
:data:`INCREMENT` (1 nm / 1e-6 deg); and ``DIR/compensation.ini``, the ini lines that load
them (``[JOINT_n]`` with ``n`` the axis' index in the layout's order, the identity
kinematics ``trivkins`` numbering; append them to the machine's ini, renumber for other
kinematics).  Joint compensation carries one error per joint: straightness, angular errors,
squareness are left whole.
"""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np

from ..errors import InputError, require
from . import comp_tables as ct

#: EMCMOT_COMP_SIZE (motion.h): points per joint table
MAX_POINTS = 256
#: mm (deg for an angular joint): the values' resolution as written
INCREMENT = 1e-6
INI_NAME = "compensation.ini"
_NUM = r"[+-]?(?:\d+\.?\d*|\.\d+)(?:[eE][+-]?\d+)?"


def _fmt(v: float) -> str:
    s = f"{v:.6f}".rstrip("0").rstrip(".")
    return "0" if s in ("-0", "") else s


def file_name(axis: str) -> str:
    return f"{axis}.comp"


def build(funcs, max_points: int = MAX_POINTS) -> list:
    """Positioning tables of every axis with one (not wrapped), split into forward (+1) and
    reverse (-1) tables where the error table carries a reversal."""
    require(max_points <= MAX_POINTS, f"--points: LinuxCNC holds at most {MAX_POINTS} per joint")
    out = []
    for a in funcs.model.axes:
        if not ct.has_positioning(funcs, a):
            continue
        start, step, n = ct.grid_for(funcs, a, max_points, False)
        pos = start + step * np.arange(n)
        vals = ct.error_values(funcs, f"E{a}{a}", a, pos)
        out.append(ct.CompTable(f"E{a}{a}", a, a, start, step, ct.quantize(vals, INCREMENT)))
    return ct.reversal_tables(funcs, out, INCREMENT)


def _columns(tables: list) -> dict:
    """{axis: (nominal, E_fwd, E_rev)} of the tables (a table of both directions in both)."""
    cols: dict = {}
    for t in tables:
        nom, fwd, rev = cols.get(t.input, (t.positions, None, None))
        if t.direction >= 0:
            fwd = t.values
        if t.direction <= 0:
            rev = t.values
        cols[t.input] = (nom, fwd, rev)
    return cols


def write(model_name: str, tables: list, axes, comp_type: int = 0) -> dict:
    """{file name: text}: one ``<A>.comp`` per axis and :data:`INI_NAME` (the ini lines)."""
    require(comp_type in (0, 1), f"--comp-file-type must be 0 or 1, not {comp_type}")
    files, ini = {}, [f"# volerr export: layout {model_name}; LinuxCNC joint compensation "
                      f"(COMP_FILE_TYPE {comp_type}), machine units mm / deg",
                      "# append to the machine's ini (joint numbers: the layout's axis order, "
                      "trivkins)"]
    for a, (nom, fwd, rev) in _columns(tables).items():
        if comp_type == 0:
            rows = zip(nom, nom + fwd, nom + rev)
        else:
            rows = zip(nom, -fwd, -rev)
        files[file_name(a)] = "".join(f"{_fmt(p)} {_fmt(f)} {_fmt(r)}\n" for p, f, r in rows)
        ini += ["", f"[JOINT_{list(axes).index(a)}]", f"# axis {a}",
                f"COMP_FILE = {file_name(a)}", f"COMP_FILE_TYPE = {comp_type}"]
    files[INI_NAME] = "\n".join(ini) + "\n"
    return files


def _ini_entries(text: str, where: str) -> dict:
    """{joint: (COMP_FILE, COMP_FILE_TYPE)} of the ``[JOINT_n]`` sections that name a file."""
    section, got = None, {}
    for n, raw in enumerate(text.splitlines(), start=1):
        line = raw.strip()
        if not line or line[0] in "#;":
            continue
        m = re.fullmatch(r"\[([^\]]+)\]", line)
        if m:
            j = re.fullmatch(r"JOINT_(\d+)", m.group(1).strip())
            section = int(j.group(1)) if j else None
            continue
        key, eq, val = line.partition("=")
        if section is None or not eq or key.strip() not in ("COMP_FILE", "COMP_FILE_TYPE"):
            continue
        got.setdefault(section, {})[key.strip()] = (val.strip(), n)
    out = {}
    for j, kv in got.items():
        require("COMP_FILE" in kv, f"{where}: [JOINT_{j}] has COMP_FILE_TYPE but no COMP_FILE")
        require("COMP_FILE_TYPE" in kv, f"{where}: [JOINT_{j}] COMP_FILE without "
                                        "COMP_FILE_TYPE (LinuxCNC needs it for each file)")
        t, n = kv["COMP_FILE_TYPE"]
        require(t in ("0", "1"), f"{where} line {n}: COMP_FILE_TYPE must be 0 or 1, not {t!r}")
        out[j] = (kv["COMP_FILE"][0], int(t))
    require(out, f"{where}: no [JOINT_n] section with a COMP_FILE")
    return out


def read_comp_file(path: Path, comp_type: int) -> tuple:
    """(nominal, E_fwd, E_rev) arrays of one compensation file, errors in mm / deg."""
    require(path.is_file(), f"compensation file not found: {path}")
    rows = []
    for n, raw in enumerate(path.read_text(encoding="latin-1").splitlines(), start=1):
        cells = raw.split()
        if not cells:
            continue
        require(len(cells) == 3 and all(re.fullmatch(_NUM, c) for c in cells),
                f"{path} line {n}: expected three numbers 'nominal forward reverse'")
        rows.append([float(c) for c in cells])
    require(len(rows) >= 2, f"{path}: fewer than two points")
    require(len(rows) <= MAX_POINTS, f"{path}: {len(rows)} points, LinuxCNC holds "
                                     f"{MAX_POINTS} per joint")
    a = np.array(rows)
    require(np.all(np.diff(a[:, 0]) > 0), f"{path}: the nominal positions must increase "
                                          "from line to line")
    nom = a[:, 0]
    if comp_type == 0:
        fwd, rev = a[:, 1] - nom, a[:, 2] - nom
    else:
        fwd, rev = -a[:, 1], -a[:, 2]
    # the written values are multiples of INCREMENT: the subtraction's last bits are noise
    return nom, np.round(fwd, 9), np.round(rev, 9)


def _joint_files(ini_path, model):
    """(axis, file, nominal, E_fwd, E_rev) of every joint the ini compensates."""
    p = Path(ini_path)
    require(p.is_file(), f"ini file not found: {ini_path}")
    for j, (name, ctype) in sorted(_ini_entries(p.read_text(encoding="latin-1"),
                                                str(p)).items()):
        require(j < len(model.axes), f"{p}: [JOINT_{j}], but {model.name} has "
                                     f"{len(model.axes)} axes (joints 0..{len(model.axes) - 1})")
        f = Path(name) if Path(name).is_absolute() else p.parent / name
        yield (model.axes[j], f, *read_comp_file(f, ctype))


def read_tables(ini_path, model) -> list:
    """The :class:`~volerr.tables.comp_tables.CompTable` s of an ini's equally spaced
    compensation files (the tables volerr writes): one per joint, or a forward (+1) and a
    reverse (-1) one where they differ."""
    out = []
    for a, f, nom, fwd, rev in _joint_files(ini_path, model):
        step = float(nom[1] - nom[0])
        require(np.allclose(np.diff(nom), step, rtol=0, atol=1e-9),
                f"{f}: nominal positions not equally spaced (volerr controller import reads "
                "any spacing)")
        pairs = [(0, fwd)] if np.array_equal(fwd, rev) else [(1, fwd), (-1, rev)]
        out += [ct.CompTable(f"E{a}{a}", a, a, float(nom[0]), step, v, False, d)
                for d, v in pairs]
    return out


def read(ini_path, model) -> dict:
    """{axis: :class:`volerr.tables.table.ErrorTable`} of an ini (the snippet volerr writes
    or a machine's whole ini: only ``[JOINT_n] COMP_FILE`` / ``COMP_FILE_TYPE`` are read),
    the files relative to the ini's folder; a rotary joint's positioning (deg) becomes the
    rotation about its direction (rad); forward and reverse become the mean and the reversal
    ``RV`` (forward minus reverse)."""
    from .table import ErrorTable

    out = {}
    for a, f, nom, fwd, rev in _joint_files(ini_path, model):
        mean, rv = 0.5 * (fwd + rev), fwd - rev
        if ct.rotary(a):
            require(np.allclose(rv, 0.0, atol=1e-12), f"{f}: forward and reverse differ for "
                    f"the rotary joint {a} (a rotary reversal is not read)")
            u = ct.direction(model, a)
            values = {f"E{r}{a}": u[k] * np.deg2rad(mean)
                      for k, r in enumerate("ABC") if abs(u[k]) > 1e-12}
            rv = None
        else:
            values = {f"E{a}{a}": mean}
            rv = rv if np.any(np.abs(rv) > 0) else None
        try:
            out[a] = ErrorTable(a, nom, values, reversal=rv)
        except InputError as exc:
            raise InputError(f"{f}: {exc}") from None
    return out
