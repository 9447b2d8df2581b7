"""What identifies a report (ISO/IEC 17025:2017 7.8.2 asks for it): one
:class:`Identification` shared by every result of volerr, printed as the first table of every
page (:func:`html_table`), of every PDF certificate (:mod:`volerr.report.pdf`) and stored in
the JSON (:meth:`Identification.as_dict`, key ``"identification"``).

Fields (none is required; a missing one shows as "not stated"):

* ``report_id``: unique and stable for the same inputs -- ``VE-`` and 12 hexadecimal digits
  of the SHA-256 of the input files' bytes, the command's options and the identification
  fields (:func:`report_id`); the date of the report does not enter it;
* the machine (text of ``--machine``, or ``[machine]`` of the file: id, make, model, serial,
  location), the instruments (``--instrument`` text, or ``[[instrument]]`` tables: id,
  description, serial, certificate, due (date the calibration expires), uncertainty),
  operator, customer, the person authorising the report;
* ``date``: the date of the measurement (YYYY-MM-DD; not in the future); ``report_date``: the
  date of the report (today, UTC);
* ``method``: the command, volerr's version and the options;
* ``environment``: temperatures with their uncertainty and expansion coefficients, as the
  user states them (label -> text), and ``conditions``: further labelled lines a command adds.

The identification file (:func:`read_identification_file`): a small TOML file the user keeps
beside the data, given by ``--identification F``; without that option a file named
:data:`IDENTIFICATION_FILE` in the folder of the first data file is read when it is there.
Options given on the command line replace the file's fields.  Its keys::

    operator = "A. Person"
    customer = "ACME Precision Ltd"
    authorised_by = "B. Person, head of the laboratory"
    date = 2026-11-30                 # the date of the measurement
    [machine]
    id = "DMU50-2"; make = "DMG MORI"; model = "DMU 50"; serial = "1234"; location = "hall 3"
    [[instrument]]
    id = "XL-80"; description = "laser interferometer"; serial = "9876"
    certificate = "UKAS 0042/26"; due = 2027-06-30; uncertainty = "0.5 ppm (k = 2)"
    [environment]
    "machine temperature" = "20.4 degC +- 0.2 K (k = 2)"
    "expansion coefficient" = "11.5 ppm/K +- 1 ppm/K"
    [conditions]                      # test conditions the data cannot tell
    feed = "1000 mm/min"; compensation = "on (controller tables of 2026-03)"

A due date before the date of the measurement is a warning on the page, never a refusal.
"""

from __future__ import annotations

import datetime
import hashlib
import html
import json
from dataclasses import dataclass, field
from pathlib import Path

from .errors import InputError, require, require_file

NOT_STATED = "not stated"
#: the identification file read automatically from the folder of the first data file
IDENTIFICATION_FILE = "volerr-identification.toml"
MACHINE_KEYS = ("id", "make", "model", "serial", "location")
INSTRUMENT_KEYS = ("id", "description", "serial", "certificate", "due", "uncertainty")
TOP_KEYS = ("operator", "customer", "authorised_by", "date", "machine", "instrument",
            "environment", "conditions")


def today() -> str:
    """Today's date (UTC), YYYY-MM-DD (:func:`volerr.units.today_utc`)."""
    from .units import today_utc

    return today_utc()


def check_date(value, where: str, future: bool = False) -> str:
    """``value`` (a :class:`datetime.date` or YYYY-MM-DD text) as YYYY-MM-DD
    (:func:`volerr.units.parse_date`: one-line :class:`InputError` naming ``where`` when
    malformed, or after today unless ``future``)."""
    from .units import parse_date

    if isinstance(value, datetime.datetime):
        value = value.date()
    if isinstance(value, datetime.date):
        value = value.isoformat()
    return parse_date(value, where, future=future)


