"""Run test_whole_chunk_path_writes_the_line_by_line_bytes of the test file given (the file
before or after session 9's change) over its 20 cases; print the first failing case and the
CPU time.  Usage: session9_chunkscan_cases.py TEST_FILE (see session9_chunkscan_breaks.py)."""
import sys, os, importlib.util, tempfile, pathlib, time
for n in ("OPENBLAS_NUM_THREADS","OMP_NUM_THREADS"): os.environ[n]="1"
sys.path[:0] = [str(pathlib.Path(__file__).resolve().parents[2] / "tests")]
import pytest
spec = importlib.util.spec_from_file_location("tmod", sys.argv[1]); t = importlib.util.module_from_spec(spec); spec.loader.exec_module(t)
import volerr
from helpers.error_dirs import write_errors
from volerr.tables.functions import ErrorFunctions
m = volerr.load("DMU50")
d = write_errors(pathlib.Path(tempfile.mkdtemp()), m, seed=5)
setup = (m, ErrorFunctions.from_dir(d, m))
fails = []
t0 = time.process_time()
for seed, orientation in [(s, o) for s in range(10) for o in (False, True)]:
    if True:
        with pytest.MonkeyPatch.context() as mp:
            try:
                t.test_whole_chunk_path_writes_the_line_by_line_bytes(setup, seed, orientation, mp)
            except AssertionError as e:
                fails.append((seed, orientation, str(e).splitlines()[0][:60])); break
            except Exception as e:
                fails.append((seed, orientation, "EXC " + type(e).__name__ + str(e)[:60])); break
print(os.path.basename(sys.argv[1]), "first failing case (seed, orientation):", fails[:1] or "none", "cpu %.1f" % (time.process_time()-t0))
