"""``volerr.plan(...)``: the Python API of ``volerr plan`` (:mod:`volerr.results`)."""

from __future__ import annotations

from ..errors import require
from ._run import Plan, plan as _plan

#: the files a plan (or a check plan) writes into its folder, by suffix
PLAN_SUFFIXES = (".csv", ".nc", ".html", ".h", ".mpf")


def plan(layout, instruments, readings: int, *, parameters: str | None = None,
         minutes: float | None = None, criterion: str = "I", seed: int = 0) -> Plan:
    """Design a measurement campaign before the machine time is spent (``volerr plan``).

    Parameters
    ----------
    layout : str or path
        Layout name (``volerr.layouts()``) or layout file.
    instruments : str or list of str
        Instrument specs as ``--instrument`` takes them, e.g. ``"ballbar:lengths=100,150"``,
        ``"sphere:places=3"`` ('volerr formats plan'); one string or several (a mixed
        campaign).
    readings : int
        Readings in all (rows of the plan files), 1 .. 10^7.
    parameters : str, optional
        Parameters the campaign must determine (as ``calibrate --parameters``); default: what
        ``calibrate`` fits for these instruments.
    minutes : float, optional
        Time budget in minutes (set-up changes and readings); default: no limit.
    criterion : {"I", "D"}
        I: mean predicted variance of the volumetric error over the working volume
        (I-optimal); D: determinant of the information matrix.
    seed : int
        Seed of the random starts of the exchange (the same seed, the same plan).

    Returns
    -------
    Plan
        ``to_dict()`` is ``volerr plan --json``: predicted standard uncertainties (k = 1) in
        um, urad, um/mm ...; ``write(folder)`` writes the instrument files (empty reading
        columns), NC programs and the set-up sheet; ``write_html(path)`` the sheet alone;
        ``summary()`` what the command prints.

    Raises
    ------
    volerr.InputError
        Bad input, with the command's one-line message.
    """
    check_options(readings, minutes, parameters)
    specs = [instruments] if isinstance(instruments, str) else list(instruments)
    return _plan(layout, specs, readings, parameters, minutes, criterion, seed)


def check_options(readings: int, minutes: float | None = None, parameters: str | None = None,
                  dialect: str = "iso", out=None, force: bool = False) -> None:
    """Refuse options of :func:`plan` out of range, one line (``volerr plan`` checks them
    before its outputs): ``readings`` outside 1 .. 10^7, ``minutes`` not positive, an empty
    ``parameters``, an unknown NC ``dialect`` (:data:`volerr.plan._dialect.NAMES`); then the
    folder ``out`` (``--out DIR``, when given: :func:`check_plan_folder`, ``force``)."""
    from ._dialect import NAMES

    require(1 <= readings <= 10 ** 7, "--readings must be between 1 and 10000000")
    require(minutes is None or minutes > 0, "--minutes must be positive")
    require(dialect in NAMES, f"--dialect {dialect}: not a dialect; give one of "
                              f"{', '.join(NAMES)}")
    require(parameters is None or parameters.strip(),
            "--parameters: empty; give names, axes or groups")
    if out is not None:
        check_plan_folder(out, force)


def check_plan_folder(folder, force: bool = False, what: str = "plan",
                 suffixes=PLAN_SUFFIXES) -> None:
    """Refuse ``folder`` (``--out DIR`` of ``volerr plan`` / ``check plan``) when it is a
    file, or, without ``force``, when it holds a file a plan writes (``suffixes``) already:
    the first such file named, one line."""
    from pathlib import Path

    out = Path(folder)
    require(not out.exists() or out.is_dir(), f"--out {out}: a file, not a folder")
    if out.is_dir() and not force:
        taken = sorted(p.name for p in out.iterdir() if p.suffix in suffixes)
        require(not taken, f"--out {out}: holds {taken[0] if taken else ''} already; give "
                           f"--force to replace {what} files there, or another folder")
