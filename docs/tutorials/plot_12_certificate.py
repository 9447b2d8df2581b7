"""
A certificate a laboratory signs
================================

The identification of a report (machine, instruments and their calibration, operator, dates,
customer, the test conditions the data cannot tell) is kept once in
``volerr-identification.toml`` beside the data; every command reads it from there (or from
``--identification F``), writes it into the JSON and the page, and ``--pdf F`` writes the
A4 certificate: identification, test conditions, results with u, k and U, the verdict with its
decision rule, and the uncertainty budget of every quantity (``volerr formats
identification``).  The command: ``volerr iso230-2 iso230_2_run_X.csv --tolerance A=12
--pdf certificate.pdf``; below the same through the Python API, and the budget of A drawn.
"""
import matplotlib.pyplot as plt

import volerr
from _common import examples
from volerr import certificate

examples()
with open(certificate.IDENTIFICATION_FILE, "w") as f:
    f.write('''operator = "A. Person"
customer = "ACME Precision Ltd"
date = 2026-11-30
[machine]
id = "VMC-7"
make = "Maker"
serial = "SN-4711"
[[instrument]]
id = "XL-80"
description = "laser interferometer"
certificate = "CAL-2025-17"
due = 2027-06-30
uncertainty = "0.5 ppm (k = 2)"
[conditions]
feed = "2000 mm/min"
overrun = "5 mm"
dwell = "2 s"
''')
ident = certificate.build({}, certificate.find_identification_file(None, ["iso230_2_run_X.csv"]),
                          ["iso230_2_run_X.csv"])
r = volerr.iso230_2("iso230_2_run_X.csv", tolerance="A=12", identification=ident)
r.write_pdf("certificate.pdf")
for label, text in ident.rows():
    print(f"{label:24s} {text}")
b = r.to_dict()["budgets"]["A"]
print(f"A: combined u = {b['u']:.3f} um, U = {b['U']:.3f} um (k = {b['k']:g})")

fig, ax = plt.subplots(figsize=(6, 2.6))
names = [s["source"].split(" (")[0] for s in b["sources"]]
ax.barh(names, [s["contribution"] for s in b["sources"]])
ax.set_xlabel("contribution |c_i| u(x_i) to u(A) (µm)")
ax.set_title(f"budget of A: u = {b['u']:.3f} µm, U = {b['U']:.3f} µm (k = 2)")
fig.tight_layout()
