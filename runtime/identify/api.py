"""``volerr.identify(...)``: the Python API of ``volerr identify`` (:mod:`volerr.results`)."""

from __future__ import annotations

from dataclasses import dataclass

from ..results import ResultMixin


@dataclass(repr=False)
class Identified(ResultMixin):
    """Result of :func:`identify`: ``data`` the ``--json`` summary (um, urad), ``errors`` the
    identified error table (:class:`volerr.tables.table.ErrorTable`, mm / rad, with ``std``
    (Type A, k = 1) when there are several rounds), ``identification`` the full solve."""

    data: dict
    errors: object
    identification: object
    axis: str
    quality: object = None      # the residual rule (volerr.fit_quality), JSON "fit_quality"
    fits: dict | None = None    # ``fit``: name -> the fitted error function (tables.errorfit)

    def summary(self, written: str = "(not written)") -> str:
        """What ``volerr identify`` prints, the written table named ``written``."""
        from ..identify.report import summary_lines

        lines = summary_lines(self.axis, self.data, written)
        return "\n".join(lines + (["  " + self.quality.line()] if self.quality else []))

    @property
    def notes(self) -> list:
        """The warnings ``volerr identify`` prints on stderr: one per flagged point (round,
        position, point, residual in um)."""
        from ..identify.report import outlier_warnings

        return outlier_warnings(self.data)

    def error_table_csv(self) -> str:
        """The error table as ``volerr identify --out`` writes it (``_um``, ``_urad``; a
        forced fit's sentence first, as a ``#`` line)."""
        from ..tables.table import table_to_csv

        forced = self.data.get("forced")
        return (f"# {forced}\n" if forced else "") + table_to_csv(self.errors)

    def write_table(self, path, inputs=()):
        """Write :meth:`error_table_csv` (``--out F`` or ``--errors-out DIR``'s
        ``<axis>.csv``); returns its path."""
        from ..fileio import write_text

        return write_text(path, self.error_table_csv(), inputs=list(inputs))

    def _write_own(self, outs, options: dict, inputs: list) -> None:
        """``volerr identify``'s table (``--out F``, else ``--errors-out DIR``'s
        ``<axis>.csv``) and ``--residuals``."""
        self.write_table(outs.path("--out") or outs.path("--errors-out") / f"{self.axis}.csv",
                         inputs=inputs)
        if options.get("residuals"):
            self.write_residuals(outs.path("--residuals"), inputs=inputs)

    def write_residuals(self, path, inputs=()):
        """Write the per-position, per-point residuals (``--residuals``: CSV, um)."""
        from ..fileio import write_text
        from .report import residual_csv

        return write_text(path, residual_csv(self.identification), inputs=list(inputs))

    def png(self) -> bytes:
        """The ``--plot`` PNG: the six error motions and the ``fit`` curves."""
        from ..plotstyle import png
        from .plots import identification_figure

        return png(identification_figure(self.identification, self.fits))

    def _rows(self) -> list:
        from .solve import error_table_rows

        return error_table_rows(self.errors)

    def figures(self) -> dict:
        """``{"motions"}``: the six error motions at every position with +-2 s bars and
        every round (um, urad; the thesis' Fig. 4.x style, as ``--plot`` draws them)."""
        from .plots import identification_figure

        return {"motions": identification_figure(self.identification, self.fits)}


