"""A result file (``volerr calibrate --json`` or ``volerr check --json``) as one history entry.

What an entry keeps of its result (:class:`Entry`):

* ``kind``: ``calibration`` (a JSON with ``"parameters": {NAME: {"value", "unit", "std"}}``)
  or ``check`` (a JSON with ``"verdict"`` and ``"changed": [{"parameter", "change", "unit",
  "std"}]``);
* ``values``: ``{NAME: Value(value, std, unit, status)}`` in the result's report units (um,
  urad, um/mm ...).  A calibration's values are its estimates (status ``estimated``).  A
  check states changes against its reference calibration; its values are the reference's
  value plus the change (status ``changed``), so every entry of a parameter lies on one
  scale.  A combination a calibration determines (``combinations``: ``EY0B + EY0C`` written
  as ``EY0B``) is kept under its ``written_as`` name (status ``combination``), as a check
  names it.  A parameter the check lists as ``unchanged`` with a number (``{"parameter",
  "change", "std"}``, or by name with ``change`` and ``change_std`` in the check's
  ``parameters`` block: the change the check measures with it free, below its threshold, and
  the uncertainty of "no change") is stored the same way (status ``unchanged``); a
  combination the check lists with status ``unchanged`` likewise; one listed by name only
  without a number carries none (value and std ``None``) and is left out of every statistic;
* a check's values also keep ``common``: the part of their ``std`` the reference's
  covariance gives (the check's budget source ``reference ... (its covariance)``), which
  every check on that reference shares (:func:`volerr.history.analysis.entry_covariance`);
* ``covariance``: ``{"names": [...], "matrix": [[...]]}`` when the result carries one (in the
  report units of the names), else ``None``;
* ``files``: the instrument files the result names, each with the SHA-256 of the file found
  beside the result (its path as written, relative to the result's folder), or ``None``
  when it is not there;
* ``sha256``: of the result file's bytes (the identity of a result in the store).
"""

from __future__ import annotations

import hashlib
import json
import math
from dataclasses import dataclass, field, replace
from pathlib import Path

from ..errors import InputError, require

CALIBRATION, CHECK = "calibration", "check"
ESTIMATED, CHANGED, UNCHANGED = "estimated", "changed", "unchanged"
COMBINATION = "combination"


@dataclass(frozen=True)
class Value:
    """One parameter of one entry: ``value`` and standard uncertainty ``std`` (k = 1) in
    ``unit``; both ``None`` for a parameter a check names as unchanged without a number."""
    value: float | None
    std: float | None
    unit: str
    status: str
    change: float | None = None     # a check's stated change (None for a calibration)
    common: float | None = None     # the part of ``std`` its reference shares (a check's)


@dataclass
class Entry:
    """One result in a machine's history (module docstring)."""
    kind: str
    layout: str
    values: dict
    sha256: str
    source: str
    document: str
    date: str | None = None
    verdict: str | None = None
    covariance: dict | None = None
    files: list = field(default_factory=list)
    reference_sha256: str | None = None


def read(path) -> Entry:
    """The entry of the result file ``path`` (its reference not yet applied for a check:
    :func:`apply_reference`).  Raises :class:`InputError` for a file that is not a volerr
    calibrate or check result."""
    p = Path(path)
    try:
        raw = p.read_bytes()
    except OSError as exc:
        raise InputError(f"{path}: cannot read ({exc.strerror or exc})") from None
    try:
        doc = json.loads(raw.decode("utf-8"))
    except (UnicodeDecodeError, json.JSONDecodeError) as exc:
        raise InputError(f"{path}: not a JSON file ({exc})".split("\n")[0]) from None
    require(isinstance(doc, dict), f"{path}: not a volerr calibrate or check result (a JSON "
                                   f"object expected)")
    sha = hashlib.sha256(raw).hexdigest()
    text = raw.decode("utf-8")
    if "verdict" in doc and "changed" in doc:
        entry = _check(doc, path, sha, text)
    elif isinstance(doc.get("parameters"), dict) and "layout" in doc:
        entry = _calibration(doc, path, sha, text)
    else:
        raise InputError(f"{path}: not a volerr calibrate or check result (neither "
                         f"'parameters' with 'layout' nor 'verdict' with 'changed')")
    entry.files = _file_hashes(doc, p)
    entry.date = _own_date(doc, path)
    return entry


