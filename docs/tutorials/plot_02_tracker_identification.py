"""
Three-point laser-tracker identification
========================================

The thesis' three-point method: three targets on the moving carriage measured by a laser
tracker at 11 positions of X, four rounds.  ``volerr.identify`` solves the six error motions
of the axis at every position (eq. 30), with the Type A standard uncertainty (k = 1) of the
rounds.  The command: ``volerr identify MB1 --axis X tracker_example_X.csv --out X.csv``.
"""
import matplotlib.pyplot as plt
import numpy as np

import volerr
from _common import examples

examples()
ident = volerr.identify("MB1", "X", "tracker_example_X.csv")
print(ident.summary())

# %%
# The error motions with their +-2 u bars (k = 2).
t = ident.errors
fig, axes = plt.subplots(1, 2, figsize=(9, 3.5))
for name, v in t.values.items():
    ang = name[1] in "ABC"
    f = 1e6 if ang else 1e3
    s = t.std.get(name, np.zeros_like(v)) if t.std else np.zeros_like(v)
    axes[int(ang)].errorbar(t.positions, f * v, yerr=2 * f * s, label=name, capsize=2)
axes[0].set_ylabel("translational error (µm)")
axes[1].set_ylabel("angular error (µrad)")
for ax in axes:
    ax.set_xlabel("X (mm)")
    ax.legend(fontsize=7)
fig.tight_layout()
