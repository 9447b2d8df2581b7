"""ISO 230-1 names of error parameters, parsed once.

``E{D}{A}`` is a component error (error motion) of axis ``A``: ``D`` in X Y Z is a
translational error (mm) along that direction, ``D`` in A B C an angular error (rad) about
the axis of that letter.  ``E{D}0{A}`` is a location error of axis ``A`` (ISO 230-7, rotary
axes) or, for ``EC0Y``, ``EB0Z``, ``EA0Z``, a squareness error (rad).  Any other name is an
effect parameter of an augmented model (units stated by its effect).

Kinds (the values of ``PARAMETER_KIND`` in every generated error-model module):
``"translational"``, ``"angular"``, ``"squareness"``, ``"location"``, ``"effect"``.
"""

from __future__ import annotations

import re
from dataclasses import dataclass

KINDS = ("translational", "angular", "squareness", "location", "effect")
SQUARENESS_NAMES = ("EA0Z", "EB0Z", "EC0Y")
_ISO = re.compile(r"^E([XYZABC])(0?)([XYZUVWABC])$")


@dataclass(frozen=True)
class IsoName:
    """A parsed parameter name: ``kind`` (see :data:`KINDS`), ``direction`` (X Y Z for a
    translation, A B C for a rotation; None for an effect) and ``axis`` (None for an effect)."""

    name: str
    kind: str
    direction: str | None = None
    axis: str | None = None

    @property
    def is_length(self) -> bool:
        """A translational component or location error (mm)."""
        return self.direction is not None and self.direction in "XYZ"

    @property
    def is_angle(self) -> bool:
        """An angular component, location or squareness error (rad)."""
        return self.direction is not None and self.direction in "ABC"


def parse(name: str) -> IsoName:
    """Parse an error-parameter name (``EXX``, ``ECY``, ``EC0Y``, ``EX0C``, ``KT_X`` ...)."""
    m = _ISO.match(name)
    if m is None:
        return IsoName(name, "effect")
    direction, zero, axis = m.groups()
    if zero:
        kind = "squareness" if name in SQUARENESS_NAMES else "location"
    else:
        kind = "translational" if direction in "XYZ" else "angular"
    return IsoName(name, kind, direction, axis)


def kind_of(name: str) -> str:
    """The kind of a parameter name (one of :data:`KINDS`)."""
    return parse(name).kind


def is_length(name: str) -> bool:
    """True for a translational ISO error (mm): ``EXX``, ``EYZ``, ``EX0C`` ..."""
    return parse(name).is_length


def is_angle(name: str) -> bool:
    """True for an angular ISO error (rad): ``EAX``, ``EC0Y``, ``EB0C`` ..."""
    return parse(name).is_angle


def component(prefix: str, axis: str) -> str:
    """ISO name of a component error: ``component("EX", "Y") == "EXY"``."""
    return prefix + axis


def along_component(layout, axis: str) -> str:
    """The component error along / about an axis' own direction (``EXX``, ``EYY``, ``ECC``
    ...): its positioning error, from the axis' direction in the layout."""
    ax = layout.axes[axis]
    i = max(range(3), key=lambda k: abs(ax.direction[k]))
    return "E" + ("XYZ" if ax.kind == "linear" else "ABC")[i] + axis
