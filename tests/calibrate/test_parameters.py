"""Issue 32, item 4: ``--parameters`` accepts every name ``calibrate`` and ``ballbar evaluate``
print (constants, ``EXX@slope``, ``EZY@P2``, Fourier ``EXC@cos1``, reversals ``RV_X``, the
diagnosis' differences ``EXX@slope-EYY@slope``) and refuses empty or malformed text with one
line.  Before: ``--parameters EXX@slope`` was refused and ``--parameters ''`` accepted."""

import pytest

from volerr.calibrate import calibrate, terms
from volerr.calibrate.examples import write_ballbar_example
from volerr.errors import InputError
from volerr.machine.model import load

pytestmark = pytest.mark.xdist_group("test_calibrate_parameters")


class _Run:
    """``volerr ARGS`` run in this process: ``returncode``, ``stdout``, ``stderr``."""

    def __init__(self, capsys, args):
        from volerr.cli import main

        self.returncode = main([str(a) for a in args])
        cap = capsys.readouterr()
        self.stdout, self.stderr = cap.out, cap.err


@pytest.fixture(scope="module")
def printed(tmp_path_factory):
    """Every name a calibration of three circles (all parameters, degree 3) and one of the
    shipped sphere file (rotary series) prints, with the layout and the files."""
    from importlib.resources import files

    folder = tmp_path_factory.mktemp("names")
    bb = [str(f) for f in write_ballbar_example(folder, "MB1")["files"]]
    sphere = str(files("volerr") / "data" / "sphere_example_DMU50.csv")
    out = {}
    for layout, fs, spec in (("MB1", bb, "all"), ("DMU50", [sphere], "location,B,C")):
        d = calibrate(layout, fs, parameters=spec, degree=3, plan=False, progress=False).data
        names = set(d["parameters"]) | set(d["unidentifiable"]) | set(d["gauge_fixed"])
        names |= {c["written_as"] for c in d["combinations"]} | set(d["fitted_terms"])
        out[layout] = (sorted(names), fs)
    return out


def test_every_printed_name_is_accepted(printed):
    kinds = set()
    for layout, (names, _) in printed.items():
        model = load(layout)
        for name in names:
            req = terms.request(name, model)                 # no InputError
            assert req.parameters or req.reversals, name
            kinds.add(name.split("@")[1].rstrip("0123456789") if "@" in name else "const")
    # the families of names the project prints were all among them
    assert {"offset", "slope", "P", "cos", "sin", "const"} <= kinds, kinds


def test_printed_terms_fit_through_the_cli(printed, capsys):
    names, files = printed["MB1"]
    r = _Run(capsys, ("calibrate", "MB1", *files, "--parameters",
                      "EXX@slope-EYY@slope,EZZ@slope,EC0Y,EB0Z,EA0Z,EYX@P2,RV_X"))
    assert r.returncode == 0, r.stderr
    assert "EC0Y = " in r.stdout


@pytest.mark.parametrize("spec, words", [
    ("", "empty"), (" ", "empty"), ("EC0Y,,EB0Z", "empty"), ("EC0Y,", "empty"),
    ("EXX@", "unknown term"), ("EXX@P2x", "unknown term"), ("EXX@cos0", "unknown term"),
    ("EX0C@slope", "constant"), ("EQQ@slope", "not a parameter"), ("FOO", "neither"),
    ("RV_Q", "reversal"), ("EXX@slope-", "malformed")])
def test_malformed_refused(spec, words):
    with pytest.raises(InputError, match=words):
        terms.request(spec, load("DMU50"))


def test_empty_refused_on_the_command_line(printed, capsys):
    _, files = printed["MB1"]
    for spec in ("", "EXX@offset"):
        r = _Run(capsys, ("calibrate", "MB1", *files, "--parameters", spec))
        assert r.returncode == 2 and len(r.stderr.strip().splitlines()) == 1, r.stderr
        assert "Traceback" not in r.stderr and "--parameters" in r.stderr
