"""
ISO 230-2 positioning evaluation
================================

A laser-interferometer run of X, five bidirectional cycles: A, E, M, R, B with their
expanded uncertainty U (k = 2, ISO/TR 230-9).  The command: ``volerr iso230-2
iso230_2_run_X.csv``.  (ISO 230-3 thermal tests: a page follows when that command lands.)
"""
import matplotlib.pyplot as plt
import numpy as np

import volerr
from _common import examples

examples()
r = volerr.iso230_2("iso230_2_run_X.csv")
print(r.summary())
d = r.to_dict()
fig, ax = plt.subplots(figsize=(6, 3))
t = np.array(d["targets_mm"])
ax.plot(t, d["mean_fwd_um"], "o-", label="mean, forward")
ax.plot(t, d["mean_bwd_um"], "s-", label="mean, backward")
ax.set_xlabel("target (mm)")
ax.set_ylabel("deviation (µm)")
ax.legend()