def _number(v, where: str) -> float:
    require(isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v),
            f"{where}: a finite number expected, got {v!r}")
    return float(v)


def _calibration(doc: dict, path, sha: str, text: str) -> Entry:
    require(isinstance(doc["layout"], str) and doc["layout"],
            f"{path}: 'layout' must be a layout name")
    values = {}
    for name, rec in doc["parameters"].items():
        where = f"{path}: parameter {name}"
        require(isinstance(rec, dict) and "value" in rec and "std" in rec,
                f"{where}: {{'value', 'unit', 'std'}} expected")
        std = _number(rec["std"], f"{where} std")
        require(std >= 0, f"{where}: std must be >= 0, got {std}")
        values[str(name)] = Value(_number(rec["value"], f"{where} value"), std,
                                  str(rec.get("unit", "")), ESTIMATED)
    cov = _covariance(doc.get("covariance"), values, path)
    from_cov = _covariance_values(doc.get("covariance"), cov, path)
    for c in doc.get("combinations", []) or []:
        # a combination the campaign determines (EY0B + EY0C), under the name it is written
        # as: a later check states its change under that name
        if not (isinstance(c, dict) and isinstance(c.get("written_as"), str)) \
                or c["written_as"] in values:
            continue
        name = c["written_as"]
        where = f"{path}: combination {c.get('expression', name)}"
        if name in from_cov and (c.get("value") is None or c.get("std") is None):
            values[name] = Value(from_cov[name].value, from_cov[name].std,
                                 str(c.get("unit") or from_cov[name].unit), COMBINATION)
            continue
        std = _number(c.get("std"), f"{where} std")
        values[name] = Value(_number(c.get("value"), f"{where} value"), std,
                             str(c.get("unit", "")), COMBINATION)
    for name, v in from_cov.items():
        # a name the covariance block holds beside 'parameters' (a combination's carrier,
        # EY0B for EY0B + EY0C, when 'combinations' does not state it)
        values.setdefault(name, v)
    require(values, f"{path}: the calibration determined no parameter")
    return Entry(CALIBRATION, doc["layout"], values, sha, Path(path).name, text,
                 covariance=cov)


def _covariance_values(raw, cov: dict | None, path) -> dict:
    """``{NAME: Value}`` of the covariance block's names with a value: ``values[i]`` and
    ``sqrt(matrix[i][i])`` in ``units[i]`` (status ``combination``: a name calibrate writes
    there and not under ``parameters`` is a combination's carrier)."""
    if cov is None or not isinstance(raw.get("values"), list) \
            or len(raw["values"]) != len(cov["names"]):
        return {}
    units = raw.get("units") if isinstance(raw.get("units"), list) \
        and len(raw["units"]) == len(cov["names"]) else [""] * len(cov["names"])
    out = {}
    for i, name in enumerate(cov["names"]):
        var = cov["matrix"][i][i]
        require(var >= 0, f"{path}: covariance of {name}: a negative variance {var}")
        out[name] = Value(_number(raw["values"][i], f"{path}: covariance value of {name}"),
                          math.sqrt(var), str(units[i]), COMBINATION)
    return out


def _covariance(cov, values: dict, path) -> dict | None:
    """``{"names", "matrix"}`` checked (square, symmetric, names known), or None."""
    if cov is None:
        return None
    require(isinstance(cov, dict) and isinstance(cov.get("names"), list)
            and isinstance(cov.get("matrix"), list),
            f"{path}: 'covariance' must be {{'names': [...], 'matrix': [[...]]}}")
    names = [str(n) for n in cov["names"]]
    m = cov["matrix"]
    require(len(m) == len(names) and all(isinstance(r, list) and len(r) == len(names)
                                         for r in m),
            f"{path}: 'covariance' matrix is not {len(names)} x {len(names)}")
    rows = [[_number(v, f"{path}: covariance") for v in r] for r in m]
    return {"names": names, "matrix": rows}


