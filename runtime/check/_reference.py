"""The reference of a check: a calibration (``volerr calibrate --json``) or an earlier check
(``volerr check --json``), read from its ``covariance`` block (values and covariance of the
written parameters in their report units, the series degree and the measured ranges their
terms refer to; ``volerr formats check``).

Units: report units (um, urad, um/mm ...) in the file; :meth:`Reference.factors` turns them
into the model's natural units (mm, rad): ``natural = report / factor``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from ..calibrate import terms
from ..errors import InputError, require
from ..estimate.design import parameter_labels


@dataclass
class Reference:
    """A reference calibration: ``names`` [report name], ``units``, ``values`` (p,) and
    ``cov`` (p, p) in report units, ``degree`` and ``ranges`` {axis: (lo, hi)} (mm, deg) of
    the series terms, ``layout`` the layout's name, ``path`` the file, ``data`` the whole
    JSON."""

    layout: str
    names: list
    units: list
    values: np.ndarray
    cov: np.ndarray
    degree: int
    ranges: dict
    path: str = ""
    data: dict = field(default_factory=dict)

    @property
    def combinations(self) -> dict:
        """``{written_as: expression}``: the names that carry a combination the reference
        determines only as a whole (``EY0B`` holding ``EY0B + EY0C``)."""
        out = {}
        for c in self.data.get("combinations", []) or []:
            if isinstance(c, dict) and c.get("written_as") in self.names:
                out[str(c["written_as"])] = str(c.get("expression", c["written_as"]))
        return out

    @property
    def std(self) -> np.ndarray:
        return np.sqrt(np.maximum(np.diag(self.cov), 0.0))

    def labels(self, model) -> list:
        """The design label ``(parameter, k)`` of each name, in the order of :attr:`names`
        (InputError naming a name the layout does not have)."""
        name_of = terms.namer(model, self.ranges)
        by_name = {name_of(lab): lab for lab in parameter_labels(model, self.degree)}
        out = []
        for n in self.names:
            require(n in by_name, f"--reference {self.path}: {n!r} is not a parameter of "
                                  f"layout {model.name} at degree {self.degree}")
            out.append(by_name[n])
        return out

    def factors(self, model) -> np.ndarray:
        """(p,) report value per natural unit of each parameter (1e3 um/mm, 1e6 urad/rad,
        slopes per mm or deg of the reference's ranges)."""
        return np.array([terms.report(lab, 1.0, 0.0, model, self.ranges)["value"]
                         for lab in self.labels(model)], float)


def load(path, model) -> Reference:
    """The reference in ``path`` for ``model`` (one-line InputError: not JSON, not a
    calibration or check of this layout, no covariance)."""
    from ..fit_quality import read_result_json

    doc = read_result_json(path, model.name)
    block = doc.get("covariance")
    require(isinstance(block, dict), f"--reference {path}: holds no covariance (calibrate it "
                                     f"again with this volerr: its JSON has the 'covariance' "
                                     f"block a check needs)")
    return _parse(block, doc, str(path), model)


def _parse(block: dict, doc: dict, path: str, model) -> Reference:
    try:
        names = [str(n) for n in block["names"]]
        units = [str(u) for u in block["units"]]
        values = np.array(block["values"], float)
        cov = np.array(block["matrix"], float).reshape(len(names), len(names))
        degree = int(block["degree"])
        ranges = {a: (float(v[0]), float(v[1])) for a, v in block["ranges"].items()}
    except (KeyError, TypeError, ValueError):
        raise InputError(f"--reference {path}: a malformed 'covariance' block (names, "
                         f"units, values, matrix, degree, ranges)") from None
    p = len(names)
    require(p > 0, f"--reference {path}: determines no parameter (nothing to check against)")
    require(len(units) == p and values.shape == (p,) and len(set(names)) == p,
            f"--reference {path}: the 'covariance' block's lists differ in length")
    require(bool(np.all(np.isfinite(values))) and bool(np.all(np.isfinite(cov))),
            f"--reference {path}: the covariance holds a number that is not finite")
    require(set(ranges) == set(model.axes), f"--reference {path}: its ranges name the axes "
                                            f"{', '.join(sorted(ranges))}, not {model.name}'s")
    cov = 0.5 * (cov + cov.T)
    d = np.sqrt(np.maximum(np.diag(cov), 0.0))
    require(bool(np.all(d > 0)) and float(np.linalg.eigvalsh(cov / np.outer(d, d))[0]) > -1e-9,
            f"--reference {path}: its covariance is not positive definite")
    require(1 <= degree <= 12 and all(math.isfinite(lo) and math.isfinite(hi) and hi >= lo
                                      for lo, hi in ranges.values()),
            f"--reference {path}: a malformed degree or range")
    return Reference(doc["layout"], names, units, values, cov, degree, ranges, path, doc)
