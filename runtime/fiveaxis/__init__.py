"""Five-axis machines: nominal and inverse kinematics helpers (also the controller's under
TCPM), compensation of NC programs on the full error model (the programs themselves are read
and written by :mod:`volerr.nc`), tool-centre-point maps, the DMU 50 example, and the plots.
"""

from ..machine.kinematics import inverse, is_five_axis, linear_axes

__all__ = ["inverse", "is_five_axis", "linear_axes"]

