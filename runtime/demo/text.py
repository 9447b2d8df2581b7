"""The demo's texts and fixed settings: its sections, one sentence per section, the figure
captions, the example tolerances, the audited layouts and the planned campaigns."""

from ..choices import DEMO_SECTIONS as SECTIONS  # the --only word list

#: one sentence per section of index.html: what it shows and how to read it
ABOUT = {
    "check": "A DMU 50 calibrated with an R-test campaign and then checked every week with "
             "the shortest check 'volerr check plan' designs (at most 20 minutes, 95 % power "
             "for a 5 um change of the volumetric error); its C-axis pivot drifts and a "
             "collision at week 12 tilts its B axis: each check names what changed with its "
             "uncertainty; the history page (volerr history) shows events and trends.",
    "plan": "Measurement plans made before any machine time (volerr plan): an R-test "
            "campaign for the DMU 50 and a ballbar + tracking-interferometer campaign for "
            "MB1, each executed on volerr's model with planted errors and calibrated with no "
            "options; the plan's predicted standard uncertainties beside the realised ones "
            "(equal up to the noise of the variance factor) and its map uncertainty beside "
            "the conventional plan's.",
    "cmm_a": "Pahk's CMM A (moving bridge MB1) with synthetic example error tables: the "
             "volumetric error over the working volume (nominal grid dashed, actual solid, "
             "magnified) and the length deviations of the space diagonals.",
    "cmm_b": "Pahk's CMM B (MH2): the same with repeatability columns in the tables, so the "
             "random component (1 sigma) is mapped and propagated to the diagonals separately.",
    "audit": "Every derived CMM equation against the one printed in Pahk 1995; differences are "
             "named errata with their evidence (audit.html, audit.json).",
    "probe": "A simulated 3-lobe kinematic probe measured on Pahk's 101-point plan: effective "
             "ball radius R_eff and the probe error map Probe(phi, theta).",
    "identify": "Shipped laser-tracker data (3 points, 11 positions, 4 rounds per axis): the six "
                "error motions of X, Y and Z identified, squareness from the straightness "
                "reference lines, then the space diagonals of the measured machine.",
    "ballbar": "Ballbar circles (ISO 230-4) in the three planes of MB1 with planted squareness "
               "and scale errors: circular deviation G and hysteresis H per trace, the polar "
               "plot, and the diagnosis in ISO 230-1 parameters computed from the layout's "
               "observation model (with an uncalibrated bar only the scale mismatch of two "
               "axes is determined).",
    "rotary": "A touch-probe kinematics cycle on the DMU 50 (two sphere placements, B and C "
              "over their travel) with planted location errors of both rotary axes: volerr "
              "calibrate identifies them with their uncertainties, names what this plan cannot "
              "separate from the sphere and tool unknowns, and the plan that would.",
    "ballplate": "A 5 x 5 ball plate measured by MB1 in four placements (XY at two heights, "
                 "XZ, YZ; the plate's pose in each unknown) with planted scale and squareness "
                 "errors: volerr calibrate identifies them with the poses, checks the file's "
                 "consistency with its stated 0.5 um, and maps the identified volumetric "
                 "error with its propagated uncertainty and the ISO 10360-2 length errors.",
    "multilateration": "A tracking interferometer at four stations on the table of the DMU 50 "
                       "measures the tool point at 200 poses of the five axes (relative "
                       "distances, 0.3 um + 0.3 um/m): volerr calibrate identifies the linear "
                       "axes' scales, the squareness and the location errors of B and C "
                       "together with the stations' positions and dead paths "
                       "(self-calibrating multilateration).",
    "fiveaxis": "A hemisphere finishing program on the DMU 50 compensated with the full model "
                "and with the thesis' strategy; the tool-tip error over the (B, C) range.",
    "loop": "A virtual MB1 whose X scale follows the X motor's temperature through a 20 min "
            "lag (four logged sensors, drives 2 h on then off): the loop fits the declared "
            "model, finds the missing effect with its sensor and time constant, augments the "
            "layout and compares before and after on held-out points.",
    "iso230_2": "A simulated laser-interferometer positioning run of X (9 targets, 5 cycles, "
                "both directions) evaluated as ISO 230-2: accuracy A, repeatability R, "
                "reversal B, systematic error E, each with its measurement uncertainty U "
                "(k = 2, ISO/TR 230-9) and a verdict against example tolerances (ISO 14253-1); "
                "the certificate is iso230_2.html.",
    "uncertainty": "Task-specific uncertainty of a 400 mm distance on MH2 by Monte Carlo "
                   "(virtual CMM, JCGM 101): the example tables' repeatability columns (_s, "
                   "drawn independently at every probing point, --repeatability) and 0.5 µm "
                   "probing noise; the result is corrected for the bias of the machine's known "
                   "errors (uncertainty.html).",
}

