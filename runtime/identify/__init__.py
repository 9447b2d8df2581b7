"""Laser-tracker identification: tracker point files, the three-point (or more) least-squares
solve of the six error motions of an axis per position, rounds with Type A uncertainty, the
conversion to the model's sign convention, and the identification plots.
"""

from .solve import Identification, identify, identify_round, to_model_signs

__all__ = ["Identification", "identify", "identify_round", "to_model_signs"]


def __getattr__(name):
    # names of the former flat module volerr.identify, still importable from here
    from . import solve as _m
    try:
        return getattr(_m, name)
    except AttributeError:
        raise AttributeError(f"module 'volerr.identify' has no attribute {name!r}") from None


from . import api as _api  # noqa: E402
from ..results import callable_package  # noqa: E402

# volerr.identify(...) is volerr.identify.api.identify(...), whatever was imported before
callable_package(__name__, _api.identify)
