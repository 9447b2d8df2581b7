"""A file of another instrument given to ``probe-cal`` (hostile-input acceptance, RULE.md in
benchmarks/acceptance/hostile_inputs): a deviations file's X, Y, Z axis positions were read
as ball centres and the run refused naming the sphere radius (the wrong mistake).  Now the
line names the file kind; a probing file with extra columns of its own still reads."""

import pytest

from volerr.errors import InputError
from volerr.probe.calibration import read_sphere_csv


@pytest.mark.parametrize("header, kind", [("X,Y,Z,dx_um,dy_um,dz_um", "deviations"),
                                          ("x,y,z,dr_um", "ballbar"),
                                          ("x,y,z,deviation_um", "interferometer"),
                                          ("x_mm,y_mm,z_mm,u_mm,v_mm,w_mm", "artifact")])
def test_another_kind_named(tmp_path, header, kind):
    f = tmp_path / "f.csv"
    n = len(header.split(","))
    f.write_text(header + "\n" + ",".join(["1.5"] * n) + "\n")
    with pytest.raises(InputError) as e:
        read_sphere_csv(f)
    assert kind in str(e.value) and "wrong file for probe-cal" in str(e.value)


def test_probing_file_with_a_comment_column_reads(tmp_path):
    f = tmp_path / "p.csv"
    f.write_text("x,y,z,note\n1,2,3,a\n2,3,4,b\n")
    assert read_sphere_csv(f).points.shape == (2, 3)
