"""
Task-specific uncertainty
=========================

A 400 mm distance measured on Pahk's CMM B (``MH2``) whose errors are known only through its
specification ``E0 = 2 + L/300 um``: a Monte Carlo over plausible machines (JCGM 101) gives
the result, its standard uncertainty u (k = 1) and expanded U (k = 2).  The command:
``volerr uncertainty MH2 --task task_distance.csv --evaluate distance --spec E0=2+L/300``
(10 000 samples by default; 500 here).
"""
import matplotlib.pyplot as plt

import volerr
from _common import examples

examples()
res = volerr.uncertainty("MH2", "task_distance.csv", "distance", spec="E0=2+L/300",
                         samples=500)
print(res.summary())
fig = res.figures()["histogram"]
doc = res.to_dict()
for name, q in doc["quantities"].items():
    print(f"{name}: result {q['result_mm']:.6f} mm, u {q['standard_uncertainty_um']:.3f} um "
          f"(k = 1), U {q['expanded_uncertainty_um']:.3f} um (k = 2)")
names = list(doc["quantities"])
fig, ax = plt.subplots(figsize=(5, 2.5))
ax.bar([f"{n}: u (k = 1)" for n in names],
       [doc["quantities"][n]["standard_uncertainty_um"] for n in names])
ax.bar([f"{n}: U (k = 2)" for n in names],
       [doc["quantities"][n]["expanded_uncertainty_um"] for n in names])
ax.set_ylabel("µm")
