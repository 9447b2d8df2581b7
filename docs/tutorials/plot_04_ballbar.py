"""
A ballbar test (ISO 230-4)
==========================

One circle in XY, both directions: circular deviation G, hysteresis H, radial range F, and
the diagnosis in ISO 230-1 parameters (squareness, scale mismatch, reversals) with standard
uncertainties (k = 1).  The command: ``volerr ballbar evaluate ballbar_example_XY.csv``.
"""
import volerr
from _common import examples

examples()
ev = volerr.ballbar_evaluate("ballbar_example_XY.csv")
print(ev.summary())
fig = ev.figures()["polar"]