@dataclass
class Identification:
    """Identification of one report (module docstring).  ``conditions``: further labelled
    lines a command adds (temperatures, expansion coefficient ...), in order."""

    machine: str | None = None
    instrument: str | None = None
    operator: str | None = None
    date: str = field(default_factory=today)
    conditions: dict = field(default_factory=dict)
    report_id: str | None = None
    report_date: str = field(default_factory=today)
    customer: str | None = None
    authorised_by: str | None = None
    machine_details: dict = field(default_factory=dict)
    instruments: list = field(default_factory=list)
    method: dict = field(default_factory=dict)
    environment: dict = field(default_factory=dict)
    warnings: list = field(default_factory=list)
    test_conditions: dict = field(default_factory=dict)
    #: whether the user stated any field (options or the identification file); a JSON
    #: document is stamped only then, so a run without one writes the API's JSON unchanged
    stated: bool = False

    def as_dict(self) -> dict:
        """The JSON form (``"date"``: the date of the measurement)."""
        out = {"report_id": self.report_id, "machine": self.machine,
               "instrument": self.instrument, "operator": self.operator, "date": self.date,
               "report_date": self.report_date, "customer": self.customer,
               "authorised_by": self.authorised_by}
        if self.machine_details:
            out["machine_details"] = dict(self.machine_details)
        if self.instruments:
            out["instruments"] = [dict(i) for i in self.instruments]
        for key in ("method", "environment", "test_conditions"):
            if getattr(self, key):
                out[key] = dict(getattr(self, key))
        if self.warnings:
            out["warnings"] = list(self.warnings)
        return {**out, **self.conditions}

    def rows(self) -> list:
        """(label, text) of every field, "not stated" where missing."""
        machine = self.machine or _joined(self.machine_details, MACHINE_KEYS)
        rows = [("report id", self.report_id), ("customer", self.customer),
                ("machine", machine)]
        n = len(self.instruments) + bool(self.instrument)
        if self.instrument or not self.instruments:     # the option's text first
            rows.append(("instrument 1" if n > 1 else "instrument", self.instrument))
        rows += [(f"instrument {i + 1 + bool(self.instrument)}" if n > 1 else "instrument",
                  _instrument_text(d)) for i, d in enumerate(self.instruments)]
        rows += [("operator", self.operator), ("date of the measurement", self.date),
                 ("date of the report", self.report_date)]
        if self.method:
            rows.append(("method", _method_text(self.method)))
        rows += list(self.environment.items()) + list(self.conditions.items())
        rows.append(("authorised by", self.authorised_by))
        return [(k, NOT_STATED if v in (None, "") else str(v)) for k, v in rows]


def _joined(d: dict, keys) -> str | None:
    parts = [f"{k} {d[k]}" if k in ("id", "serial") else str(d[k]) for k in keys if d.get(k)]
    return ", ".join(parts) or None


def _instrument_text(d: dict) -> str:
    parts = [str(d[k]) for k in ("description", "id") if d.get(k)]
    for key, label in (("serial", "serial"), ("certificate", "calibration certificate"),
                       ("due", "due"), ("uncertainty", "stated uncertainty")):
        if d.get(key):
            parts.append(f"{label} {d[key]}")
    return ", ".join(parts)


def _option_text(v) -> str:
    """An option's value as typed (lists and vectors space-separated, a flag alone)."""
    if v is True:
        return ""
    if isinstance(v, (list, tuple)):
        return " ".join(_option_text(x) for x in v)
    return str(v)


def _method_text(m: dict) -> str:
    opts = " ".join(f"--{k.replace('_', '-')} {_option_text(v)}".strip()
                    for k, v in (m.get("options") or {}).items())
    return f"{m.get('command', 'volerr')} (volerr {m.get('version', '?')}) {opts}".strip()


