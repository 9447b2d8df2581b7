"""Error tables: reading and writing per-axis tables and constants (unit-suffixed CSV), error
functions of position (linear, cubic, Legendre least squares), fitting identified tables, and the
controller exchange formats (ISG, Etalon).
"""

from volerr.tables.table import (ErrorFunctions, ErrorTable, read_constants, read_error_dir,
                                  read_error_table, table_to_csv, write_constants,
                                  write_error_dir, write_error_table)

__all__ = ["ErrorFunctions", "ErrorTable", "read_constants", "read_error_dir", "read_error_table", "table_to_csv", "write_constants", "write_error_dir", "write_error_table"]


def __getattr__(name):
    # names of the former flat module volerr.tables, still importable from here
    from volerr.tables import table as _m
    try:
        return getattr(_m, name)
    except AttributeError:
        raise AttributeError(f"module 'volerr.tables' has no attribute {name!r}") from None
