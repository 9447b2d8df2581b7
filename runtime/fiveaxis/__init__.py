"""Five-axis machines: nominal and inverse kinematics helpers, the G-code subset reader/writer,
compensation of NC programs on the full error model, the DMU 50 example, and the plots.
"""

from .kinematics import inverse, is_five_axis, linear_axes

__all__ = ["inverse", "is_five_axis", "linear_axes"]


def __getattr__(name):
    # names of the former flat module volerr.fiveaxis, still importable from here
    from . import kinematics as _m
    try:
        return getattr(_m, name)
    except AttributeError:
        raise AttributeError(f"module 'volerr.fiveaxis' has no attribute {name!r}") from None