def identify(layout, axis: str, files, *, format: str = "csv", positions: str | None = None,
             points: str | None = None, method: str = "lsq", tracker=None, direction=None,
             origin=None, sense="auto", max_cond: float = 1e4, outlier_k: float = 5.0,
             signs: str = "component", accept_implausible: bool = False,
             accept_residual: bool = False, fit: str | None = None) -> Identified:
    """Three-point (or more) laser-tracker identification of the six error motions of an axis
    (``volerr identify``; the thesis' eq. 30 for linear axes, eq. 3.4 for rotary axes).

    Parameters
    ----------
    layout : str or path
        Layout name or file.
    axis : str
        The measured axis (``"X"`` ... ``"C"``).
    files : str, path or list
        Tracker point files ('volerr formats tracker'): ``round,point,position,x,y,z`` in mm
        (position in mm or deg); the first position of each round is the reference.
    format, positions, points, method, tracker, direction, origin, sense, max_cond, outlier_k
        As the command's options of the same names (``volerr identify --help``);
        ``tracker`` / ``direction`` / ``origin``: 3-vectors (mm; direction unitless; as
        numbers or their text, ``"1,2,3"``), ``origin`` also ``"layout"``.
    signs : {"component", "model"}
        component: the error motions of the moving component that carries the points (as
        the thesis); model: volerr's tool-relative convention, ready for map / compensate.
    accept_implausible : bool
        Accept identified errors beyond what a machine of the layout's travel can have
        (:mod:`volerr.tables.plausible`); by default they are refused with the likely cause.
    accept_residual : bool
        ``--accept-residual``: a fit far above the points' uncertainty
        (:mod:`volerr.fit_quality`) is returned marked forced (``data["fit_quality"]``
        verdict ``"forced"``, ``data["forced"]`` the sentence the written table carries)
        instead of refused (InputError).
    fit : {"poly", "smooth", "linear", "cubic"}, optional
        ``--fit``: fit error functions to the identified table (poly: degree by
        cross-validation; smooth: smoothing spline by GCV; weighted by the rounds' ``std``
        where there is one); their residuals (um, urad) in ``data["fit"]``, the curves on
        the plot.

    Returns
    -------
    Identified
        ``to_dict()`` is ``--json``; ``errors`` the error table (mm / rad).
    """
    from ..identify.inputs import read_rounds, refuse_repeated_files
    from ..identify.solve import identify as solve, to_model_signs
    from ..machine.layout import read_layout

    origin = _origin(origin)
    files = [files] if isinstance(files, str) or hasattr(files, "__fspath__") else list(files)
    refuse_repeated_files(files)
    lay = read_layout(layout)
    rounds = read_rounds(files, format, positions, points)
    sense = {"auto": "auto", "+": 1, "-": -1}.get(sense, sense)
    result = solve(rounds, lay, axis, method=method, tracker=tracker, direction=direction,
                   origin=origin, sense=sense, max_cond=max_cond, outlier_k=outlier_k)
    table = result.errors_table()
    if signs == "model":
        table = to_model_signs(table, lay, reference=result.rounds[0].positions[0])
    check_identified(table, lay, files, accept_implausible)
    from ..fit_quality import gate

    quality = result.fit_quality()
    data = result.report()
    from .solve import error_table_budgets

    data["budgets"] = error_table_budgets(table, len(result.rounds))
    data["fit_quality"] = quality.to_dict()
    quality = gate(data, quality, accept_residual, f"identify {' '.join(map(str, files))}",
                   key="fit_quality")
    fits = None
    if fit:
        from ..tables.errorfit import fit_table

        fits = fit_table(table, fit, weighted=table.std != {})
        data["fit"] = [f.report() for f in fits.values()]
    return Identified(data, table, result, axis.strip().upper(), quality, fits)


def _origin(origin):
    """``origin`` as the solve takes it: ``None``, ``"layout"`` (also ``["layout"]``, the
    command's ``--origin layout``) or a list of three numbers (mm; parsed and checked as
    every 3-vector option, :func:`volerr.units.parse_vector`)."""
    from ..units import parse_vector

    if origin is None or isinstance(origin, str) and origin == "layout":
        return origin
    if not isinstance(origin, str) and list(origin) == ["layout"]:
        return "layout"
    return list(parse_vector(origin, "--origin"))


#: what identified errors beyond the size limits likely come from
IMPLAUSIBLE_CAUSE = ("likely tracker coordinates in another unit, points not fixed to the moving "
                     "component, or the wrong --direction / --origin")


def check_identified(table, layout, files, accept_implausible: bool = False) -> None:
    """Refuse an identified table (mm / rad) beyond what a machine of ``layout``'s travel can
    have (:func:`volerr.tables.table.check_magnitudes`), naming the tracker ``files``."""
    from ..tables.table import check_magnitudes

    table._source = ", ".join(str(f) for f in files)
    check_magnitudes({table.axis: table}, machine=layout, cause=IMPLAUSIBLE_CAUSE,
                     accept_implausible=accept_implausible)