def _check(doc: dict, path, sha: str, text: str) -> Entry:
    verdict = doc["verdict"]
    require(verdict in (CHANGED, UNCHANGED),
            f"{path}: 'verdict' must be 'changed' or 'unchanged', got {verdict!r}")
    require(isinstance(doc["changed"], list) and isinstance(doc.get("unchanged", []), list),
            f"{path}: 'changed' and 'unchanged' must be lists")
    values = {}
    measured = _measured(doc, path)
    unchanged = list(doc.get("unchanged", [])) + [
        c["written_as"] for c in doc.get("combinations", []) or []
        if isinstance(c, dict) and c.get("status") == UNCHANGED
        and isinstance(c.get("written_as"), str)]
    for status, items in ((CHANGED, doc["changed"]), (UNCHANGED, unchanged)):
        for item in items:
            if isinstance(item, str):
                require(status == UNCHANGED, f"{path}: a changed parameter needs "
                                             f"{{'parameter', 'change', 'unit', 'std'}}")
                values[item] = measured.get(item) or Value(None, None, "", status)
                continue
            require(isinstance(item, dict) and "parameter" in item,
                    f"{path}: {status}: {{'parameter', 'change', 'unit', 'std'}} expected")
            name = str(item["parameter"])
            if "change" not in item:
                values[name] = Value(None, None, str(item.get("unit", "")), status)
                continue
            where = f"{path}: {status} {name}"
            std = _number(item.get("std"), f"{where} std")
            require(std >= 0, f"{where}: std must be >= 0, got {std}")
            values[name] = Value(None, std, str(item.get("unit", "")), status,
                                 _number(item["change"], f"{where} change"))
    values = with_reference_parts(values, doc)
    layout = doc.get("layout")
    require(layout is None or (isinstance(layout, str) and layout),
            f"{path}: 'layout' must be a layout name")
    ref = doc.get("reference")
    ref_sha = doc.get("reference_sha256") or (ref.get("sha256") if isinstance(ref, dict)
                                              else None)
    return Entry(CHECK, layout or "", values, sha, Path(path).name, text, verdict=verdict,
                 reference_sha256=ref_sha)


#: the largest share of a check's variance its reference may hold in the history's trend
#: (the rest is the check's own readings; 1 would leave two checks of one reference with a
#: singular covariance)
MAX_COMMON_SHARE = 0.99


def with_reference_parts(values: dict, doc: dict) -> dict:
    """``values`` of the check JSON ``doc`` (also as the store keeps them) with their
    :attr:`Value.common` (:func:`_with_common`)."""
    budgets = doc.get("budgets") if isinstance(doc, dict) else None
    return {n: _with_common(v, budgets, n) for n, v in values.items()}


def _with_common(v: Value, budgets, name: str) -> Value:
    """``v`` with ``common``: the standard uncertainty its check states for the reference's
    covariance propagated (the budget's source ``reference ... (its covariance)``,
    :meth:`volerr.check._result.CheckResult.budgets`), at most ``sqrt(MAX_COMMON_SHARE)``
    of ``std``; None without a number or a budget (an older check JSON).  Every check on
    one reference carries the same reference error: :func:`volerr.history.analysis.trend`
    correlates this part among them."""
    rec = budgets.get(name) if isinstance(budgets, dict) else None
    srcs = rec.get("sources") if isinstance(rec, dict) else None
    u = next((x.get("u") for x in srcs or [] if isinstance(x, dict)
              and str(x.get("source", "")).startswith("reference")), None)
    if v.std is None or not isinstance(u, (int, float)) or not math.isfinite(u) or u <= 0:
        return v
    return replace(v, common=min(float(u), math.sqrt(MAX_COMMON_SHARE) * v.std))


