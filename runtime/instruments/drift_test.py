"""``volerr.iso230_3(...)``: the Python API of ``volerr iso230-3``, the ISO 230-3 evaluation of
a thermal drift test.  Here, in the instruments' room, because it reads the drift file
(:mod:`volerr.instruments.drift`) and evaluates it with :mod:`volerr.positioning.iso230_3`
(the positioning room cannot import the instruments)."""

from __future__ import annotations

from ..results import ResultMixin


def iso230_3(file, *, stage_column: str | None = None, identification=None):
    """ISO 230-3:2020 evaluation of a thermal drift test (environmental temperature
    variation, rotating spindle, moving linear axes; ``volerr iso230-3``).

    Parameters
    ----------
    file : str or path
        The drift file ('volerr formats drift'): time ``t_s`` / ``t_min`` / ``t_h``, channels
        ``d_<label>_um`` (um) with ``# channel d_<label>: DIR [at z=<mm>]`` header lines,
        temperatures ``T_*`` (degC), spindle speed ``S_rpm``.
    stage_column : str, optional
        The logged column whose changes make the stages (default ``stage``, else ``S_rpm``).
    identification : volerr.certificate.Identification, optional
        Machine, instrument, operator and date of the report (``write_html``).

    Returns
    -------
    volerr.positioning.api.Iso230_3
        ``to_dict()`` is ``--json``: drift d(t) = reading - first reading (um) per channel,
        its range, max, min and their times; tilts (urad, right hand: about Y = +(sX(z2) -
        sX(z1)) / (z2 - z1), about X = -(sY(z2) - sY(z1)) / (z2 - z1)); stages.
    """
    from ..positioning.api import evaluate_drift_runs
    from .drift import read_runs

    return evaluate_drift_runs(read_runs(file), stage_column, identification)


def drift_convert(raw, *, mapping=None, time_unit: str | None = None, channels=None):
    """A thermal logger's file as saved -> a ``drift`` file (``volerr drift convert``).

    Parameters
    ----------
    raw : str or path
        The logger's CSV (UTF-8): ``Time(min)``, ``ch1(um)``, ``t1(°C)``, ``spindle(RPM)`` ...
        (the header rules of :mod:`volerr.instruments._drift_logger`).
    mapping : str or dict, optional
        Column names over the rules: ``"RAW=NAME,..."`` (``--map``) or ``{RAW: NAME}``.
    time_unit : {"s", "min", "h"}, optional
        The unit of a time column whose header gives none.
    channels : list of str or dict, optional
        A channel's direction and height: ``["ch1=X at z=120", ...]`` (``--channel``) or
        ``{label: "X at z=120"}`` (direction X Y Z -X -Y -Z ?, height on the mandrel, mm).

    Returns
    -------
    DriftConversion
        ``text`` the drift file (time in s, displacements in um), read back already: a file
        that converts is a file ``volerr iso230-3`` and ``volerr loop`` read.
    """
    from . import _drift_logger as logger
    from .drift import convert

    if not isinstance(mapping, dict):
        mapping = logger.parse_map(mapping)
    if not isinstance(channels, dict):
        channels = logger.parse_channels(channels)
    text, runs = convert(raw, mapping, time_unit, channels)
    return DriftConversion(text, runs)


class DriftConversion(ResultMixin):
    """Result of :func:`drift_convert`: ``text`` the drift file, ``runs`` its
    :class:`volerr.instruments.drift.DriftRun` (time in s, displacements in um)."""

    def __init__(self, text: str, runs: list):
        self.text, self.runs = text, list(runs)

    def data(self) -> dict:
        """Per run: readings, time span (s), channels with their directions, other inputs."""
        return {"runs": [{"run": r.run, "n_readings": r.n,
                          "span_s": float(r.t_s[-1] - r.t_s[0]),
                          "channels": {k: r.directions[k] for k in r.channels},
                          "inputs": list(r.inputs)} for r in self.runs]}

    def summary(self, out: str = "drift file") -> str:
        """What ``volerr drift convert`` prints, ``out`` the name of the file written."""
        lines = []
        for r in self.runs:
            head = out if len(self.runs) == 1 else f"{out}[{r.run}]"
            lines.append(f"{head}: {r.n} readings over {r.t_s[-1] - r.t_s[0]:g} s; channels "
                         f"{', '.join(f'{k} ({r.directions[k]})' for k in r.channels)}; inputs "
                         f"{', '.join(r.inputs) or 'none'}")
        return "\n".join(lines)

    def write(self, path, inputs=()):
        """Write the drift file (``--out``); returns its path."""
        from ..fileio import write_text

        return write_text(path, self.text, inputs=list(inputs))
