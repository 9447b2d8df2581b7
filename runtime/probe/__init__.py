"""Probe error: master-sphere calibration (sphere fit, effective radius, spherical-harmonic probe
error map, outliers), probing plans (Pahk's 101 points), and the probe plots.
"""

from .calibration import ProbeCalibration, ProbeMap, calibrate, fit_sphere
from ..results import former_module

__all__ = ["ProbeCalibration", "ProbeMap", "calibrate", "fit_sphere"]


# names of the former flat module volerr.probe, still importable from here
__getattr__ = former_module(__name__, "calibration")
