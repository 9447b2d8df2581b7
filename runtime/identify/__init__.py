"""Laser-tracker identification: tracker point files, the three-point (or more) least-squares
solve of the six error motions of an axis per position, rounds with Type A uncertainty, the
conversion to the model's sign convention, and the identification plots.
"""

from .solve import Identification, identify, identify_round, to_model_signs
from ..results import former_module

__all__ = ["Identification", "identify", "identify_round", "to_model_signs"]


# names of the former flat module volerr.identify, still importable from here
__getattr__ = former_module(__name__, "solve")


from . import api as _api  # noqa: E402
from ..results import callable_package  # noqa: E402

# volerr.identify(...) is volerr.identify.api.identify(...), whatever was imported before
callable_package(__name__, _api.identify)
