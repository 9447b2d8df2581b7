"""LinuxCNC itself loads volerr's COMP_FILE and applies it with the sign volerr intends: a
headless LinuxCNC 2.9 simulator (``linuxcnc`` with POSIX non-realtime, trivkins XYZ, a display
program that homes, moves the joint up to one position and down to another, and reads the
motion module's HAL pins) runs with the exported table; the correction it commands there
(``joint.0.backlash-corr`` = ``motor-pos-cmd - pos-cmd``) is minus the planted error
approaching that way (E + B/2 up, E - B/2 down).  Skipped, saying why, where LinuxCNC or its
Python module is not installed (``.ci/run`` installs linuxcnc-uspace with apt)."""

import json
import os
import shutil
import subprocess
import tempfile
from pathlib import Path

import numpy as np
import pytest

from volerr.cli import main
from volerr.tables.table import ErrorTable, write_error_dir

SYSTEM_PYTHON = "/usr/bin/python3"


def _linuxcnc_available() -> str:
    """'' when a headless LinuxCNC can run here, else the reason it cannot."""
    if shutil.which("linuxcnc") is None or shutil.which("halcmd") is None:
        return "LinuxCNC is not installed (apt-get install linuxcnc-uspace)"
    r = subprocess.run([SYSTEM_PYTHON, "-c", "import linuxcnc"], capture_output=True)
    if r.returncode:
        return "LinuxCNC's Python module is not importable by /usr/bin/python3"
    return ""


def _e(x):
    return 3e-3 * np.sin(x / 150.0) + 4e-3 * x / 900.0        # mm, the planted EXX


def _rv(x):
    return -5e-3 + 0 * x                                      # mm, ISO 230-2 B of X


PROBE = r'''#!/usr/bin/python3
import json, subprocess, sys, time
import linuxcnc
s, c = linuxcnc.stat(), linuxcnc.command()
def wait(cond, t=30):
    t0 = time.time()
    while time.time() - t0 < t:
        s.poll()
        if cond():
            return True
        time.sleep(0.05)
    return False
def pin(p):
    return float(subprocess.run(["halcmd", "getp", p], capture_output=True,
                                text=True).stdout)
out = {}
try:
    c.state(linuxcnc.STATE_ESTOP_RESET); c.state(linuxcnc.STATE_ON)
    wait(lambda: s.task_state == linuxcnc.STATE_ON)
    c.mode(linuxcnc.MODE_MANUAL); c.wait_complete(); c.teleop_enable(0); c.wait_complete()
    c.home(-1); wait(lambda: all(s.homed[:3]))
    c.mode(linuxcnc.MODE_MDI); c.wait_complete()
    for name, cmd in MOVES:
        c.mdi(cmd); c.wait_complete(30); wait(lambda: s.inpos, 30); time.sleep(0.3)
        out[name] = [{k: pin(f"joint.{j}.{k}") for k in ("pos-cmd", "motor-pos-cmd",
                                                         "backlash-corr")} for j in (0, 1)]
except Exception as exc:
    out["error"] = repr(exc)
open(RESULT, "w").write(json.dumps(out))
'''


def _ini(comps: dict, probe: Path) -> str:
    """The simulator's ini; ``comps``: joint -> (COMP_FILE, COMP_FILE_TYPE)."""
    joints, axes = [], []
    for j, (a, hi) in enumerate((("X", 900), ("Y", 575), ("Z", 400))):
        axes.append(f"[AXIS_{a}]\nMIN_LIMIT = -1\nMAX_LIMIT = {hi + 1}\nMAX_VELOCITY = 200\n"
                    "MAX_ACCELERATION = 2000\n")
        extra = f"COMP_FILE = {comps[j][0]}\nCOMP_FILE_TYPE = {comps[j][1]}\n" \
            if j in comps else ""
        joints.append(f"[JOINT_{j}]\nTYPE = LINEAR\nHOME = 0\nMAX_VELOCITY = 200\n"
                      f"MAX_ACCELERATION = 2000\nMIN_LIMIT = -1\nMAX_LIMIT = {hi + 1}\n"
                      f"HOME_SEQUENCE = 0\n{extra}")
    return ("[EMC]\nVERSION = 1.1\nMACHINE = volerr-comp-test\n"
            f"[DISPLAY]\nDISPLAY = {probe}\nCYCLE_TIME = 0.100\n"
            "[TASK]\nTASK = milltask\nCYCLE_TIME = 0.001\n"
            "[RS274NGC]\nPARAMETER_FILE = sim.var\n"
            "[EMCMOT]\nEMCMOT = motmod\nCOMM_TIMEOUT = 1.0\nBASE_PERIOD = 0\n"
            "SERVO_PERIOD = 1000000\n"
            "[EMCIO]\nEMCIO = io\nCYCLE_TIME = 0.100\nTOOL_TABLE = sim.tbl\n"
            "[HAL]\nHALFILE = core_sim.hal\n"
            "[TRAJ]\nCOORDINATES = X Y Z\nLINEAR_UNITS = mm\nANGULAR_UNITS = degree\n"
            "DEFAULT_LINEAR_VELOCITY = 100\nMAX_LINEAR_VELOCITY = 200\n"
            "[KINS]\nKINEMATICS = trivkins\nJOINTS = 3\n" + "".join(axes) + "".join(joints))


