"""
Task-specific uncertainty
=========================

A 400 mm distance measured on Pahk's CMM B (``MH2``) whose errors are known only through its
specification ``E0 = 2 + L/300 um``: a Monte Carlo over plausible machines (JCGM 101) gives
the result, its standard uncertainty u (k = 1) and expanded U (k = 2).  Run through the
command here (``volerr uncertainty MH2 --task task_distance.csv --evaluate distance --spec
E0=2+L/300 --samples 300 --json u.json``).
"""
import json

import matplotlib.pyplot as plt

from volerr.cli import main
from _common import examples

examples()
main(["uncertainty", "MH2", "--task", "task_distance.csv", "--evaluate", "distance",
      "--spec", "E0=2+L/300", "--samples", "300", "--json", "u.json", "--quiet"])
doc = json.load(open("u.json"))
q = next(iter(doc["results"].values())) if isinstance(doc.get("results"), dict) else doc
print({k: v for k, v in q.items() if not isinstance(v, (list, dict))})
fig, ax = plt.subplots(figsize=(5, 2.5))
u = q.get("standard_uncertainty_um", 0.0)
U = q.get("expanded_uncertainty_um", 0.0)
ax.bar(["u (k = 1)", "U (k = 2)"], [u, U])
ax.set_ylabel("µm")
