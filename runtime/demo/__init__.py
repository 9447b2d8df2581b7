"""``volerr demo [--out DIR]``: the whole pipeline on built-in data; writes a report.

Sections (each runs the real command or API on built-in data and writes into DIR):

1. CMM A of Pahk (MB1): example error tables, volumetric error map, space diagonals;
2. CMM B of Pahk (MH2): map with the random component, diagonals with their random part;
3. audit of the derived models against the printed equations;
4. probe calibration on a simulated master-sphere run (Pahk's 101-point plan);
5. laser-tracker identification of a simulated three-point campaign, squareness, diagonals;
   ballbar circles (ISO 230-4 G, H, diagnosis) and the rotary axes of the DMU 50 from a
   simulated sphere probing cycle (``volerr calibrate``); a ball plate in four placements on
   MB1 and multilateration from four stations of a tracking interferometer on the DMU 50
   (``volerr calibrate``: parameters, poses, stations, consistency, map with its uncertainty);
6. five-axis DMU 50: a hemisphere finishing program compensated (full model and the thesis'
   strategy), tool-centre-point error over the (B, C) range;
7. closing the loop: a virtual MB1 with an undeclared effect, fit, diagnosis, augmented model;
8. ISO 230-2 evaluation of a simulated positioning run;
9. task-specific uncertainty of a distance (Monte Carlo);
10. measurement plans (``volerr plan``): an R-test campaign for the DMU 50 and a ballbar +
    tracking-interferometer campaign for MB1, executed on volerr's model and calibrated, the
    predicted against the realised standard uncertainties; weekly interim checks of a DMU 50
    (``volerr check``; the history page by ``volerr history`` when installed);
11. ``index.html`` with a section, figures and captions per step, and the headline figures
    printed.  Everything is written at the end, all or nothing.

The sections compute through the Python API (:mod:`volerr.demo.cmm_sections`,
:mod:`~volerr.demo.calibration_sections`, :mod:`~volerr.demo.machine_sections`); their pages,
figures and JSON documents are kept until the last section is done
(:class:`volerr.demo.work.Work`) and written then, with ``index.html``
(:mod:`volerr.demo.page`), into a staged folder put in place all or nothing.
``volerr.demo(out=...)`` is :func:`volerr.demo.run.demo`.
"""

from ..results import callable_package
from .run import Demo, demo
from .text import SECTIONS

__all__ = ["Demo", "SECTIONS", "demo"]

callable_package(__name__, demo)