@pytest.mark.slow
def test_linuxcnc_loads_the_tables_and_corrects_with_their_sign(tmp_path):
    """Joint 0 (X) with a COMP_FILE_TYPE 0 table, joint 1 (Y) with a type 1 table, one run."""
    why = _linuxcnc_available()
    if why:
        pytest.skip(why)
    comps = {}
    for j, a, hi in ((0, "X", 900), (1, "Y", 575)):
        x = np.linspace(0, hi, 91)
        err = tmp_path / f"err{a}"
        write_error_dir(err, {a: ErrorTable(a, x, {f"E{a}{a}": _e(x)}, reversal=_rv(x))},
                        None)
        out = tmp_path / f"comp{j}"
        assert main(["controller", "export", "MB1", "--errors", str(err), "--format",
                     "linuxcnc", "--out", str(out), "--comp-file-type", str(j)]) == 0
        ini_lines = (out / "compensation.ini").read_text()
        assert f"[JOINT_{j}]" in ini_lines and f"COMP_FILE_TYPE = {j}" in ini_lines
        comps[j] = (out / f"{a}.comp", j)
    # the rtapi FIFO in a folder the fallback user (nobody) can write; LinuxCNC refuses root
    fifo = Path(tempfile.mkdtemp(prefix="volerr-rtapi-"))
    os.chmod(fifo, 0o777)
    cfg = tmp_path / "cfg"
    cfg.mkdir()
    moves = [("up", "G0 X437.5 Y301.25"), ("down", "G0 X212.5 Y120")]
    probe = cfg / "probe.py"
    probe.write_text(PROBE.replace("MOVES", repr(moves)).replace(
        "RESULT", repr(str(cfg / "result.json"))))
    probe.chmod(0o755)
    (cfg / "sim.tbl").write_text("")
    (cfg / "sim.ini").write_text(_ini(comps, probe))
    env = {**os.environ, "RTAPI_UID": "65534", "RTAPI_FIFO_PATH": str(fifo / "fifo")}
    try:
        r = subprocess.run(["linuxcnc", str(cfg / "sim.ini")], cwd=cfg, env=env,
                           stdin=subprocess.DEVNULL, capture_output=True, text=True,
                           timeout=180)
    finally:
        shutil.rmtree(fifo, ignore_errors=True)
    if not (cfg / "result.json").exists():
        pytest.skip(f"LinuxCNC did not start here (rc {r.returncode}: "
                    f"{(r.stdout + r.stderr).strip().splitlines()[-1:]})")
    got = json.loads((cfg / "result.json").read_text())
    assert "error" not in got, got
    for name, d in (("up", 1), ("down", -1)):
        for j in (0, 1):
            pins = got[name][j]
            p = pins["pos-cmd"]
            want = -(_e(p) + d * _rv(p) / 2)          # LinuxCNC adds the trim to the command
            assert pins["backlash-corr"] == pytest.approx(want, abs=2e-5), (name, j, pins, want)
            # (halcmd prints about 7 digits: 1e-4 mm at 400 mm)
            assert pins["motor-pos-cmd"] - p == pytest.approx(pins["backlash-corr"], abs=2e-4)
