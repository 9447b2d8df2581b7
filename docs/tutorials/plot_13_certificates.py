"""
One certificate of each kind
============================

Every report volerr writes is also an A4 PDF certificate (``--pdf F`` beside ``--html``, or
``write_pdf`` on the result): the identification, the test conditions of its standard, the
results with u, k and U, the verdict and its decision rule where a tolerance was given, the
uncertainty budget of every reported uncertainty, the notes, then the figures.  Below, each
kind is built from the shipped examples (``volerr examples``) with one identification file,
when this manual was built, and the first page of its PDF is shown (rendered with
`pypdfium2 <https://pypi.org/project/pypdfium2/>`_).  The certificates here are written
without their figures, which come last, so that the manual builds quickly: the first page
is the same as the one the command writes.
"""
import os

import matplotlib.pyplot as plt
import pypdfium2 as pdfium

import volerr
from _common import examples
from volerr import certificate
from volerr.report.stamp import write_pdf

folder = examples()
with open(certificate.IDENTIFICATION_FILE, "w") as f:
    f.write('''operator = "A. Person"
customer = "ACME Precision Ltd"
authorised_by = "B. Person"
date = 2026-11-30
[machine]
id = "VMC-7"
make = "Maker"
serial = "SN-4711"
location = "hall 3"
[[instrument]]
id = "XL-80"
description = "laser interferometer"
certificate = "CAL-2025-17"
due = 2027-06-30
uncertainty = "0.5 ppm (k = 2)"
[conditions]
feed = "1000 mm/min"
compensation = "off"
''')
# a reference calibration for the check and a history with it
volerr.calibrate("DMU50", "sphere_example_DMU50.csv").write_json("cal.json")
volerr.history.add("h.sqlite", "VMC-7", ["cal.json"])

#: (kind, the command, its input files, the API call on the same input)
KINDS = [
    ("iso230-2", "volerr iso230-2", ["iso230_2_run_X.csv"],
     lambda: volerr.iso230_2("iso230_2_run_X.csv", tolerance="A=12")),
    ("iso230-3", "volerr iso230-3", ["drift_spindle.csv"],
     lambda: volerr.iso230_3("drift_spindle.csv")),
    ("ballbar", "volerr ballbar evaluate", ["ballbar_example_XY.csv"],
     lambda: volerr.ballbar_evaluate("ballbar_example_XY.csv")),
    ("iso10360", "volerr iso10360", ["errors_MB1"],
     lambda: volerr.iso10360("MB1", "errors_MB1", mpe="E0=3+L/250")),
    ("calibrate", "volerr calibrate", ["sphere_example_DMU50.csv"],
     lambda: volerr.calibrate("DMU50", "sphere_example_DMU50.csv")),
    ("check", "volerr check", ["sphere_example_DMU50.csv", "cal.json"],
     lambda: volerr.check("DMU50", "sphere_example_DMU50.csv", reference="cal.json")),
    ("history", "volerr history show", ["h.sqlite"],
     lambda: volerr.history("h.sqlite", "VMC-7")),
    ("identify", "volerr identify", ["tracker_example_X.csv"],
     lambda: volerr.identify("MB1", "X", "tracker_example_X.csv")),
    ("probe-cal", "volerr probe-cal", ["probe_sphere.csv"],
     lambda: volerr.probe_cal("probe_sphere.csv", 25.006)),
    ("uncertainty", "volerr uncertainty", ["task_distance.csv"],
     lambda: volerr.uncertainty("MH2", "task_distance.csv", "distance", spec="E0=2+L/300",
                                samples=200)),
    ("loop", "volerr loop", ["deviations_MB1.csv"],
     lambda: volerr.loop("MB1", "deviations_MB1.csv", families="thermal", folds=5)),
    ("drift loop", "volerr loop", ["drift_spindle.csv"],
     lambda: volerr.loop("DMU50", "drift_spindle.csv")),
    ("plan", "volerr plan", [],
     lambda: volerr.plan("MB1", "distances", 60, parameters="squareness")),
    ("map", "volerr map", ["errors_MB1"],
     lambda: volerr.error_map("MB1", "errors_MB1", grid=5)),
    ("diagonals", "volerr diagonals", ["errors_MB1"],
     lambda: volerr.diagonals("MB1", "errors_MB1")),
    ("compensate", "volerr compensate", ["dmu50/hemisphere.nc"],
     lambda: volerr.compensate("DMU50", "dmu50/hemisphere.nc", "dmu50/errors")),
    ("controller", "volerr controller export", ["errors_MB1"],
     lambda: volerr.controller_export("MB1", "errors_MB1", format="fanuc")),
]

# %%
# Each kind: its certificate written, the first page shown
# --------------------------------------------------------
# The identification is the same file for all (a real lab keeps one beside each data
# set); the report id differs because it hashes the inputs and the method.
os.chdir(folder)            # each block of this page runs from the tutorials' folder
for kind, command, files, call in KINDS:
    ident = certificate.build({}, certificate.IDENTIFICATION_FILE, files,
                              method={"command": command, "version": volerr.__version__})
    path = write_pdf(f"{kind.replace(' ', '_')}.pdf", call(), ident, figures=False)
    pdf = pdfium.PdfDocument(str(path))
    page = pdf[0].render(scale=1.6).to_pil()
    print(f"{kind:12s} {path.name}: {len(pdf)} page(s), report id {ident.report_id}")
    fig, ax = plt.subplots(figsize=(7.0, 9.9))
    ax.imshow(page)
    ax.set_axis_off()
    ax.set_title(f"{kind}: page 1 of {len(pdf)} ({command})", fontsize=10)
    fig.tight_layout()
    pdf.close()
plt.show()
