"""Session 9 (the suite's time): the deliberate breaks of the whole-chunk NC path used to
compare tests/fiveaxis/test_chunkscan.py before and after its programs were shortened.
``python session9_chunkscan_breaks.py N`` applies break N to the checkout's runtime (revert with
``git checkout runtime``); then ``python session9_chunkscan_cases.py TEST_FILE`` runs the
whole-chunk test's 20 cases of that test file and prints the first failing one.  Results:
session9_nonloop_chunkscan_breaks.txt."""
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
MUT = {
 1: ("runtime/nc/interpret.py", "        val = sheet.w[j - 1, c]\n", "        val = sheet.w[i, c]\n"),
 2: ("runtime/nc/interpret.py", "    interp.tools.update(sc.last_tracked(ws))\n", "    pass\n"),
 3: ("runtime/nc/interpret.py", "np.maximum(sheet.nd[i + wl, wa], sc.frac[ws][ax])", "sheet.nd[i + wl, wa]"),
 4: ("runtime/nc/chunkscan.py", "(v != 0.0) & (v != 1.0),", "(v != 0.0) & (v != 1.0) & (v != 28.0),"),
 5: ("runtime/nc/writer.py", "            elif li >= 0:\n", "            elif li > 0:\n"),
 6: ("runtime/nc/writer.py", "            if la is not None and la[0] > li:\n", "            if la is not None and la[0] >= li:\n"),
 7: ("runtime/nc/interpret.py", "    startv = np.array([np.nan if pos[a] is None else pos[a] for a in letters])", "    startv = np.array([np.nan for a in letters])"),
 8: ("runtime/nc/chunkscan.py", "np.isin(np.round(v), list(gcode.SPECIAL_M))", "np.isin(np.round(v), list(gcode.SPECIAL_M)[1:])"),
}
n = int(sys.argv[1])
f, old, new = MUT[n]
p = ROOT / f
s = open(p).read()
assert s.count(old) == 1, (n, s.count(old))
open(p, "w").write(s.replace(old, new))
