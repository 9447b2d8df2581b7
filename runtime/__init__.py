"""volerr: derived, audited volumetric error models of CMMs and five-axis machine tools.

Units of the Python API: positions in mm (linear axes) and degrees (rotary axes); translational
errors in mm, angular errors in rad; results in mm.  Reports (the results' ``to_dict()``,
``summary()``, ``table()``) state um, urad, um/mm ... as the commands do, every uncertainty a
standard uncertainty (k = 1) unless it says its k.

One function per command, its options as keywords (imported when first used, so ``import
volerr`` stays light):

* :func:`volerr.calibrate` (``volerr calibrate``), :func:`volerr.plan` (``volerr plan``),
  :func:`volerr.loop` (``volerr loop``), :func:`volerr.identify` (``volerr identify``),
  :func:`volerr.uncertainty` (``volerr uncertainty``), :func:`volerr.check` (``volerr check``),
  :func:`volerr.history` (``volerr history show``; ``volerr.history.add`` stores results):
  callable sub-packages (:mod:`volerr.results`; ``inspect.signature`` shows their keywords);
* :func:`volerr.compensate`, :func:`volerr.ballbar_evaluate`, :func:`volerr.iso230_2`,
  :func:`volerr.error_map` (``volerr map``), :func:`volerr.diagonals`,
  :func:`volerr.probe_cal` (``volerr probe-cal``), :func:`volerr.iso10360`,
  :func:`volerr.iso230_3` (``volerr iso230-3``), :func:`volerr.controller_export` /
  :func:`volerr.controller_import` (``volerr controller export|import``).

Bad input raises :class:`volerr.InputError` with the command's one-line message.
"""

import importlib

from .errors import InputError
from .machine.layout import layout_names as layouts

__version__ = "0.1.0"

#: callable sub-packages: ``volerr.NAME(...)`` (``volerr/NAME/__init__.py`` makes itself callable)
_PACKAGES = ("calibrate", "plan", "loop", "identify", "uncertainty", "check", "history",
             "demo")
#: capability packages named as modules only (none left: ``volerr.history`` is callable as
#: ``volerr.history.show``, and ``volerr.history.add`` / ``show`` stay)
_MODULES = ()
#: API functions living in a capability package: name -> module
_FUNCTIONS = {"compensate": "fiveaxis.api", "ballbar_evaluate": "ballbar.api",
              "iso230_2": "positioning.api", "error_map": "cmm.api",
              "probe_cal": "probe.api", "diagonals": "cmm.api",
              "iso10360": "uncertainty.api", "iso230_3": "instruments.drift_test",
              "controller_export": "fiveaxis.controller_api",
              "controller_import": "fiveaxis.controller_api", "tcpmap": "fiveaxis.api"}

__all__ = ["InputError", "Model", "layouts", "load", *_PACKAGES, *_MODULES, *_FUNCTIONS]


def __getattr__(name):
    # lazy: the capability is imported when first named (numpy, scipy, matplotlib ...); so are
    # Model and load (numpy): ``python -m volerr CMD --help`` imports no numpy
    if name in ("Model", "load"):
        return getattr(importlib.import_module(f"{__name__}.machine.model"), name)
    if name in _PACKAGES or name in _MODULES:
        return importlib.import_module(f"{__name__}.{name}")
    if name in _FUNCTIONS:
        return getattr(importlib.import_module(f"{__name__}.{_FUNCTIONS[name]}"), name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


def __dir__():
    return sorted(set(globals()) | set(__all__))
