"""The tool-tip error map as data (volerr.fiveaxis.tcpmap) and the plot drawn from that data
alone."""

import sys

import numpy as np
from helpers.error_dirs import write_errors

import volerr
from volerr.fiveaxis.tcpmap import TcpMap, tcp_map
from volerr.tables.functions import ErrorFunctions


def test_map_positions_keep_the_tip_on_the_point_and_errors_match_the_model(tmp_path):
    m = volerr.load("DMU50")
    funcs = ErrorFunctions.from_dir(write_errors(tmp_path, m, seed=2), m)
    point, tool = (20.0, -10.0, 60.0), (0.0, 0.0, 25.0)
    t = tcp_map(m, funcs, point, tool, n1=7, n2=5)
    assert t.positions.shape == (5, 7, 5) and t.err.shape == (5, 7, 3)
    assert np.allclose(t.positions[..., 3], np.broadcast_to(t.q1, (5, 7)), atol=1e-12)  # B
    assert np.allclose(t.positions[..., 4], np.broadcast_to(t.q2[:, None], (5, 7)), atol=1e-12)
    q = t.positions.reshape(-1, 5)
    assert np.allclose(m.nominal_position(q, tool), point, atol=1e-9)
    ok = t.valid.ravel()
    assert ok.any() and np.isnan(t.err.reshape(-1, 3)[~ok]).all()
    # independent: the model's exact error and orientation error with the tables at q
    # (C: the table covers 0..360 here, so no modulo is needed)
    e = funcs(q[ok])
    assert np.allclose(t.err.reshape(-1, 3)[ok], m.exact_error(q[ok], e, probe=tool),
                       rtol=1e-12, atol=1e-15)
    assert np.allclose(t.orientation.reshape(-1, 3)[ok], m.orientation_error(q[ok], e),
                       rtol=1e-12, atol=1e-18)
    assert np.allclose(t.linear, t.positions[..., :3])


def test_plot_draws_a_map_given_as_data_only(tmp_path):
    """A hand-made map (no model, no error tables): the plot needs nothing else."""
    from volerr.fiveaxis.plots import plot_tcp_error_map

    q1, q2 = np.linspace(0, 90, 4), np.linspace(-180, 180, 3)
    g1, g2 = np.meshgrid(q1, q2)
    err = np.stack([np.sin(np.deg2rad(g1)), np.cos(np.deg2rad(g2)), g1 * 0], axis=2) * 1e-3
    valid = np.ones(g1.shape, dtype=bool)
    valid[0, 0] = False
    err[0, 0] = np.nan
    pos = np.stack([g1 * 0, g1 * 0, g1 * 0, g1, g2], axis=2)
    t = TcpMap("hand", ("X", "Y", "Z", "B", "C"), "B", "C", q1, q2, np.zeros(3), np.zeros(3),
               pos, err, err * 1e-3, valid)
    before = set(sys.modules)
    out = plot_tcp_error_map(t, tmp_path / "m.png")
    assert (tmp_path / "m.png").read_bytes()[:4] == b"\x89PNG" and out == tmp_path / "m.png"
    assert "volerr.fiveaxis.compensate" not in set(sys.modules) - before
