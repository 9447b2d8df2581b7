"""``volerr.iso230_3(...)``: the Python API of ``volerr iso230-3``, the ISO 230-3 evaluation of
a thermal drift test.  Here, in the instruments' room, because it reads the drift file
(:mod:`volerr.instruments.drift`) and evaluates it with :mod:`volerr.positioning.iso230_3`
(the positioning room cannot import the instruments)."""

from __future__ import annotations


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
