"""Stepwise selection over a scorer, the accept rule a parameter: forward (take the best
proposal while it is accepted), backward (drop the term whose removal costs least while the
rule allows it), merge (replace two terms by one while a replacement is found).  The scorers
(cross-validation from cross-products for drift runs, BIC and paired t over blocks of points
for the 3-D loop, chi-square for the check) and the rules (:mod:`volerr.selection.rules`)
stay the callers'; the order of steps and the tie rule (the first in the stated order) are
stated here once."""

from __future__ import annotations


def forward(propose, accept, max_steps: int, take=None) -> list:
    """The terms taken in order.  ``propose(chosen)`` the best next term (None: no
    candidate); ``accept(term, chosen)`` the rule; ``take(term)`` updates the caller's state
    when a term is taken; at most ``max_steps`` terms."""
    chosen: list = []
    while len(chosen) < max_steps:
        term = propose(chosen)
        if term is None or not accept(term, chosen):
            break
        chosen.append(term)
        if take is not None:
            take(term)
    return chosen


def backward(items, without, drop, keep: int = 0) -> tuple[list, list | None]:
    """Drop, one at a time, the item whose removal costs least while ``drop`` allows it.

    ``without(items, i) -> (cost, payload)`` scores the set without item ``i`` (lower: the
    item matters less; ties: the first); ``drop(result, items) -> bool`` the rule, given the
    least-cost result and the current items; stops at ``keep`` items.  Returns (items kept,
    the results of the last pass over the kept items or None)."""
    items = list(items)
    while len(items) > keep:
        res = [without(items, i) for i in range(len(items))]
        i = min(range(len(res)), key=lambda j: res[j][0])
        if not drop(res[i], items):
            return items, res
        items.pop(i)
    return items, None


def merge(items, replacement, min_items: int = 2) -> list:
    """Replace items while ``replacement(items)`` finds a better set (it returns the new list,
    or None): parsimony across overlapping candidates."""
    items = list(items)
    while len(items) >= min_items:
        new = replacement(items)
        if new is None:
            break
        items = new
    return items
