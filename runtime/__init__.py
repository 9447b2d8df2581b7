"""volerr: derived, audited volumetric error models of CMMs and five-axis machine tools.

Units of the Python API: positions in mm (linear axes) and degrees (rotary axes); translational
errors in mm, angular errors in rad; results in mm.
"""

from .errors import InputError
from .machine.layout import layout_names as layouts
from .machine.model import Model, load  # noqa: F401

__all__ = ["InputError", "Model", "layouts", "load"]
__version__ = "0.1.0"
