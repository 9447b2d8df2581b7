"""Issue 36 item 4: LinuxCNC itself loads the ``[JOINT_n] COMP_FILE`` table that ``volerr
controller export ... --format linuxcnc`` writes, and corrects the joint with it.

LinuxCNC 2.9 (Debian ``linuxcnc-uspace``, installed by ``.ci/run``) runs headless here in
simulation: ``linuxcnc INI`` with the sample configurations' ``basic_sim.tcl`` HAL file (a
simulated machine: ``motmod``, ``milltask``, ``io``, no hardware) and, as ``[DISPLAY]
DISPLAY``, a small Python program (LinuxCNC's own ``linuxcnc`` / ``halcmd`` interfaces) that
switches the machine on, homes it, moves the X joint by MDI to positions from both sides and
reads the HAL pins ``joint.0.pos-cmd`` (the commanded joint position) and
``joint.0.motor-pos-cmd`` (what the motion module sends the motor: command plus the
compensation trim), then exits, which shuts LinuxCNC down.  As root, the uspace realtime
``rtapi_app`` needs ``RTAPI_UID`` (a fallback user) and ``RTAPI_FIFO_PATH`` (its socket).

Checked: the trim LinuxCNC applies equals the table's value interpolated at the command, from
the forward column while the joint moved up and from the reverse one while it moved down
(``COMP_FILE_TYPE`` 0: ``nominal - column``, 1: ``column``; measured on a hand-written table:
type 0 ``50 -> 50.005`` gives -0.005 mm, type 1 ``0.005`` gives +0.005 mm), and the joint's
planted error (actual = motor + E + B/2 forward, - B/2 reverse) is left below 0.2 um of up to
8 um.
"""

from __future__ import annotations

import json
import os
import shutil
import signal
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np
import pytest

from volerr.cli import main
from volerr.tables.table import ErrorTable, write_error_dir

PY = "/usr/bin/python3"     # the interpreter LinuxCNC's Python modules are built for
TRAVEL = (0.0, 900.0)       # MB1's X travel, mm
X = np.linspace(*TRAVEL, 46)
#: commanded positions of X and Y, mm, in order: up, up, down, down, up (each reached from its
#: side; inside both joints' travel)
MOVES = (112.5, 431.0, 287.25, 60.0, 503.3)


def _e(x):
    """Planted positioning error of X, mm (actual minus nominal)."""
    return 5e-3 * np.sin(np.asarray(x) / 120.0) + 3e-3 * np.asarray(x) / 900


def _rv(x):
    """Planted ISO 230-2 reversal B of X, mm (+ approach minus - approach)."""
    return -8e-3 + 2e-3 * np.cos(np.asarray(x) / 150.0)


def _why_not() -> str | None:
    if shutil.which("linuxcnc") is None or shutil.which("halcmd") is None:
        return ("LinuxCNC (Debian linuxcnc-uspace) is not installed: .ci/run installs it with "
                "apt-get; apt could not reach the package archive here")
    probe = subprocess.run([PY, "-c", "import linuxcnc, hal"], capture_output=True)
    if probe.returncode != 0:
        return f"{PY} cannot import LinuxCNC's Python module linuxcnc"
    ok = subprocess.run([sys.executable, "-m", "volerr", "controller", "export", "--help"],
                        capture_output=True, text=True)
    if "linuxcnc" not in ok.stdout:
        return "volerr controller export has no --format linuxcnc on this branch yet"
    return None


WHY_NOT = _why_not()
pytestmark = [pytest.mark.skipif(WHY_NOT is not None, reason=WHY_NOT or ""), pytest.mark.slow]

INI = """\
[EMC]
VERSION = 1.1
MACHINE = volerr-comp-file-test
[DISPLAY]
DISPLAY = {display}
[TASK]
TASK = milltask
CYCLE_TIME = 0.001
[RS274NGC]
PARAMETER_FILE = sim.var
[EMCIO]
EMCIO = io
CYCLE_TIME = 0.100
TOOL_TABLE = tool.tbl
[EMCMOT]
EMCMOT = motmod
SERVO_PERIOD = 1000000
[HAL]
HALFILE = LIB:basic_sim.tcl -no_use_hal_manualtoolchange -no_sim_spindle
[TRAJ]
COORDINATES = XYZ
LINEAR_UNITS = mm
ANGULAR_UNITS = degree
MAX_LINEAR_VELOCITY = 200
[KINS]
JOINTS = 3
KINEMATICS = trivkins coordinates=XYZ
{axes}"""

