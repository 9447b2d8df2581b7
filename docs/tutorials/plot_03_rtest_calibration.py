"""
A five-axis sphere (R-test) calibration
=======================================

A touch-probe cycle on a sphere fixed to the DMU 50's table, B and C over their travel:
``volerr.calibrate`` identifies the location errors of both rotary axes with their standard
uncertainties (k = 1), names what the campaign cannot determine, and gives the combination it
does determine.  The command: ``volerr calibrate DMU50 sphere_example_DMU50.csv``.

The readings scatter less than their stated uncertainty here (variance factor 0.28, Birge
ratio 0.53): the stated, a-priori uncertainties are kept, not shrunk (GUM practice).
"""
import volerr
from _common import examples

examples()
cal = volerr.calibrate("DMU50", ["sphere_example_DMU50.csv"])
print(cal.summary())

# %%
# The determined combination of the two Y locations, and the table of values.
print(cal.combination({"EY0B": 1, "EY0C": 1}))
print(cal.table())   # a pandas DataFrame where pandas is installed

# %%
# The figures of the report.
figs = cal.figures()
