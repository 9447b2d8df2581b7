"""G1 moves: the report states the largest predicted deviation of the tool path from the
nominal line between the corrected end points, and its line; checked against a dense sampling
of the written move through the independent exact chain (helpers.fiveaxis_chain.tool2work);
G0 rapids are not counted (their path is not cut)."""

import numpy as np
import pytest
from helpers.error_dirs import write_errors
from test_arcs import _actual_tips, _nominal_tips

import volerr
from volerr.fiveaxis.program import compensate_program
from volerr.tables.functions import ErrorFunctions

#: a long G1 diagonal (line 3), then a longer G0 rapid back (line 4, not counted), a short G1
PROGRAM = ("%\nG90 G0 X-200 Y-150 Z50 B10 C30\nG1 X200 Y150 Z150 F800\n"
           "G0 X-200 Y-150 Z50\nG1 X-190 F500\n")


@pytest.fixture(scope="module")
def setup(tmp_path_factory):
    m = volerr.load("DMU50")
    d = write_errors(tmp_path_factory.mktemp("err"), m, seed=11)
    return m, ErrorFunctions.from_dir(d, m)


def _dense_deviation_um(m, funcs, a_nom, b_nom, a_out, b_out, n=2001) -> float:
    """Largest distance (um) of the actual tip along the written move (n points, joint-space
    linear) from the nominal tip segment, by the independent chain."""
    t = np.linspace(0.0, 1.0, n)[:, None]
    act = _actual_tips(m, funcs, a_out + t * (b_out - a_out))
    p0, p1 = _nominal_tips(m, np.array([a_nom, b_nom]))
    d = p1 - p0
    s = np.clip((act - p0) @ d / (d @ d), 0.0, 1.0)
    return float(np.linalg.norm(act - (p0 + s[:, None] * d), axis=1).max()) * 1e3


def test_g1_path_deviation_is_reported_with_its_line_and_agrees_with_a_dense_check(setup):
    m, funcs = setup
    res = compensate_program(m, funcs, PROGRAM)
    lines = res.summary()["lines"]
    assert lines["sampled"] == 2 and lines["tcpm_not_sampled"] == 0
    assert lines["line"] == 3
    rep = {r.line: r for r in res.reports}
    pos = {k: (np.array([rep[k].nominal[a] for a in m.axes]),
               np.array([rep[k].output[a] for a in m.axes])) for k in (2, 3, 4)}
    dense = _dense_deviation_um(m, funcs, pos[2][0], pos[3][0], pos[2][1], pos[3][1])
    assert dense > 2.0          # the straight move strays: the check can fail
    # the report samples the knots and quarter points: within 0.02 um of the dense maximum
    assert abs(lines["max_path_deviation_um"] - dense) < 0.02, (lines, dense)
    # the rapid (line 4) strays as far, but is not counted
    rapid = _dense_deviation_um(m, funcs, pos[3][0], pos[4][0], pos[3][1], pos[4][1])
    assert rapid > 2.0


def test_no_feed_move_no_figure(setup):
    m, funcs = setup
    s = compensate_program(m, funcs, "G90 G0 X10 Y10 Z100 B10 C30\nX20\n").summary()
    assert s["lines"] == {"sampled": 0, "tcpm_not_sampled": 0, "max_path_deviation_um": 0.0,
                          "line": None}
