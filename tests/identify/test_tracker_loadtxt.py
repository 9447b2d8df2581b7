"""The numpy.loadtxt path of read_tracker_csv gives what the row-by-row reader gives, and
leaves irregular files to the readers that name the faulty line."""

import numpy as np
import pytest

from volerr.errors import InputError
from volerr.identify import tracker_io as tio


def _rows(rng, rounds=("1", "2"), labels=("K", "P", "Q"), n=4):
    out = []
    for r in rounds:
        for p in np.linspace(0.0, 300.0, n).tolist()[::-1 if r == "2" else 1]:
            for lab in labels:
                x, y, z = (float(v) for v in rng.normal(size=3) * 100)
                out.append((r, lab, p, x, y, z))
    return out


def test_plain_file_matches_row_reader(tmp_path):
    rows = _rows(np.random.default_rng(1))
    text = "x_mm, round ,point,position,y,z,note\n" + "".join(
        f"{x!r}, {r} ,{lab},{p!r},{y!r},{z!r},n\n" for r, lab, p, x, y, z in rows)
    path = tmp_path / "t.csv"
    path.write_text(text)
    assert tio._read_loadtxt(path) is not None          # the fast path is taken
    got = tio.read_tracker_csv(path)
    body = tio._open_rows(path)
    ref = tio._read_by_row(path, body[1:], tio._header_index(path, body[0][1]))
    assert [g.name for g in got] == [r.name for r in ref] == ["t.csv:1", "t.csv:2"]
    for g, r in zip(got, ref):
        assert g.labels == r.labels == ("K", "P", "Q")
        assert np.array_equal(g.positions, r.positions)
        assert np.array_equal(g.points, r.points)
    # hand check of one value: round 2 is measured backwards, first row is position 300
    r2 = [row for row in rows if row[0] == "2"]
    assert got[1].positions[0] == 300.0 and tuple(got[1].points[0, 0]) == r2[0][3:]


@pytest.mark.parametrize("body, message", [
    ('1,P,0,1,2,3\n"1",Q,0,1,2,3\n1,K,0,1,2,3\n1,P,1,1,2,3\n1,Q,1,1,2,3\n', "no measurement"),
    ("1,P,0,1,2,3\n# c\n1,P,0,1,2,4\n", "measured twice"),
    ("1,P,0,1,2,3\n1,Q,0,1,nan,3\n", r"bad.csv:3: y = nan"),
    ("1,P,0,1,2,3\n1,Q,0,1,2\n", "expected at least 6 columns"),
])
def test_irregular_files_fall_back_to_line_messages(tmp_path, body, message):
    path = tmp_path / "bad.csv"
    path.write_text("round,point,position,x,y,z\n" + body)
    assert tio._read_loadtxt(path) is None
    with pytest.raises(InputError, match=message):
        tio.read_tracker_csv(path)
