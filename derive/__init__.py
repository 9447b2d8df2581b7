"""Symbolic derivations (sympy) and the code generator. Knows nothing of files or plots:
it takes parsed layouts and returns expressions or module text."""
