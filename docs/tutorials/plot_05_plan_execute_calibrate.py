"""
Plan, execute, calibrate
========================

``volerr.plan`` chooses ballbar circles for MB1 before any machine time is spent and predicts
the standard uncertainty (k = 1) ``calibrate`` will report; here the plan files are filled by
a simulated machine with planted errors (:func:`volerr.plan.execute`) and calibrated.
"""
import tempfile
from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np

import volerr
from volerr.plan import execute

p = volerr.plan("MB1", ["ballbar"], readings=300)
print(p.summary())
folder = Path(tempfile.mkdtemp())
p.write(folder)
planted = {"EC0Y": 20e-6, "EB0Z": -10e-6, "EA0Z": 8e-6}    # rad
rng = np.random.default_rng(1)
files = sorted(str(f) for f in folder.glob("*.csv"))
for f in files:
    execute(f, p.model, planted, rng)
cal = volerr.calibrate("MB1", files)
print(cal.summary())

# %%
# Predicted against realised standard uncertainty.
pred = p.to_dict()["parameters"]
names = [n for n in pred if n in cal.parameters]
fig, ax = plt.subplots(figsize=(6, 3))
x = np.arange(len(names))
ax.bar(x - 0.2, [pred[n]["predicted_std"] for n in names], 0.4, label="predicted u")
ax.bar(x + 0.2, [cal.parameters[n]["std"] for n in names], 0.4, label="realised u")
ax.set_xticks(x)
ax.set_xticklabels(names)
ax.set_ylabel("standard uncertainty (k = 1)")
ax.legend()
