"""Deterministic line wrapping of generated Python statements (the last step of the printer).

A statement longer than the width is broken at token boundaries inside brackets (Python's
implicit line joining), so the code means exactly what the one-line form meant.  An assignment
whose right-hand side has operators outside any bracket is first put in parentheses.  Break
points are preferred in this order: after a comma, before a binary ``+``/``-``, at a ``*``,
anywhere else between tokens; within the preferred kind the latest one that fits is taken, as
long as it leaves the line at least half full.  No randomness, no dependence on hashing: the
same text gives the same lines.
"""

from __future__ import annotations

import io
import re
import textwrap
import tokenize

#: widest generated line (the project's line length)
WIDTH = 99

_OPEN, _CLOSE = "([{", ")]}"
_SKIP = (tokenize.NEWLINE, tokenize.NL, tokenize.ENDMARKER, tokenize.INDENT, tokenize.DEDENT,
         tokenize.COMMENT)


# Python's own token patterns, in the tokenizer's order (number, operator, string, name);
# strings without escapes or line breaks only (others fall back to tokenize)
_TOKEN = re.compile(r"[ ]*(?:(?P<number>%s)|(?P<op>%s)|(?P<string>(?:%s)(?:'[^'\\\n]*'|"
                    r'"[^"\\\n]*"))|(?P<name>\w+))'
                    % (tokenize.Number, tokenize.Special, tokenize.StringPrefix))
_TYPES = {"number": tokenize.NUMBER, "name": tokenize.NAME, "string": tokenize.STRING,
          "op": tokenize.OP}


def _tokens(code: str) -> list[tuple[str, int, int, int]]:
    """(text, start column, end column, type) of the tokens of a one-line statement.

    The statements the printer emits (names, decimal numbers, plain quoted strings,
    operators, single spaces) are split by one regular expression; anything it does not
    consume entirely goes to :mod:`tokenize` (a test compares the two on such statements)."""
    out, pos, n = [], 0, len(code.rstrip(" "))
    match = _TOKEN.match
    while pos < n:
        m = match(code, pos)
        if m is None or m.end() == pos:
            return _tokenize(code)
        kind = m.lastgroup
        start = m.start(kind)
        out.append((m.group(kind), start, m.end(), _TYPES[kind]))
        pos = m.end()
    return out


def _tokenize(code: str) -> list[tuple[str, int, int, int]]:
    toks = tokenize.generate_tokens(io.StringIO(code).readline)
    return [(t.string, t.start[1], t.end[1], t.type) for t in toks if t.type not in _SKIP]


def _depths(toks) -> list[int]:
    """Bracket depth in front of every token."""
    out, depth = [], 0
    for s, *_ in toks:
        out.append(depth)
        if s in _OPEN:
            depth += 1
        elif s in _CLOSE:
            depth -= 1
    return out


def _assignment(toks, depths) -> int | None:
    """Index of the top-level ``=`` of an assignment, if any."""
    for i, ((s, *_), d) in enumerate(zip(toks, depths)):
        if d == 0 and s == "=":
            return i
    return None


def _parenthesised(code: str) -> str:
    """``lhs = rhs`` with ``rhs`` in parentheses when it has operators outside brackets."""
    toks = _tokens(code)
    depths = _depths(toks)
    eq = _assignment(toks, depths)
    if eq is None:
        return code
    bare = any(d == 0 and typ == tokenize.OP and s not in "." + _OPEN + _CLOSE
               for (s, _, _, typ), d in zip(toks[eq + 1:], depths[eq + 1:]))
    if not bare:
        return code
    cut = toks[eq][2]
    return f"{code[:cut]} ({code[cut:].strip()})"


def _break_points(toks, depths) -> list[tuple[int, int]]:
    """(column, preference) of every legal break: before a token inside brackets, right of
    the assignment's ``=``; preference 0 (best) .. 3."""
    eq = _assignment(toks, depths)
    first = 1 if eq is None else eq + 2
    out = []
    for i in range(max(first, 1), len(toks)):
        if depths[i] == 0 or toks[i][0] in _CLOSE:
            continue
        prev, prev_type = toks[i - 1][0], toks[i - 1][3]
        binary = prev_type in (tokenize.NAME, tokenize.NUMBER, tokenize.STRING) or \
            prev in _CLOSE
        if prev == ",":
            pref = 0
        elif toks[i][0] in ("+", "-") and binary:
            pref = 1
        elif toks[i][0] == "*" or prev == "*":
            pref = 2
        else:
            pref = 3
        out.append((toks[i][1], pref))
    return out


def wrap_statement(code: str, indent: str = "", width: int = WIDTH, hang: int = 4) -> list[str]:
    """One Python statement (a single line, no indentation) as lines of at most ``width``
    characters where a legal break exists: the first line indented by ``indent``, the
    continuation lines by ``indent`` plus ``hang`` spaces."""
    if len(indent) + len(code) <= width:
        return [indent + code]
    code = _parenthesised(code)
    toks = _tokens(code)
    points = _break_points(toks, _depths(toks))
    lines, start, lead = [], 0, indent
    while len(lead) + len(code) - start > width:
        room = width - len(lead)
        fits = [(c, p) for c, p in points if start < c <= start + room]
        chosen = None
        for pref in range(4):
            ok = [c for c, p in fits if p <= pref and c - start >= room // 2]
            if ok:
                chosen = max(ok)
                break
        if chosen is None:
            later = [c for c, _ in points if c > start]
            if fits:
                chosen = max(c for c, _ in fits)
            elif later:
                chosen = min(later)
            else:
                break
        lines.append(lead + code[start:chosen].rstrip())
        start, lead = chosen, indent + " " * hang
    lines.append(lead + code[start:].strip())
    return lines


def wrap_text(text: str, indent: str = "", width: int = WIDTH) -> list[str]:
    """Prose (a docstring) filled to ``width`` with ``indent`` on every line after the first
    (the first line follows the opening quotes)."""
    return textwrap.wrap(text, width=width - len(indent) - 3, break_long_words=False,
                         break_on_hyphens=False) or [""]
