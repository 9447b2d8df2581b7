"""
Each layout's chain
===================

Every shipped layout as its two chains from the base: the tool chain (to the probe or tool)
and the workpiece chain (to the part), read from the layout files (``volerr formats
layout``).  A new machine is one more TOML file: ``volerr derive my_machine.toml`` derives
and generates its code, ``volerr audit`` checks the printed equations of the documented ones.
"""
import matplotlib.pyplot as plt

import volerr
from volerr.machine.layout import read_layout

names = volerr.layouts()
fig, ax = plt.subplots(figsize=(8, 0.45 * len(names) + 0.8))
for i, name in enumerate(names):
    lay = read_layout(name)
    ax.text(0, i, name, fontweight="bold", va="center")
    ax.text(0.12, i, "base -> " + " -> ".join(lay.tool_chain) + " (tool)", va="center",
            color="C0", fontsize=8)
    ax.text(0.6, i, "base -> " + " -> ".join(lay.workpiece_chain or ("-",)) + " (part)",
            va="center", color="C1", fontsize=8)
ax.set_ylim(len(names) - 0.5, -0.5)
ax.axis("off")
