"""ISO 230-2 positioning runs: read a laser-interferometer run of one axis, evaluate it.

Reading (long and wide CSV formats, :mod:`._io`), correction to 20 degC (:mod:`._thermal`),
the ISO 230-2:2014 clause 3 quantities (:mod:`._evaluate`) and the outputs: JSON, plot,
certificate-like HTML and an error table with reversal for ``--errors DIR`` (:mod:`._report`);
several files at once as the command does (:mod:`._batch`).
"""

from ._batch import RunSet, evaluate_files, summary_lines
from ._evaluate import Evaluation, evaluate
from ._io import PositioningRun, read_run
from ._report import (error_table, error_table_csv, plot_runs, report_dict, report_html,
                      standard_notes)
from ._thermal import ThermalCorrection, correct_to_20C
from ._uncertainty import BudgetInputs, budget

__all__ = ["PositioningRun", "read_run", "ThermalCorrection", "correct_to_20C", "Evaluation",
           "evaluate", "report_dict", "plot_runs", "report_html", "error_table", "error_table_csv",
           "standard_notes", "RunSet", "evaluate_files", "summary_lines", "BudgetInputs",
           "budget"]
