"""NC programs of a plan: ISO 6983 G-code in the layout's machine axes (linear axes in mm,
rotary axes in deg, named as the layout names them).

Contract (``volerr formats plan``): every row of the plan file is, in order, the end point of
one motion block (``G0`` for the first, ``G1`` for the others; absolute ``G90``, metric
``G21``, feed per minute ``G94``); where the instrument reads at a stop (sphere / R-test,
tracking interferometer) the block is followed by a dwell ``G4 P<s>`` (seconds, as LinuxCNC and
ISO 6983 controls read it; a Fanuc-type control reads ``G4 X<s>``).  A set-up change inside
one file (the next sphere placement, the next station) is a program stop ``M0`` with a comment
saying what to move; the program ends with ``M30``.
"""

from __future__ import annotations

import numpy as np

from . import _spec

#: feed of the motion blocks, mm/min (ballbar circles: the ISO 230-4 test feed)
FEED = {"ballbar": _spec.BALLBAR_FEED_MM_MIN, "sphere": 1000.0, "distances": 2000.0}


def _word(axis: str, value: float) -> str:
    text = f"{value:.4f}".rstrip("0").rstrip(".")
    return f"{axis}{'0' if text in ('', '-0') else text}"


def program(model, pf, header: list) -> str:
    """The NC program of plan file ``pf`` (a :class:`volerr.plan._files.PlanFile`)."""
    lines = ["%", *[f"({_comment(h)})" for h in header], "G90 G21 G94"]
    label_col = "station" if pf.kind == "distances" else "placement"
    labels = np.asarray(pf.columns[label_col]).astype(str)
    dwell = _spec.DWELL_S.get(pf.kind)
    texts = {s.label: s.text for s, _ in pf.setups}
    previous = None
    for i in range(pf.n):
        if labels[i] != previous:
            if previous is not None:
                lines.append(f"M0 (set-up change: {_comment(texts.get(labels[i], labels[i]))})")
            else:
                lines.append(f"(set-up {labels[i]}: {_comment(texts.get(labels[i], ''))})")
            motion = "G0"
        words = " ".join(_word(a, float(pf.columns[a][i])) for a in model.axes)
        lines.append(f"{motion} {words}" + ("" if motion == "G0" else f" F{FEED[pf.kind]:g}"))
        motion = "G1"
        if dwell:
            lines.append(f"G4 P{dwell:g}")
        previous = labels[i]
    lines += ["M30", "%"]
    return "\n".join(lines) + "\n"


def _comment(text: str) -> str:
    """Text safe inside ( ): no parentheses."""
    return str(text).replace("(", "[").replace(")", "]")