def read_identification_file(path) -> dict:
    """The fields of an identification file (module docstring), checked: unknown keys,
    malformed dates and a date of measurement in the future are refused in one line naming
    the file and the key."""
    import tomllib

    p = Path(path)
    try:
        doc = tomllib.loads(p.read_text(encoding="utf-8"))
    except OSError as exc:
        raise InputError(f"--identification {p}: cannot be read ({exc.strerror})") from None
    except (tomllib.TOMLDecodeError, UnicodeDecodeError) as exc:
        raise InputError(f"{p}: not valid TOML ({_where(p, exc)}; dates are written "
                         f"YYYY-MM-DD, texts in quotes)") from None
    _known(p, "", doc, TOP_KEYS)
    out = {k: str(doc[k]) for k in ("operator", "customer", "authorised_by") if k in doc}
    if "date" in doc:
        out["date"] = check_date(doc["date"], f"{p}: date")
    if "machine" in doc:
        require(isinstance(doc["machine"], dict), f"{p}: machine must be a table "
                                                  f"[machine] with id, make, model ...")
        _known(p, "machine.", doc["machine"], MACHINE_KEYS)
        out["machine_details"] = {k: str(v) for k, v in doc["machine"].items()}
    items = doc.get("instrument", [])
    items = [items] if isinstance(items, dict) else items
    require(isinstance(items, list) and all(isinstance(i, dict) for i in items),
            f"{p}: instrument must be [[instrument]] tables with id, serial, certificate ...")
    out["instruments"] = []
    for i, item in enumerate(items):
        _known(p, f"instrument[{i + 1}].", item, INSTRUMENT_KEYS)
        d = {k: str(v) for k, v in item.items()}
        if "due" in item:
            d["due"] = check_date(item["due"], f"{p}: instrument[{i + 1}].due", future=True)
        out["instruments"].append(d)
    env = doc.get("environment", {})
    require(isinstance(env, dict), f"{p}: environment must be a table [environment] of "
                                   f"label = \"text\" lines")
    out["environment"] = {str(k): str(v) for k, v in env.items()}
    cond = doc.get("conditions", {})
    require(isinstance(cond, dict), f"{p}: conditions must be a table [conditions] of "
                                    f"label = \"text\" lines (feed, compensation ...)")
    out["test_conditions"] = {str(k): str(v) for k, v in cond.items()}
    return out


def _where(p: Path, exc) -> str:
    """The TOML error and the line it points at (``at line N, column M``)."""
    import re

    msg = str(exc).splitlines()[0]
    m = re.search(r"line (\d+)", msg)
    if m is None:
        return msg
    lines = p.read_text(encoding="utf-8", errors="replace").splitlines()
    n = int(m.group(1))
    return f"{msg}: {lines[n - 1].strip()!r}" if 0 < n <= len(lines) else msg


def _known(p: Path, prefix: str, d: dict, keys) -> None:
    bad = sorted(set(d) - set(keys))
    require(not bad, f"{p}: unknown key {prefix}{bad[0] if bad else ''} (known: "
                     f"{', '.join(keys)}); a misspelt key?")


def find_identification_file(explicit, files) -> Path | None:
    """The identification file: ``explicit`` (``--identification``), else
    :data:`IDENTIFICATION_FILE` beside the first data file of ``files`` when it is there."""
    if explicit:
        require_file(explicit, f"--identification {explicit}: no such file",
                     f"--identification {explicit}")
        return Path(explicit)
    for f in files:
        if Path(str(f)).is_file():
            candidate = Path(str(f)).parent / IDENTIFICATION_FILE
            return candidate if candidate.is_file() else None
    return None


def report_id(files=(), options: dict | None = None) -> str:
    """``VE-`` and 12 hexadecimal digits of the SHA-256 of the files' bytes (in order) and the
    options (JSON, keys sorted): the same inputs and options give the same id."""
    h = hashlib.sha256()
    for f in files:
        p = Path(str(f))
        h.update(p.name.encode())
        if p.is_file():
            h.update(hashlib.sha256(p.read_bytes()).digest())
    h.update(json.dumps(options or {}, sort_keys=True, default=str).encode())
    return "VE-" + h.hexdigest()[:12].upper()


