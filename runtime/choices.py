"""The word lists (and the defaults shown in ``--help``) of options that a capability checks and its command offers as argparse
``choices``, stated once in a module that imports nothing: ``volerr --help`` and every
``volerr CMD --help`` build their parsers without importing the capabilities (numpy, scipy,
SQLAlchemy ...), which are imported only when a command runs.  Each capability names its
list from here (``tables.functions.METHODS is choices.INTERPOLATION``)."""

#: how error functions are made from an error table (:mod:`volerr.tables.functions`):
#: linear or cubic interpolation, or a least-squares Legendre polynomial
INTERPOLATION = ("linear", "cubic", "poly")

#: the diagonal lines of ``volerr diagonals`` (:mod:`volerr.cmm.diagonals`): the four space
#: diagonals of the box, the face diagonals, the lines along the axes
DIAGONAL_KINDS = ("space", "face", "axis")

#: ``volerr uncertainty --bias`` (:mod:`volerr.uncertainty.report`): ``corrected`` states the
#: estimate minus the known bias, with U; ``uncorrected`` the reading, with an interval widened
#: to contain the bias
BIAS_MODES = ("corrected", "uncorrected")

#: ``volerr simulate --instrument`` (:mod:`volerr.instruments.simulated_files`): the file written
SIMULATED_INSTRUMENTS = ("deviations", "sphere", "ballbar")

#: the errors planted by ``volerr simulate --instrument sphere|ballbar`` without ``--plant``
#: (:mod:`volerr.instruments.simulated_files`), in report units: um for a translational
#: error, urad for an angular one, um/mm for a ``@slope`` (scale) term
SIMULATED_PLANTED = {
    "sphere": {"EX0B": 12.0, "EY0B": -8.0, "EA0B": 35.0, "EB0B": -20.0, "EX0C": 15.0,
               "EY0C": -10.0, "EA0C": 25.0, "EB0C": -40.0, "EY0A": 9.0, "EZ0A": -7.0,
               "EB0A": 22.0, "EC0A": -18.0},
    "ballbar": {"EC0Y": 20.0, "EB0Z": -12.0, "EA0Z": 8.0, "EXX@slope": 0.015,
                "EYY@slope": -0.005, "EZZ@slope": 0.010},
}

#: controller table formats (``volerr controller``): per-axis tables, temperature compensation
CONTROLLER_AXIS_FORMATS = ("sinumerik-lec", "sinumerik-cec", "heidenhain", "fanuc", "linuxcnc")
CONTROLLER_TEMP_FORMATS = ("sinumerik-temp", "isg-temp")

#: the sections of ``volerr demo`` (``--only``), in the order of its report
DEMO_SECTIONS = ("cmm_a", "cmm_b", "audit", "probe", "identify", "ballbar", "rotary", "ballplate",
                 "multilateration", "fiveaxis", "loop", "iso230_2", "uncertainty", "plan",
                 "check")
