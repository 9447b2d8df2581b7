"""``volerr.ballbar_evaluate(...)``: the Python API of ``volerr ballbar evaluate``."""

from __future__ import annotations

from .evaluate import Evaluation, check_layout_for, evaluate


def ballbar_evaluate(files, layout=None, *, diagnose: bool = True,
                     accept_residual: bool = False) -> Evaluation:
    """ISO 230-4 evaluation of ballbar traces and their diagnosis in ISO 230-1 parameters.

    Parameters
    ----------
    files : str, path or list
        Ballbar files ('volerr formats ballbar'): readings ``dr_um`` (um, positive when the
        bar is longer than nominal), positions in mm / deg.
    layout : str, optional
        Layout name or file; None: a Cartesian machine (``MB1``, its travel not enforced).
        A trace with rotary-axis columns needs its layout.
    diagnose : bool
        Also fit the layout's squareness / location / scale parameters to the traces.
    accept_residual : bool
        ``--accept-residual``: a diagnosis whose fit is far above the readings' declared
        uncertainty (:mod:`volerr.fit_quality`) is given, marked forced; by default it is
        withheld (``diagnosis`` empty, ``diagnosis_note`` says why; G, H, F always given).

    Returns
    -------
    Evaluation
        ``to_dict()`` is ``--json``: per trace the circular deviation G, hysteresis H and
        radial deviation range F (um); ``diagnosis`` value +- std (k = 1) in um, urad, um/m.
    """
    files = [files] if isinstance(files, (str, bytes)) or hasattr(files, "__fspath__") \
        else list(files)
    check_layout_for(files, layout)
    return evaluate(files, layout, diagnose, accept_residual,
                    f"ballbar evaluate {' '.join(map(str, files))} (the diagnosis)")
