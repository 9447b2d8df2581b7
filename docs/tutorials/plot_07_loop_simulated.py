"""
Closing the loop on simulated data
==================================

Measured volumetric deviations of a virtual MB1 whose X scale grows with temperature (an
effect the layout does not declare).  ``volerr.loop`` fits the declared model, traces the
residual to the missing effect, augments the layout and reports the held-out error before
and after.  The command: ``volerr loop MB1 deviations_MB1.csv``.
"""
import matplotlib.pyplot as plt

import volerr
from _common import examples

examples()
res = volerr.loop("MB1", "deviations_MB1.csv")
print(res.summary())
print(res.table())   # a pandas DataFrame where pandas is installed
d = res.to_dict()
fig, ax = plt.subplots(figsize=(4, 3))
ax.bar(["before", "after"], [d["rms_before_um"], d["rms_after_um"]])
ax.set_ylabel("held-out RMS (µm)")
