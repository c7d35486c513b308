"""Integer keys for the frontier explorer: sorted tables instead of a dictionary entry per
state, distinct keys and rows found by sorting (never ``np.unique``, which imports
``numpy.ma`` on its first call).

Example
-------
>>> first, inverse = distinct(np.array([7, 3, 7, 5, 3]))
>>> first.tolist(), inverse.tolist()
([1, 3, 0], [2, 0, 2, 1, 0])
>>> first_occurrences(np.array([7, 3, 7, 5, 3])).tolist()
[0, 1, 3]
>>> t = SortedKeys(); t.add(np.array([10, 4]), np.array([0, 1])); t.find(np.array([4, 5, 10])).tolist()
[1, -1, 0]
"""

from __future__ import annotations

import numpy as np

__all__ = ["Collision", "SortedKeys", "ROW_BITS", "distinct", "distinct_rows", "row_codes", "first_occurrences", "occurrences",
           "slices"]


class Collision(Exception):
    """Two different states under one key (:mod:`synth.validation.words`: two wide plant
    states mixed to the same key, or more than its capacity met): the explorer leaves the
    model to the machine's path."""


class SortedKeys:
    """Integer keys kept sorted, each with an integer value: a lookup table without a
    dictionary entry per key (insertions are merges of sorted arrays)."""

    def __init__(self) -> None:
        self.keys = np.empty(0, dtype=np.int64)
        self.values = np.empty(0, dtype=np.int64)

    def find(self, keys: np.ndarray) -> np.ndarray:
        """The value of each key, -1 where absent."""
        if not self.keys.size:
            return np.full(len(keys), -1, dtype=np.int64)
        pos = self.keys.searchsorted(keys)
        np.minimum(pos, self.keys.size - 1, out=pos)
        return np.where(self.keys[pos] == keys, self.values[pos], -1)

    def add(self, keys: np.ndarray, values: np.ndarray) -> None:
        """Insert absent, distinct ``keys``."""
        order = keys.argsort(kind="stable")
        keys, values = keys[order], values[order]
        n, m = self.keys.size, keys.size
        at = self.keys.searchsorted(keys) + np.arange(m)  # the new keys' places in the merged table
        old = np.ones(n + m, dtype=bool)
        old[at] = False
        merged, merged_values = np.empty(n + m, dtype=np.int64), np.empty(n + m, dtype=np.int64)
        merged[at], merged_values[at] = keys, values
        merged[old], merged_values[old] = self.keys, self.values
        self.keys, self.values = merged, merged_values


def _groups(perm: np.ndarray, change: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """From a stable sorting permutation and where the sorted keys change (first True):
    each group's first position and each position's group."""
    inverse = np.empty(len(perm), dtype=np.int64)
    inverse[perm] = change.cumsum() - 1
    return perm[change], inverse


def _changes(keys: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """A stable sorting permutation of ``keys``, and where the sorted keys change (first True)."""
    perm = keys.argsort(kind="stable")
    s = keys[perm]
    change = np.empty(len(s), dtype=bool)
    change[:1] = True
    change[1:] = s[1:] != s[:-1]
    return perm, change


def distinct(keys: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The distinct keys, in increasing order, as the position of their first occurrence;
    and each position's rank among them."""
    return _groups(*_changes(keys))


ROW_BITS = 62
"""Rows of at most this many Boolean columns are keyed by one integer each (:func:`row_codes`)."""


def row_codes(bits: np.ndarray) -> np.ndarray:
    """Each row of a Boolean matrix of at most :data:`ROW_BITS` columns as one integer
    (column j: bit j)."""
    return bits.astype(np.int64) @ (np.int64(1) << np.arange(bits.shape[1], dtype=np.int64))


def distinct_rows(bits: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """:func:`distinct` for the rows of a Boolean matrix."""
    n, k = bits.shape
    if k <= ROW_BITS:
        return distinct(row_codes(bits))
    packed = np.packbits(bits, axis=1)
    packed = np.hstack([packed, np.zeros((n, -packed.shape[1] % 8), dtype=np.uint8)])
    words = packed.view(np.uint64)
    perm = np.lexsort(words.T[::-1])
    s = words[perm]
    change = np.ones(n, dtype=bool)
    change[1:] = (s[1:] != s[:-1]).any(axis=1)
    return _groups(perm, change)


def first_occurrences(keys: np.ndarray) -> np.ndarray:
    """Positions of the first occurrence of each distinct key, in the order they occur."""
    perm, change = _changes(keys)
    out = perm[change]
    out.sort()
    return out


def occurrences(keys: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """:func:`first_occurrences`, and for each position the index into them of its key's
    first occurrence (a table's values for new keys set without looking them up again).

    >>> first, at = occurrences(np.array([7, 3, 7, 5, 3]))
    >>> first.tolist(), at.tolist()
    ([0, 1, 3], [0, 1, 0, 2, 1])
    """
    firsts, group = distinct(keys)  # each key's first position, the keys in increasing order
    order = firsts.argsort()  # the keys in order of occurrence
    rank = np.empty(len(order), dtype=np.int64)
    rank[order] = np.arange(len(order))
    return firsts[order], rank[group]


def slices(starts: np.ndarray, groups: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The sizes of the slices ``starts[g]:starts[g + 1]`` of ``groups`` and their
    positions, concatenated in order.

    >>> counts, at = slices(np.array([0, 2, 2, 5]), np.array([2, 0]))
    >>> counts.tolist(), at.tolist()
    ([3, 2], [2, 3, 4, 0, 1])
    """
    counts = starts[groups + 1] - starts[groups]
    ends = counts.cumsum()
    at = (starts[groups] - ends + counts).repeat(counts) + np.arange(int(ends[-1]) if ends.size else 0)
    return counts, at
