"""Linear estimation on a layout's chain, shared by ``volerr loop`` and ``volerr calibrate``:
the design of the declared model at the readings of any instrument (generated sensitivities
projected by the instrument, set-up columns), gauge fixing, identifiability, and least squares
with the columns generated per block of readings.  Modules: ``design`` (columns, gauge,
identifiability, dense linear algebra), ``blocks`` (blockwise normal equations, cross-validated
residuals, score tests).
"""
