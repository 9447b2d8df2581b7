"""A command's bare JSON document as a result for its certificate (:mod:`volerr.report.stamp`):
``map``, ``compensate``, ``iso10360`` ... write a document, ``check`` a result without rows."""

from __future__ import annotations


class Document:
    """``result`` (a JSON document, or a result without rows) with what a certificate reads:
    ``to_dict()`` the document, ``_rows()`` the rows of its ``"parameters"``
    (``{name: {"value", "std", "unit"}}``) and ``figures()`` the result's figures."""

    def __init__(self, result):
        self.result = result
        self.data = result if isinstance(result, dict) else result.to_dict()

    def to_dict(self) -> dict:
        return self.data

    def figures(self) -> dict:
        return {} if isinstance(self.result, dict) or not hasattr(self.result, "figures") \
            else self.result.figures()

    def _rows(self) -> list:
        from ..results import rows_of

        return rows_of(self.data.get("parameters"))