def _measured(doc: dict, path) -> dict:
    """``{NAME: Value}`` of the parameters a check calls unchanged and measures: its
    ``parameters`` block's ``change`` and ``change_std`` (the change the check measures with
    the parameter free, below its threshold, and the uncertainty of "no change"); a check
    JSON without them (an older one) gives ``{}``."""
    params = doc.get("parameters")
    out = {}
    if not isinstance(params, dict):
        return out
    for name, rec in params.items():
        if not (isinstance(rec, dict) and rec.get("status") == UNCHANGED
                and rec.get("change") is not None and rec.get("change_std") is not None):
            continue
        where = f"{path}: parameters {name}"
        std = _number(rec["change_std"], f"{where} change_std")
        require(std >= 0, f"{where}: change_std must be >= 0, got {std}")
        out[str(name)] = Value(None, std, str(rec.get("unit", "")), UNCHANGED,
                               _number(rec["change"], f"{where} change"))
    return out


def apply_reference(entry: Entry, reference: Entry, path) -> None:
    """A check's values: the reference's value plus the stated change (same unit), in place.
    Raises :class:`InputError` when the check names a parameter the reference does not hold,
    or another layout or unit."""
    require(not entry.layout or entry.layout == reference.layout,
            f"{path}: a check of layout {entry.layout}, its reference calibration "
            f"({reference.source}, {reference.date}) is of {reference.layout}")
    entry.layout = reference.layout
    entry.reference_sha256 = reference.sha256
    out = {}
    for name, v in entry.values.items():
        ref = reference.values.get(name)
        if ref is None and v.change is None:
            continue                # named unchanged, no number: nothing to keep
        require(ref is not None, f"{path}: the check names {name}, which its reference "
                                 f"calibration ({reference.source}) does not determine")
        require(not v.unit or v.unit == ref.unit,
                f"{path}: {name} in {v.unit}, its reference in {ref.unit}")
        if v.change is None:
            out[name] = Value(None, None, ref.unit, v.status)
        else:
            out[name] = Value(ref.value + v.change, v.std, ref.unit, v.status, v.change,
                              v.common)
    entry.values = out


def _file_hashes(doc: dict, path: Path) -> list:
    """``[{"file", "sha256"}]`` of the instrument files the result names (its
    ``instruments`` or ``files`` list): the SHA-256 the result states, else that of the file
    found beside the result (its path as written, relative to the result's folder), else
    ``None``."""
    named: dict = {}
    for key in ("instruments", "files"):
        for item in doc.get(key, []) or []:
            if isinstance(item, str):
                named.setdefault(item, None)
            elif isinstance(item, dict) and isinstance(item.get("file"), str):
                sha = item.get("sha256")
                named[item["file"]] = sha if isinstance(sha, str) else named.get(item["file"])
    out = []
    for name, digest in named.items():
        if digest is None:
            f = Path(name) if Path(name).is_absolute() else path.parent / name
            try:
                digest = hashlib.sha256(f.read_bytes()).hexdigest() if f.is_file() else None
            except OSError:
                digest = None
        out.append({"file": name, "sha256": digest})
    return out


def as_reference(entry: Entry, path) -> Entry:
    """The values a later check's changes are relative to: a calibration's own; a check's
    ``parameters`` (the reference updated by the check, as ``volerr check`` writes them)."""
    if entry.kind == CALIBRATION:
        return entry
    import json as _json

    doc = _json.loads(entry.document)
    params = doc.get("parameters")
    require(isinstance(params, dict) and params,
            f"{path}: its reference is the check {entry.source}, which states no parameter "
            f"values")
    ref = _calibration({"layout": entry.layout, "parameters": params}, entry.source,
                       entry.sha256, entry.document)
    ref.date = entry.date
    return ref


def _own_date(doc: dict, path) -> str | None:
    """The result's own date: the date of the measurement in its identification
    (``identification.date``), else ``"date"``, when it states one."""
    for d in ((doc.get("identification") or {}).get("date")
              if isinstance(doc.get("identification"), dict) else None, doc.get("date")):
        if isinstance(d, str) and d:
            return d
    return None
