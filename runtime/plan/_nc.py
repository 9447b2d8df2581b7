"""NC programs of a plan: ISO 6983 G-code in the layout's machine axes (linear axes in mm,
rotary axes in deg, named as the layout names them).

Contract (``volerr formats plan``): every row of the plan file is, in order, the end point of
one motion block (``G0`` for the first, ``G1`` for the others; absolute ``G90``, metric
``G21``, feed per minute ``G94``); where the instrument reads at a stop (sphere / R-test,
tracking interferometer, laser interferometer, artifact) the block is followed by a dwell
``G4 P<s>`` (seconds, as LinuxCNC and
ISO 6983 controls read it; a Fanuc-type control reads ``G4 X<s>``).  A set-up change inside
one file (the next sphere placement, the next station) is a program stop ``M0`` with a comment
saying what to move; the program ends with ``M30``.

Sphere / R-test readings are approached safely: before each reading the tool goes up to the
clearance height (the top of the Z travel: +Z moves the tool away from the workpiece, ISO 841),
turns the rotary axes there, comes down to a point ``RETRACT_MM`` back along the tool axis from
the reading (rotary axes held, so the last move is straight along the tool axis into the nest or
onto the sphere), moves to the reading at the feed, dwells, and leaves the same way.  A ball of
an artifact (ball plate) is approached the same way: its row is the ball's nominal centre, the
dwell stands for the control's ball-probing cycle there.  A
straight ``G1`` from one reading to the next would turn the table under the tool and sweep the
tool through the sphere or out of the R-test's nest.
"""

from __future__ import annotations

import numpy as np

from . import _spec

#: feed of the motion blocks, mm/min (ballbar circles: the ISO 230-4 test feed)
FEED = {"ballbar": _spec.BALLBAR_FEED_MM_MIN, "sphere": 1000.0, "distances": 2000.0,
        "interferometer": 2000.0, "artifact": 1000.0}
#: distances tried, largest first, for the point back along the tool axis from a sphere reading
#: (the first whose axis positions lie inside the travel), mm
RETRACT_MM = (20.0, 10.0, 5.0, 2.0)


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
    retract = _retract_positions(model, pf) if pf.kind in ("sphere", "artifact") else None
    for i in range(pf.n):
        if labels[i] != previous:
            if previous is not None:
                if retract is not None:
                    lines.append(_to_clearance(model))
                lines.append(f"M0 (set-up change: {_comment(texts.get(labels[i], labels[i]))})")
            else:
                lines.append(f"(set-up {labels[i]}: {_comment(texts.get(labels[i], ''))})")
            motion = "G0"
        target = [float(pf.columns[a][i]) for a in model.axes]
        if retract is not None:
            lines += _approach(model, retract[i], target, dwell)
        else:
            words = _words(model, target)
            lines.append(f"{motion} {words}" + ("" if motion == "G0" else f" F{FEED[pf.kind]:g}"))
            if dwell:
                lines.append(f"G4 P{dwell:g}")
        motion = "G1"
        previous = labels[i]
    if retract is not None:
        lines.append(_to_clearance(model))
    lines += ["M30", "%"]
    return "\n".join(lines) + "\n"


def _words(model, values) -> str:
    return " ".join(_word(a, v) for a, v in zip(model.axes, values))


def _to_clearance(model) -> str:
    """The block up to the clearance height: the top of the Z travel (+Z moves the tool away
    from the workpiece, ISO 841)."""
    return f"G0 Z{_word('', model.travel['Z'][1])}"


def _approach(model, above, target, dwell) -> list:
    """The blocks of one sphere reading: up to the clearance height, across with the rotary
    axes turned there, down to ``above`` (the point back along the tool axis), along the tool
    axis to ``target`` at the feed, dwell, and back to ``above``."""
    z = model.axes.index("Z")
    across = [v for j, v in enumerate(above) if j != z]
    feed = FEED["sphere"]
    return [_to_clearance(model),
            "G0 " + " ".join(_word(a, v) for a, v in zip(
                [a for a in model.axes if a != "Z"], across)),
            f"G0 Z{_word('', above[z])}",
            f"G1 {_words(model, target)} F{feed:g}",
            *([f"G4 P{dwell:g}"] if dwell else []),
            f"G1 {_words(model, above)} F{feed:g}"]


def _retract_positions(model, pf) -> np.ndarray:
    """(N, n_axes) axis positions of the points :data:`RETRACT_MM` back along the tool axis from
    each reading of a sphere file, rotary axes held (mm / deg): the largest distance whose
    positions lie inside the travel; the reading itself where none does."""
    q = np.column_stack([np.asarray(pf.columns[a], float) for a in model.axes])
    probe = tuple(float(np.asarray(pf.columns[c], float)[0]) for c in ("Xp", "Yp", "Zp"))
    tip = model.forward(q, probe=probe)
    rotary = {a: q[:, j] for j, a in enumerate(model.axes) if a in model.rotary_axes}
    lo = np.array([model.travel[a][0] for a in model.axes])
    hi = np.array([model.travel[a][1] for a in model.axes])
    out, todo = q.copy(), np.ones(len(q), bool)
    for d in RETRACT_MM:
        pos = model.linear_positions(tip[:, :3] + d * tip[:, 3:], rotary, probe)
        cand = np.column_stack([pos[a] for a in model.axes])
        ok = todo & np.all((cand >= lo) & (cand <= hi), axis=1)
        out[ok], todo = cand[ok], todo & ~ok
    return out


def _comment(text: str) -> str:
    """Text safe inside ( ): no parentheses."""
    return str(text).replace("(", "[").replace(")", "]")
