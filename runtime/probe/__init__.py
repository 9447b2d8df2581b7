"""Probe error: master-sphere calibration (sphere fit, effective radius, spherical-harmonic probe
error map, outliers), probing plans (Pahk's 101 points), and the probe plots.
"""

from .calibration import ProbeCalibration, ProbeMap, calibrate, fit_sphere

__all__ = ["ProbeCalibration", "ProbeMap", "calibrate", "fit_sphere"]


def __getattr__(name):
    # names of the former flat module volerr.probe, still importable from here
    from . import calibration as _m
    try:
        return getattr(_m, name)
    except AttributeError:
        raise AttributeError(f"module 'volerr.probe' has no attribute {name!r}") from None