#: figure captions (file name -> sentence)
CAPTIONS = {
    "map_MB1.png": "MB1: volumetric error on the travel grid, nominal (dashed) and actual "
                   "(solid) grid, errors magnified by the factor in the title.",
    "map_MB1_random.png": "MB1: random component of the volumetric error, the standard "
                          "uncertainty (k = 1) for one reading from the tables' repeatability "
                          "columns; bars \u00b1 the magnified rx, ry, rz.",
    "map_MH2.png": "MH2: volumetric error on the travel grid (magnified).",
    "map_MH2_random.png": "MH2: random component (k = 1) of the volumetric error; bars \u00b1 "
                          "the magnified rx, ry, rz.",
    "diagonals_MB1.png": "MB1: length deviation along the space diagonals (top) and of every "
                         "line (below); bands and bars \u00b1 2 u (k = 2).",
    "diagonals_MH2.png": "MH2: length deviation along the space diagonals, bands \u00b1 2 u "
                         "(k = 2) of the random part, and of every line (bars \u00b1 2 u).",
    "probe_map.png": "Probe error: 3-D lobing map (top) and over (theta, phi) (below), µm.",
    "identified_X.png": "X axis: identified error motions, mean of 4 rounds; bars \u00b1 2 s, "
                        "s the standard deviation of one round (the table's _s; its _std is "
                        "s / \u221a4).",
    "identified_Y.png": "Y axis: identified error motions (bars \u00b1 2 s of one round).",
    "identified_Z.png": "Z axis: identified error motions (bars \u00b1 2 s of one round).",
    "ballbar_polar.png": "Ballbar polar plot: radial deviation about the least-squares circle "
                         "(magnified; CCW blue, CW red), G and H per trace.",
    "calibrate_rotary.png": "Identified location errors of B and C, bars \u00b1 2 u (k = 2), "
                            "beside the planted values (crosses).",
    "calibrate_ballplate.png": "Ball plate on MB1: identified scale (\u00b5m/mm) and squareness "
                               "(\u00b5rad), bars \u00b1 2 u (k = 2), beside the planted "
                               "values (crosses).",
    "calibrate_multilateration.png": "Multilateration on the DMU 50: identified parameters, "
                                     "bars \u00b1 2 u (k = 2), beside the planted values "
                                     "(crosses).",
    "compensate_full.png": "DMU 50 program, full model: predicted tool-tip error per block "
                           "before and after compensation.",
    "compensate_thesis.png": "DMU 50 program, thesis strategy (rotary, then linear).",
    "tcpmap_DMU50.png": "DMU 50: tool-tip error at one workpiece point over B and C (grey: "
                        "outside the travel or the tables).",
    "iso230_2.png": "ISO 230-2 plot: mean deviations per direction with bands \u00b1 2 S "
                    "(k = 2) of one reading; ringed: readings that decide a quantity that "
                    "fails or is undecided.",
    "check_weekly.png": "EX0C and EA0B after each weekly check (the reference updated by the "
                        "check, 2 std bars); ringed: the weeks the check names the parameter "
                        "changed.",
    "plan_predicted.png": "Standard uncertainty of each parameter: predicted by volerr plan "
                          "before the measurement (bars) and realised by volerr calibrate on "
                          "the executed plan (dots), k = 1.",
    "uncertainty.png": "Distribution of the Monte Carlo readings of the distance about their "
                       "mean: 95 % coverage interval (red) and \u00b1 U (k = 2, blue).",
}


#: the example tolerances of the ISO 230-2 certificate, um
DEMO_TOLERANCE = "A=12,E=10,M=8,R=4,B=3"

#: the demo audits the CMM models (seconds); ``volerr audit`` alone audits everything
DEMO_AUDIT = ("MB1", "MB2", "FB1", "FB2", "MH1", "MH2", "FH1", "FH2", "CX", "CY")


#: the demo's planned campaigns: layout, instruments, readings, --parameters, planted errors
#: (mm / rad)
PLAN_CASES = (
    ("DMU50", ("sphere:tool=100:tool_u_um=0.5",), 300, None,
     {"EX0B": 20e-3, "EY0B": -10e-3, "EA0B": 30e-6, "EB0B": -20e-6, "EX0C": 5e-3,
      "EY0C": 7e-3, "EA0C": 10e-6, "EB0C": 15e-6}),
    ("MB1", ("ballbar:u_um=0.5:lengths=150,250", "distances:stations=4"), 600, "squareness",
     {"EC0Y": 25e-6, "EB0Z": -15e-6, "EA0Z": 10e-6}))
