"""``volerr history add`` and ``volerr history show`` as functions (the commands are thin
layers over :func:`add` and :func:`show`).

Rules of ``add`` (the store's own rules in :mod:`volerr.history.store`):

* A machine id is 1 to 64 characters: letters, digits, space and ``. _ - : / + #``, not
  starting or ending with a space (:data:`MACHINE_RULE`).  Anything else (quotes, ``;``,
  control characters) is refused; every id is sent to the database as a bound parameter
  anyway.
* A result's date: ``--date`` (YYYY-MM-DD, for every file of one ``add``), else the date the
  result states (``"date"``), else today (UTC).  A date after today is refused (a result is
  not from the future); a date before the stored entries is accepted (an old certificate
  back-filled takes its place in date order).
* All entries of a machine are of one layout; a parameter keeps its unit.
* A check needs its reference in the machine's history: the calibration (or earlier check,
  whose ``parameters`` are then the base) it names by SHA-256 (``"reference_sha256"`` or
  ``"reference": {"sha256"}``), else the latest calibration dated on or before the check; the
  reference must not be dated after the check.
* The files of one ``add`` are stored in date order (calibrations before checks of the same
  date), so a reference and its checks can be added at once.
* Several files in one ``add``: one transaction, all or none.
"""

from __future__ import annotations

import re
from pathlib import Path

from ..errors import InputError, require
from ..units import (QUANTITY_UNITS, check_tolerance_um, convert, match_name,
                     parse_assignments, parse_date, today_utc)
from . import results
from .results import CALIBRATION, CHECK

MACHINE_RULE = re.compile(r"[A-Za-z0-9._:/+#-](?:[A-Za-z0-9 ._:/+#-]{0,62}[A-Za-z0-9._:/+#-])?")


def check_machine(machine: str) -> str:
    """``machine`` when it follows :data:`MACHINE_RULE`, else :class:`InputError`."""
    require(isinstance(machine, str) and MACHINE_RULE.fullmatch(machine) is not None,
            f"--machine {machine!r}: a machine id is 1 to 64 letters, digits, spaces (not at "
            f"either end) and . _ - : / + # (no quotes, no ';')")
    return machine


def check_wait(wait_s: float) -> float:
    """``wait_s`` (seconds to wait for another writer's lock) when within 0 to 3600 s, else
    :class:`InputError`."""
    require(0 <= wait_s <= 3600, f"--wait {wait_s:g}: 0 to 3600 s")
    return wait_s


def added_lines(done: list, machine: str) -> str:
    """What ``volerr history add`` prints: a line per result of :func:`add`'s ``done``
    (its file, kind, layout and date, and whether it was added or stored already)."""
    return "\n".join(f"{entry.source}: {entry.kind} of {entry.layout} on {entry.date} for "
                     f"machine {machine}: {what}" for entry, what in done)


def add(db: str, machine: str, files, date: str | None = None, wait_s: float = 10.0) -> list:
    """Add the result files to ``machine``'s history in ``db`` (module docstring); returns
    ``[(Entry, "added" | "already stored")]``.  Every entry reported ``"added"`` is committed.
    A new SQLite file appears only with its entries committed
    (:func:`volerr.history.store.add_to_new_file`); a failing call removes nothing but its
    own staging folder.  Another writer storing the same result in between (a new file
    created first by another process, a :class:`~volerr.history.store.Conflict`): the files
    are read again and added to what is stored."""
    from .store import Conflict, Store, add_to_new_file

    check_wait(wait_s)
    check_machine(machine)
    files = list(files)
    require(files, "give at least one RESULT.json")
    date = parse_date(date) if date is not None else None
    _read_entries(files, date)              # every file checked before the database is touched

    def work(store):
        entries = _read_entries(files, date)    # fresh: a check's reference is applied in place
        paths = {id(e): f for f, e in entries}
        return store.add(machine, [e for _, e in entries],
                         lambda entry, stored: _prepare(entry, stored, paths[id(entry)]))

    for _ in range(_ATTEMPTS):
        try:
            if "://" not in str(db) and not Path(db).exists():
                made, value = add_to_new_file(db, wait_s, work)
                if made:
                    return value
                continue                        # another process created it: add to that
            return work(Store(db, wait_s=wait_s, create=True))
        except Conflict:
            continue
    raise InputError(f"--db {db}: other processes kept writing the same results at the same "
                     f"time; nothing written, try again")