def method_options(values: dict, files=(), skip=()) -> dict:
    """The options of a run that state its method (the report's ``method.options``): of
    ``values`` (option -> value, as a command's arguments), those given (not None, False or
    ``[]``), not private (``_...``), not in ``skip`` (outputs, the identification's own
    fields), not callable and not an input file of ``files`` (hashed into the report id
    instead; also as ``KIND:FILE``, or a list of them); paths as text."""
    paths = {str(f) for f in files}

    def is_input(v) -> bool:
        return str(v) in paths or str(v).split(":", 1)[-1] in paths

    options = {k: (str(v) if isinstance(v, Path) else v) for k, v in sorted(values.items())
               if not k.startswith("_") and k not in skip and v not in (None, False, [])
               and not is_input(v) and not callable(v)}
    return {k: v for k, v in options.items()
            if not (isinstance(v, list) and all(is_input(x) for x in v))}


def build(given: dict, file=None, files=(), method: dict | None = None,
          conditions: dict | None = None) -> Identification:
    """One :class:`Identification` from the file's fields (:func:`read_identification_file`)
    and the options ``given`` (``machine instrument operator date customer``; not None
    replaces the file's), with its :func:`report_id`, the method and the due-date warnings."""
    fields = read_identification_file(file) if file is not None else {}
    for key, value in given.items():
        if value not in (None, ""):
            fields[key] = check_date(value, "--date") if key == "date" else str(value)
    method = dict(method or {})
    hashed = {"method": method, **{k: v for k, v in fields.items()}}
    ident = Identification(conditions=dict(conditions or {}), method=method,
                           report_id=report_id(files, hashed), stated=bool(fields), **fields)
    for i, d in enumerate(ident.instruments):
        if d.get("due") and d["due"] < ident.date:
            ident.warnings.append(
                f"instrument {d.get('id') or i + 1}: calibration due {d['due']}, before the "
                f"date of the measurement {ident.date}")
    return ident


#: a run's options that name outputs or switches of writing, not its method (the report id)
NOT_METHOD = frozenset({"json", "html", "pdf", "plot", "errors_out", "map_out", "out", "force",
                        "func", "command", "action", "identification", "date"})
#: the fields an option may state (``--machine`` ...), in the order of the options
FIELD_OPTIONS = ("machine", "instrument", "operator", "date", "customer")


def from_options(options: dict, files=(), conditions: dict | None = None) -> Identification:
    """The :class:`Identification` of a run from its options as a plain dict (a command's
    arguments): the fields ``machine instrument operator customer`` where ``_ident_own``
    names them (a command whose option of that name means something else: the field comes
    from the file), ``date`` (YYYY-MM-DD), the file ``identification`` (else
    :data:`IDENTIFICATION_FILE` beside ``files[0]``); the method: ``_ident_prog`` (the
    command), ``_ident_version`` (volerr's version) and the options that state the method
    (:func:`method_options`).
    ``files``: the run's inputs (the report id hashes them); ``conditions``: labelled test
    conditions (e.g. the correction to 20 degC)."""
    own = set(options.get("_ident_own", ())) | {"date"}
    given = {k: options.get(k) for k in FIELD_OPTIONS if k in own}
    method = {"command": options.get("_ident_prog", "volerr"),
              "version": options.get("_ident_version", ""),
              "options": method_options(options, files, NOT_METHOD | own)}
    file = find_identification_file(options.get("identification"), list(files))
    return build(given, file, list(files), method, conditions)


def html_table(ident: Identification) -> str:
    """The identification block of a report page (HTML table, then its warnings)."""
    e = html.escape
    warn = "".join(f"<p class='warn'>warning: {e(w)}</p>" for w in ident.warnings)
    return ("<table class='ident'>" + "".join(
        f"<tr><th class='l'>{e(k)}</th><td class='l'>{e(v)}</td></tr>" for k, v in ident.rows())
        + "</table>" + warn)


def verdict_html(verdict: str | None) -> str:
    """A verdict as a coloured word (pass green, fail red, undecided amber)."""
    if verdict is None:
        return "no tolerance given"
    colour = {"pass": "#1a7f37", "fail": "#c62828", "undecided": "#b26a00"}[verdict]
    return f"<b style='color:{colour}'>{html.escape(verdict.upper())}</b>"