AXIS = """\
[AXIS_{a}]
MIN_LIMIT = {lo}
MAX_LIMIT = {hi}
MAX_VELOCITY = 200
MAX_ACCELERATION = 2000
[JOINT_{j}]
TYPE = LINEAR
HOME = 0
HOME_SEQUENCE = 0
HOME_SEARCH_VEL = 0
HOME_LATCH_VEL = 0
MIN_LIMIT = {lo}
MAX_LIMIT = {hi}
MAX_VELOCITY = 200
MAX_ACCELERATION = 2000
FERROR = 10
MIN_FERROR = 10
{extra}"""

DISPLAY = """\
#!/usr/bin/python3
# LinuxCNC's [DISPLAY] program for the test: on, home, MDI moves, HAL pins -> JSON; exit.
import json, time
import hal, linuxcnc
s, c = linuxcnc.stat(), linuxcnc.command()
h = hal.component("volerr_reader")           # hal.get_value needs a component of its own
h.ready()
out = {{"moves": [], "error": None}}
def wait(cond, t=60.0):
    t0 = time.time()
    while time.time() - t0 < t:
        s.poll()
        if cond():
            return True
        time.sleep(0.02)
    return False
def pin(name):
    return float(hal.get_value(name))      # full double (halcmd getp prints 7 digits)
try:
    c.state(linuxcnc.STATE_ESTOP_RESET)
    c.state(linuxcnc.STATE_ON)
    assert wait(lambda: s.task_state == linuxcnc.STATE_ON), "machine not on"
    c.teleop_enable(0); c.wait_complete()
    c.home(-1); c.wait_complete()
    assert wait(lambda: all(s.homed[:3])), "not homed"
    c.mode(linuxcnc.MODE_MDI); c.wait_complete()
    for x in {moves}:
        c.mdi("G90 G21 G1 X%r Y%r F12000" % (x, x)); c.wait_complete(60)
        assert wait(lambda: s.interp_state == linuxcnc.INTERP_IDLE
                    and abs(pin("joint.0.pos-cmd") - x) < 1e-6
                    and abs(pin("joint.1.pos-cmd") - x) < 1e-6), "move to %r" % x
        time.sleep(0.05)
        out["moves"].append([x] + [pin("joint.%d.%s" % (j, n)) for j in (0, 1)
                                   for n in ("pos-cmd", "motor-pos-cmd")])
except Exception as exc:
    out["error"] = repr(exc)
with open({result!r}, "w") as f:
    json.dump(out, f)
"""


def _comp_lines(ini_text: str) -> dict:
    """{section: [lines]} of the ini lines volerr writes (compensation.ini)."""
    out, sec = {}, None
    for line in ini_text.splitlines():
        line = line.strip()
        if line.startswith("[") and line.endswith("]"):
            sec = line[1:-1]
            out.setdefault(sec, [])
        elif sec and line and not line.startswith(("#", ";")):
            out[sec].append(line)
    return out


def _config(folder: Path, exported: dict) -> Path:
    """The simulated machine's ini in ``folder``: joint ``j`` compensated by the X table
    exported into ``exported[j]`` (its ini lines, the file named with its folder)."""
    comp = {}
    for j, where in exported.items():
        lines = _comp_lines((where / "compensation.ini").read_text())
        assert set(lines) == {"JOINT_0"}, lines
        comp[f"JOINT_{j}"] = [f"COMP_FILE = {where / ln.split('=', 1)[1].strip()}"
                              if ln.startswith("COMP_FILE ") else ln for ln in lines["JOINT_0"]]
    limits = {"X": TRAVEL, "Y": (0.0, 575.0), "Z": (0.0, 400.0)}
    axes = "".join(AXIS.format(a=a, j=j, lo=limits[a][0], hi=limits[a][1],
                               extra="\n".join(comp.get(f"JOINT_{j}", [])) + "\n")
                   for j, a in enumerate("XYZ"))
    display = folder / "display.py"
    display.write_text(DISPLAY.format(moves=MOVES, result=str(folder / "result.json")))
    display.chmod(0o755)
    (folder / "tool.tbl").write_text("T1 P1 Z0 D0 ;\n")
    ini = folder / "sim.ini"
    ini.write_text(INI.format(display=display, axes=axes))
    return ini