#: attempts of one add against writers racing for the same new file or the same result
_ATTEMPTS = 4


def _read_entries(files: list, date: str | None) -> list:
    """``[(file, Entry)]`` dated (``date``, else the result's own, else today) and in the
    order they are stored (date, calibrations first)."""
    entries = []
    for f in files:
        e = results.read(f)
        e.date = date or (parse_date(e.date, f"{f}: its date") if e.date else today_utc())
        entries.append((f, e))
    entries.sort(key=lambda fe: (fe[1].date, fe[1].kind != CALIBRATION))
    return entries


def _prepare(entry, stored: list, path) -> None:
    """Inside the store's transaction: the reference of a check applied, the layout and the
    units checked against the machine's stored entries."""
    if entry.kind == CHECK:
        ref = _reference(entry, stored, path)
        results.apply_reference(entry, ref, path)
    layouts = {e.layout for e in stored}
    require(not layouts or layouts == {entry.layout},
            f"{path}: layout {entry.layout}, the machine's history is of "
            f"{', '.join(sorted(layouts))}")
    units = {}
    for e in stored:
        for n, v in e.values.items():
            units.setdefault(n, v.unit)
    for n, v in entry.values.items():
        require(n not in units or units[n] == v.unit,
                f"{path}: {n} in {v.unit}, the history holds it in {units.get(n)}")
    stored.append(entry)


def _reference(entry, stored: list, path):
    if entry.reference_sha256:
        named = [e for e in stored if e.sha256 == entry.reference_sha256]
        require(named, f"{path}: its reference (sha256 {entry.reference_sha256[:12]}...) is "
                       f"not in this machine's history; add it first")
        ref = named[0]
        require(ref.date <= entry.date, f"{path}: dated {entry.date}, before its reference "
                                        f"({ref.source}, {ref.date})")
        return results.as_reference(ref, path)
    before = [e for e in stored if e.kind == CALIBRATION and e.date <= entry.date]
    require(before, f"{path}: a check dated {entry.date}, and no calibration of this machine "
                    f"on or before that date in the history; add the reference first")
    return before[-1]


def parse_tolerances(text: str | None) -> dict:
    """``"EX0C=20 um,EA0C=50 urad,map=30 um"`` -> ``{name: (value, unit)}``: every value with
    its unit (:func:`volerr.units.parse_assignments`, the reading of every ``--tolerance``;
    a bare number is refused, the history holds parameters in different units); ``map``
    (the volumetric error, any case: ``MAP``) a length, in um.  A parameter's name is matched
    to the history's in :meth:`volerr.history.report.History.build` (as written, or in any
    case when that names one: :func:`volerr.units.match_name`)."""
    if not text:
        return {}
    out = {}
    for name, (value, unit) in parse_assignments(text, "--tolerance", any_unit=True):
        if match_name(name, ["map"], "--tolerance") == "map":
            require("map" not in out, f"--tolerance: {name} given twice")
            name = "map"
            require(QUANTITY_UNITS.get(unit, ("",))[0] == "length",
                    "--tolerance map=VALUE um (the volumetric error, a length)")
            value, unit = convert(value, unit, "um"), "um"
        if QUANTITY_UNITS.get(unit, ("",))[0] == "length":     # below any machine's: in mm?
            check_tolerance_um(convert(value, unit, "um"), f"--tolerance {name}={value:g} "
                               f"{unit}", unit, name, ceiling=False)
        out[name] = (value, unit)
    return out


def show(db: str, machine: str, tolerance: str | None = None, wait_s: float = 10.0):
    """The :class:`volerr.history.report.History` of ``machine`` in ``db``."""
    from .report import History
    from .store import Store

    check_wait(wait_s)
    check_machine(machine)
    tol = parse_tolerances(tolerance)
    store = Store(db, wait_s=wait_s, create=False)
    entries = store.entries(machine)
    require(entries, f"--machine {machine!r}: no entries in {store.shown} (machines there: "
                     f"{', '.join(store.machines()[:8]) or 'none'})")
    return History.build(machine, entries, tol)
