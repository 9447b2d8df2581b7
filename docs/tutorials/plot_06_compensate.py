"""
Compensating a post-processor's program
=======================================

The DMU 50 hemisphere finishing program compensated with the machine's error tables, once
relative to the machine reference and once relative to a probed work datum (the work offset
absorbs the error there).  The command: ``volerr compensate DMU50 --errors dmu50/errors
dmu50/hemisphere.nc --out out.nc [--datum X,Y,Z]``.
"""
import matplotlib.pyplot as plt
import numpy as np

import volerr
from _common import examples

examples()
full = volerr.compensate("DMU50", "dmu50/hemisphere.nc", "dmu50/errors")
datum = volerr.compensate("DMU50", "dmu50/hemisphere.nc", "dmu50/errors", datum=(0, 0, 0))
print(full.summary())
print(datum.summary())
print(full.text.splitlines()[5])

# %%
# Predicted tool-tip error of every block before compensation (um).
fig, ax = plt.subplots(figsize=(7, 3))
for res, label in ((full, "machine reference"), (datum, "work datum (0, 0, 0)")):
    b = [np.linalg.norm(r.before_um) for r in res.blocks]
    ax.plot(b, label=f"before, {label}")
ax.set_xlabel("motion block")
ax.set_ylabel("|tool-tip error| (µm)")
ax.legend()
