"""Error tables: reading and writing per-axis tables and constants (unit-suffixed CSV,
:mod:`.table`), error functions of position (linear, cubic, Legendre least squares,
:mod:`.functions`, :mod:`.legendre`), fitting identified tables (:mod:`.errorfit`), and the
controller exchange formats (ISG, Etalon, :mod:`.controller`).
"""

from .table import (ErrorTable, read_constants, read_error_dir, read_error_table,
                                 table_to_csv, write_constants, write_error_dir,
                                 write_error_table)
from .functions import ErrorFunctions
from ..results import former_module

__all__ = ["ErrorFunctions", "ErrorTable", "read_constants", "read_error_dir", "read_error_table", "table_to_csv", "write_constants", "write_error_dir", "write_error_table"]


# names of the former flat module volerr.tables, still importable from here
__getattr__ = former_module(__name__, "table")
