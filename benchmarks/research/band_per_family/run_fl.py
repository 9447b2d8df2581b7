"""Run the independent FL driver (fl.py) with a44_sim.ROOT set to the repository (it points one level too low).
usage: ACCEPT44_OUT=DIR [BAND_RULE=A PYTHONPATH=this folder] python run_fl.py"""
import os, sys
REPO = os.path.abspath(os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", ".."))
D = os.path.join(REPO, "benchmarks", "acceptance", "issue44_independent")
sys.path.insert(0, D)
os.chdir(D)
import a44_sim as sim
sim.ROOT = REPO
import fl
fl.SRC = os.path.join(sim.ROOT, "runtime", "data", "fl_thermal_spindle.csv")
fl.main()
