"""Per-element bits of many plant states at once, read a run of elements at a time.

A run is a stretch of consecutive elements inside one word of the plant codes (the flat
code, or one of a wide plant's words, :mod:`synth.validation.words`) whose states number
at most :data:`RUN`: its joint local index is ``(word // base) % size``, two numpy passes
for the whole run instead of two per element (:class:`Runs`). A :class:`Masks` holds, per
run, a table of bits packed in ``int64`` words (63 bits each): the AND over the run's
elements of per-element bits (which product terms hold: the factors of SUP's level
terms), or their OR (which plant variables are true: the orders' values); the bits of a
whole array of states are then one gather and one AND (OR) per run.

Example
-------
>>> runs = Runs((2, 3, 4), np.zeros(3, dtype=np.int64), np.array([12, 4, 1]), limit=12)
>>> [(r.word, r.base, r.size, r.members) for r in runs.items]
[(0, 12, 2, [0]), (0, 1, 12, [1, 2])]
>>> m = Masks(runs, {0: np.array([[True], [False]]), 2: np.array([[False], [True], [True], [False]])}, 1, conj=True)
>>> codes = np.array([0 * 12 + 1, 0 * 12 + 2, 1 * 12 + 1])  # element 0 at 0, 0 and 1; element 2 at 1, 2, 1
>>> unpack(m.of(lambda g: runs.index(runs.items[g], [codes]), 3), 1)[:, 0].tolist()
[True, True, False]
"""

from __future__ import annotations

from typing import Callable

import numpy as np

from synth.frozen import frozen

__all__ = ["RUN", "Run", "Runs", "Masks", "pack", "unpack"]

RUN = 4096
"""The most joint states of a run (its tables' rows)."""

BITS = 63


@frozen
class Run:
    """Consecutive elements ``members`` of word ``word``: joint index ``(word // base) % size``."""

    word: int
    base: int
    size: int
    members: list[int]
    subs: list[int]  # each member's stride inside the joint index


class Runs:
    """The elements (sizes ``shape``, each in word ``word`` with stride ``stride`` there)
    cut into runs of at most ``limit`` joint states."""

    def __init__(self, shape: tuple[int, ...], word: np.ndarray, stride: np.ndarray, limit: int = RUN) -> None:
        self.shape = shape
        order = sorted(range(len(shape)), key=lambda a: (int(word[a]), int(stride[a])))  # by word, then significance
        self.items: list[Run] = []
        members: list[int] = []
        for a in order:
            if members and (int(word[a]) != int(word[members[0]])
                            or int(stride[a]) != int(stride[members[-1]]) * shape[members[-1]]
                            or self._size(members) * shape[a] > limit):
                self.items.append(self._run(members, word, stride))
                members = []
            members.append(a)
        if members:
            self.items.append(self._run(members, word, stride))
        self.items.sort(key=lambda r: min(r.members))
        self.of_element = {a: g for g, r in enumerate(self.items) for a in r.members}

    def _size(self, members: list[int]) -> int:
        return int(np.prod([self.shape[a] for a in members], dtype=object))

    def _run(self, members: list[int], word: np.ndarray, stride: np.ndarray) -> Run:
        base = int(stride[members[0]])
        return Run(int(word[members[0]]), base, self._size(members), sorted(members),
                   [int(stride[a]) // base for a in sorted(members)])

    @staticmethod
    def index(run: Run, words: list[np.ndarray]) -> np.ndarray:
        """The joint index of ``run`` at each state (``words``: each word's column)."""
        return (words[run.word] // run.base) % run.size

    def local(self, g: int) -> np.ndarray:
        """Each joint index of run ``g``: its members' local indices (size × members)."""
        run = self.items[g]
        c = np.arange(run.size, dtype=np.int64)[:, None]
        return (c // np.array(run.subs)) % np.array([self.shape[a] for a in run.members])


_BIT = np.left_shift(np.int64(1), np.arange(BITS, dtype=np.int64))


def pack(bits: np.ndarray) -> np.ndarray:
    """Boolean columns (n × k) as ``int64`` words of 63 bits (n × words): a word is the
    sum of its distinct bits, one product per word."""
    n, k = bits.shape
    out = np.zeros((n, max(1, -(-k // BITS))), dtype=np.int64)
    for w in range(0, k, BITS):
        part = bits[:, w:w + BITS]
        out[:, w // BITS] = part.astype(np.int64) @ _BIT[:part.shape[1]]
    return out


def unpack(words: np.ndarray, k: int) -> np.ndarray:
    """The first ``k`` bits of words (n × words) as Boolean columns (n × k): only those
    ``k`` bits are read (one pass when they fit one word)."""
    if words.shape[1] == 1:
        return (words & _BIT[:k]) != 0
    j = np.arange(k, dtype=np.int64)
    return (words[:, j // BITS] & _BIT[j % BITS]) != 0


class Masks:
    """Bits of states from per-element tables (``tables[a]``: element ``a``'s local
    states × ``k`` bits), combined by AND (``conj``; an element without a table: all
    bits true) or OR (no table: all false), a run's table per run."""

    def __init__(self, runs: Runs, tables: dict[int, np.ndarray], k: int, conj: bool) -> None:
        self.k, self.conj = k, conj
        self.identity = pack(np.full((1, k), conj, dtype=bool))[0]
        self.tables: list[tuple[int, np.ndarray]] = []
        for g, run in enumerate(runs.items):
            mine = [(j, pack(tables[a])) for j, a in enumerate(run.members) if a in tables]  # packed per element
            if not mine:
                continue
            local = runs.local(g)
            joint: np.ndarray | None = None
            for j, t in mine:  # the members' packed words combined at each joint index
                v = t[local[:, j]]
                joint = v if joint is None else (joint & v if conj else joint | v)
            assert joint is not None
            self.tables.append((g, joint))

    def of(self, index: Callable[[int], np.ndarray], n: int) -> np.ndarray:
        """The packed bits (n × words) of states whose run ``g`` has joint index ``index(g)``."""
        out: np.ndarray | None = None
        for g, table in self.tables:
            v = table[index(g)]
            out = v if out is None else (out & v if self.conj else out | v)
        if out is None:
            return np.tile(self.identity, (n, 1))
        return out
