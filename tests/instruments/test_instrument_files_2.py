"""Bad artifact, interferometer and distances files (issue 20): exit 2 and one line naming the
defect, never a traceback, nothing written.  One case through a real process; the others
through ``volerr.cli.main`` in-process (the same entry point, without the start-up cost)."""

import numpy as np
import pytest

from instruments._common import check_one_line_error, cli

def _plate(scale=1.0):
    """Four balls; ``scale`` multiplies the calibrated coordinates (1000: um given as mm)."""
    return ("placement,ball,u_mm,v_mm,w_mm,x_mm,y_mm,z_mm\n"
            + "".join(f"P1,B{i},{u * scale},{v * scale},0,{300 + u},{200 + v},100\n"
                      for i, (u, v) in enumerate([(0, 0), (100, 0), (0, 100), (100, 100)])))


PLATE = _plate()


def _distances(extra_col="", station=True, both=False):
    rng = np.random.default_rng(1)
    head = ("station," if station else "") + "X,Y,Z,d_mm" + (",dd_mm" if both else "")
    rows = [head]
    for s, c in (("S1", (0, 0, 0)), ("S2", (900, 0, 0))):
        for _ in range(10):
            q = rng.uniform((0, 0, 0), (900, 575, 400))
            d = np.linalg.norm(q - c)
            rows.append((f"{s}," if station else "") + f"{q[0]},{q[1]},{q[2]},{d}"
                        + (f",{d}" if both else ""))
    return "\n".join(rows) + "\n"


RUN = "target_mm,cycle,direction,deviation_um\n" + "".join(
    f"{t},{c},{d},0.1\n" for c in (1, 2) for d in ("+1", "-1") for t in (0, 300, 600, 900))

CASES = {
    "artifact_u_um": (PLATE.replace("z_mm\n", "z_mm,u_um\n", 1).replace("100\n", "100,0.5\n"),
                      "ambiguous"),
    "artifact_um_as_mm": (_plate(1000.0), "disagree"),
    "artifact_no_placement": (PLATE.replace("placement,", "").replace("P1,", ""),
                              "placement"),
    "distances_two_readings": (_distances(both=True), "one reading column"),
    "distances_no_station": (_distances(station=False), "station"),
    "run_without_axis": (RUN, "axis"),
    "straightness_without_sense": ("# axis: X\n# mode: straightness\n" + RUN, "sense"),
    "run_axis_not_linear": ("# axis: Q\n" + RUN, "axis"),
}


@pytest.mark.parametrize("case", sorted(CASES))
def test_bad_file_one_line(case, tmp_path, capsys):
    from volerr.cli import main

    text, word = CASES[case]
    path = tmp_path / "bad.csv"
    path.write_text(text)
    spec = ("interferometer:" if case.startswith(("run", "straightness")) else "") + str(path)
    code = main(["calibrate", "MB1", spec, "--json", str(tmp_path / "out.json")])
    err = capsys.readouterr().err
    lines = [ln for ln in err.splitlines() if ln.strip()]
    assert code == 2 and len(lines) == 1 and "Traceback" not in err, err
    assert word.lower() in lines[0].lower(), lines[0]
    assert not (tmp_path / "out.json").exists()


def test_bad_file_through_a_process(tmp_path):
    path = tmp_path / "run.csv"
    path.write_text(RUN)
    r = cli("calibrate", "MB1", f"interferometer:{path}", "--json", tmp_path / "out.json")
    check_one_line_error(r, "axis")
    assert not (tmp_path / "out.json").exists()
