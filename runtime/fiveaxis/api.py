"""``volerr.compensate(...)``: the Python API of ``volerr compensate`` (:mod:`volerr.results`)."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from ..errors import require
from ..results import ResultMixin


@dataclass(repr=False)
class Compensation(ResultMixin):
    """Result of :func:`compensate`: ``text`` the compensated program, ``data`` the
    ``--json`` summary (predicted tool-tip error before / after in um, the tool axis in urad),
    ``blocks`` the per-block reports."""

    text: str
    data: dict
    blocks: list

    def summary(self) -> str:
        s = self.data
        return (f"{s['layout']}: {s['compensated']} of {s['motion_blocks']} motion blocks "
                f"compensated ({s['strategy']}{', orientation' if s['orientation'] else ''}); "
                f"predicted tool-tip error max {s['max_before_um']:.3f} -> "
                f"{s['max_after_um']:.3f} um, rms {s['rms_before_um']:.3f} -> "
                f"{s['rms_after_um']:.3f} um")

    def write_program(self, path, inputs=()) -> Path:
        """Write the compensated program (never over an input)."""
        from ..fileio import write_text

        return write_text(path, self.text, inputs=list(inputs))

    def _rows(self) -> list:
        return []


def compensate(layout, program, errors, *, datum=None, tool=(0.0, 0.0, 0.0),
               orientation: bool = False, strategy: str = "full", types=None,
               tol_um: float = 0.1, decimals: int = 4, method: str = "linear", degree=None,
               extrapolate: bool = False, initial: dict | None = None,
               check_travel: bool = True, arc_tol_um: float = 1.0,
               tool_length: float | None = None, dialect: str = "auto") -> Compensation:
    """Rewrite an NC program with compensated coordinates (``volerr compensate``).

    Parameters
    ----------
    layout : str or path
        Layout name or file.
    program : str or path
        A program file, or the program text itself (G-code in machine axis coordinates: mm,
        rotary axes in deg; 'volerr formats nc').
    errors : str or path
        Error directory (``X.csv`` ... ``constants.csv``; 'volerr formats error-table').
    datum : sequence of float, optional
        The work datum: axis positions (layout order, mm / deg) where the work offset was set
        by probing the part.  The corrections are then relative to the error at the datum
        (which the work offset absorbs); None: every block moves by its full volumetric error.
    tool : (3,) mm
        Tool offset from the spindle nose / tool reference point.
    orientation, strategy, types, tol_um, decimals, method, degree, extrapolate, initial,
    check_travel, arc_tol_um, tool_length, dialect
        As the command's options (``volerr compensate --help``).

    Returns
    -------
    Compensation
        ``text``: the compensated program; ``to_dict()``: the ``--json`` summary.
        Sign: a correction is minus the predicted error (actual minus nominal tool tip).
    """
    from ..machine.model import load
    from .compensate import error_functions
    from .program import compensate_program

    model = load(layout)
    require(Path(errors).is_dir(), f"error directory not found: {errors}")
    funcs, _ = error_functions(errors, model, method, degree, extrapolate)
    if datum is not None:   # rotary axes not given are at 0 deg, as --datum takes them
        n_lin = len(model.axes) - len(model.rotary_axes)
        require(n_lin <= len(datum) <= len(model.axes),
                f"datum: give {n_lin} to {len(model.axes)} numbers ({','.join(model.axes)})")
        datum = tuple(float(v) for v in datum) + (0.0,) * (len(model.axes) - len(datum))
    text = program
    if "\n" not in str(program) and Path(program).is_file():
        text = Path(program).read_text(encoding="latin-1")
    res = compensate_program(model, funcs, text, tuple(tool), orientation, strategy, tol_um,
                             decimals, initial, check_travel, types=types,
                             arc_tol_um=arc_tol_um, tool_length=tool_length, dialect=dialect,
                             datum=datum)
    data = {"layout": model.name, "strategy": strategy, "orientation": bool(orientation),
            "types": ",".join(types) if types else "L-VOL,R-VOL",
            "datum": None if datum is None else {"positions": dict(zip(model.axes, datum))},
            **res.summary()}
    return Compensation(res.text, data, res.reports)