def _run_linuxcnc(ini: Path) -> dict:
    """Run LinuxCNC on ``ini`` in its own session; end that session's processes after."""
    fifo = Path(tempfile.mkdtemp(prefix="volerr-rtapi-"))   # reachable by the fallback user
    fifo.chmod(0o777)
    env = {**os.environ, "RTAPI_FIFO_PATH": str(fifo / "sock"), "DISPLAY": ""}
    if os.geteuid() == 0:
        env["RTAPI_UID"] = "65534"           # uspace refuses root without a fallback user
    proc = subprocess.Popen(["linuxcnc", str(ini)], cwd=ini.parent, env=env,
                            stdin=subprocess.DEVNULL, stdout=subprocess.PIPE,
                            stderr=subprocess.STDOUT, text=True, start_new_session=True)
    try:
        log, _ = proc.communicate(timeout=120)
    except subprocess.TimeoutExpired:
        log = "timed out after 120 s"
    finally:
        try:
            os.killpg(proc.pid, signal.SIGKILL)   # whatever of this session is left
        except ProcessLookupError:
            pass
        shutil.rmtree(fifo, ignore_errors=True)
    result = ini.parent / "result.json"
    assert result.exists(), f"LinuxCNC wrote no result:\n{log[-2000:]}"
    doc = json.loads(result.read_text())
    assert doc["error"] is None, f"{doc['error']}\n{log[-2000:]}"
    return doc


def _export(errdir: Path, out: Path, comp_type: int) -> np.ndarray:
    rc = main(["controller", "export", "MB1", "--errors", str(errdir), "--format", "linuxcnc",
               "--comp-file-type", str(comp_type), "--out", str(out)])
    assert rc == 0
    return np.array([[float(v) for v in ln.split()] for ln in
                     (out / "X.comp").read_text().splitlines() if ln.strip()])


def test_linuxcnc_loads_and_applies_the_exported_comp_files(tmp_path):
    """Joint 0 (X) with the COMP_FILE_TYPE 0 table, joint 1 (Y) with the type 1 table of the
    same X errors, in one LinuxCNC run."""
    errdir = tmp_path / "err"
    errdir.mkdir()
    write_error_dir(errdir, {"X": ErrorTable("X", X, {"EXX": _e(X)}, reversal=_rv(X))}, None)
    rows = {t: _export(errdir, tmp_path / f"type{t}", t) for t in (0, 1)}
    sim = tmp_path / "sim"
    sim.mkdir()
    doc = _run_linuxcnc(_config(sim, {0: tmp_path / "type0", 1: tmp_path / "type1"}))
    moves = np.array(doc["moves"])
    assert moves.shape == (len(MOVES), 5)
    sense = np.sign(np.diff([0.0, *MOVES]))
    for t, (cmd, motor) in ((0, (1, 2)), (1, (3, 4))):
        np.testing.assert_allclose(moves[:, cmd], MOVES, atol=1e-6)
        nom, left, without = rows[t][:, 0], [], []
        for x, c, m, s in zip(MOVES, moves[:, cmd], moves[:, motor], sense):
            col = rows[t][:, 1] if s > 0 else rows[t][:, 2]
            trim = np.interp(c, nom, nom - col if t == 0 else col)
            assert m - c == pytest.approx(trim, abs=1e-8), (t, x, s)
            left.append(m + _e(m) + s * _rv(m) / 2 - x)
            without.append(_e(x) + s * _rv(x) / 2)      # where the joint ends with no table
        assert np.abs(without).max() > 5e-3
        assert np.abs(left).max() < 2e-4, (t, left)
