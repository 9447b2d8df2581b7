"""Plans the loop refuses (issue 21): a file whose points all stand at one position (effects
would be "found" on nothing), and readings that determine none of the declared model's
parameters (sphere probing with the rotary axes standing still): exit 2, one line naming what
is missing, nothing written.  Data from the independent exact simulator."""

import numpy as np

from helpers import family_sim as F
from helpers import in_process
from helpers import instrument_sim as S


def _cli(*args):
    """``volerr ARGS`` in this process (``helpers.in_process``: ``main``'s exit code and
    lines; a warning a process would print is appended to stderr), without starting an
    interpreter; the entry point's own process is tests/cli/test_cli_core.py's."""
    return in_process.volerr(*args)


def _one_line(r, *words):
    lines = [ln for ln in r.stderr.splitlines() if ln.strip()]
    assert r.returncode == 2, (r.returncode, r.stderr[-2000:])
    assert len(lines) == 1 and "Traceback" not in r.stderr, r.stderr
    for w in words:
        assert w in lines[0], (w, lines[0])


def _deviations(m, name, n, rng, still=False):
    b = S.deviations_block(m, name, n, rng, probes=[(0, 0, -100), (60, 0, -80), (0, 60, -80)],
                           cov={"T_C": rng.uniform(19.0, 25.0, n)})
    if still:
        for a in m.axes:
            b.pos[a][:] = 0.5 * sum(m.travel[a])
    return b


def test_point_cloud_from_one_position_refused(tmp_path):
    """Three styli, temperatures varying, every point at X = 450, Y = 287.5, Z = 200: alone or
    beside a file spread over the travel, the file is named and nothing is written."""
    m = F.Machine("MB1")
    rng = np.random.default_rng(2)
    one = _deviations(m, "one.csv", 60, rng, still=True)
    spread = _deviations(m, "spread.csv", 200, rng)
    camp = F.Campaign(m, [one, spread], [S.constant("EC0Y")], {"EC0Y": 12.0}, {}, 3)
    one_file, spread_file = camp.write(tmp_path)
    out = tmp_path / "loop.json"
    for files in ([one_file], [spread_file, one_file]):
        r = _cli("loop", "MB1", *files, "--json", out)
        _one_line(r, "one.csv", "one position", "X = 450")
        assert not out.exists()


def test_readings_that_determine_nothing_refused(tmp_path):
    """Sphere probing on DMU50 with B and C standing still: every reading is absorbed by its
    placement's unknown centre; the message names the axes no point moves."""
    m = F.Machine("DMU50")
    rng = np.random.default_rng(4)
    centres = {"P1": (80, 0, 30), "P2": (-60, 60, 90), "P3": (0, -70, 130)}
    b = S.sphere_block(m, "still.csv", centres, [{"B": 0.0, "C": 0.0}] * 30, probe=(0, 0, -100),
                       u_um=0.5, cov={"T_C": lambda pi, gi: 20.0 + 0.2 * gi})
    locs = ["EX0C", "EY0C", "EX0B", "EY0B"]
    camp = F.Campaign(m, [b], [S.constant(n) for n in locs],
                      dict(zip(locs, rng.normal(0, 10, 4))), F.placement(rng, [b]), 5)
    (path,) = camp.write(tmp_path)
    out = tmp_path / "loop.json"
    r = _cli("loop", "DMU50", path, "--json", out)
    _one_line(r, "determine none", "no point moves B or C")
    assert not out.exists()
