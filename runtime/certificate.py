"""What identifies a test certificate (ISO/IEC 17025 7.8 asks for it): the machine, the
instrument, the operator, the date, the temperatures and expansion coefficients -- one
:class:`Identification` shared by every certificate of volerr (``iso230-2``, ``iso10360``),
printed as the first table of the page (:func:`html_table`) and stored in the JSON
(:meth:`Identification.as_dict`).  Values are the user's text; none is required, a missing
one shows as "not stated"."""

from __future__ import annotations

import datetime
import html
from dataclasses import dataclass, field

NOT_STATED = "not stated"


@dataclass
class Identification:
    """Identification fields of one certificate.  ``conditions``: further labelled lines
    (temperatures, expansion coefficient ...), in order."""

    machine: str | None = None
    instrument: str | None = None
    operator: str | None = None
    date: str = field(default_factory=lambda: datetime.date.today().isoformat())
    conditions: dict = field(default_factory=dict)

    def as_dict(self) -> dict:
        return {"machine": self.machine, "instrument": self.instrument,
                "operator": self.operator, "date": self.date, **self.conditions}

    def rows(self) -> list:
        """(label, text) of every field, "not stated" where missing."""
        rows = [("machine", self.machine), ("instrument", self.instrument),
                ("operator", self.operator), ("date of the test", self.date)]
        rows += list(self.conditions.items())
        return [(k, NOT_STATED if v in (None, "") else str(v)) for k, v in rows]


def html_table(ident: Identification) -> str:
    """The identification block of a certificate page (HTML table)."""
    e = html.escape
    return ("<table class='ident'>" + "".join(
        f"<tr><th class='l'>{e(k)}</th><td class='l'>{e(v)}</td></tr>" for k, v in ident.rows())
        + "</table>")


def verdict_html(verdict: str | None) -> str:
    """A verdict as a coloured word (pass green, fail red, undecided amber)."""
    if verdict is None:
        return "no tolerance given"
    colour = {"pass": "#1a7f37", "fail": "#c62828", "undecided": "#b26a00"}[verdict]
    return f"<b style='color:{colour}'>{html.escape(verdict.upper())}</b>"
