"""Plant states past one machine word: the frontier explorer's codes for wide plants.

A plant of 2^40 states or more (twelve cylinders and up) has flat codes that do not fit
the explorer's 64-bit keys (situation × plant), and from 2^63 on not even an ``int64``.
Its states are then written in ``W`` words: the elements are cut, in declaration order,
into groups whose product of sizes fits 62 bits, each group a mixed-radix word
(:class:`Layout`); a move changes one element, hence adds one offset to one word. The
states actually met are numbered densely in the order they are first met
(:class:`Interned`), and that number is the state's code in the explorer: its keys stay
(situation, code) with codes below 2^32.

Words are found again through sorted integer keys: the word itself when ``W`` is 1, else
a 64-bit mix of the words, every look-up checked against the stored words (two different
states that mix to the same key raise :class:`Collision`: the explorer then leaves the
model to the machine's path, which gives the same result).

Example
-------
>>> lay = Layout((2, 12, 12), limit=5)  # 2 * 12 fits 5 bits, 2 * 12 * 12 does not
>>> lay.count, lay.word.tolist(), lay.stride.tolist()
(2, [0, 0, 1], [1, 2, 1])
>>> ids = Interned(lay.count)
>>> ids.find_or_add(lay.encode(np.array([[1, 3, 4], [0, 0, 0], [1, 3, 4]]))).tolist()
[0, 1, 0]
>>> lay.decode(ids.words[np.array([0])]).tolist()
[[1, 3, 4]]
"""

from __future__ import annotations

import numpy as np

from synth.validation.keys import Collision, SortedKeys, first_occurrences

__all__ = ["Layout", "Interned", "Collision", "CAPACITY"]

CAPACITY = 1 << 32
"""Dense codes of a wide plant stay below this (the explorer's keys: situation × code)."""

_MIX = np.array([0x9E3779B97F4A7C15, 0xC2B2AE3D27D4EB4F, 0x165667B19E3779F9, 0x27D4EB2F165667C5,
                 0x94D049BB133111EB, 0xBF58476D1CE4E5B9, 0xFF51AFD7ED558CCD, 0xC4CEB9FE1A85EC53], dtype=np.uint64)


class Layout:
    """The elements (sizes ``shape``) cut into words of at most ``limit`` bits, in order:
    each element's word and stride inside it."""

    def __init__(self, shape: tuple[int, ...], limit: int = 62) -> None:
        word: list[int] = []
        stride: list[int] = []
        filled: list[int] = []
        for n in shape:
            if not filled or filled[-1] * n > 1 << limit:
                filled.append(1)
            word.append(len(filled) - 1)
            stride.append(filled[-1])
            filled[-1] *= n
        self.count = max(len(filled), 1)
        self.word = np.array(word, dtype=np.int64)
        self.stride = np.array(stride, dtype=np.int64)
        self.shape = np.array(shape, dtype=np.int64)

    def encode(self, local: np.ndarray) -> np.ndarray:
        """The words (n × count) of element-local indices (n × elements)."""
        out = np.zeros((len(local), self.count), dtype=np.int64)
        for w in range(self.count):
            at = np.flatnonzero(self.word == w)
            out[:, w] = local[:, at] @ self.stride[at]
        return out

    def decode(self, words: np.ndarray) -> np.ndarray:
        """The element-local indices (n × elements) of words (n × count)."""
        return (words[:, self.word] // self.stride) % self.shape


class Interned:
    """Words (``width`` int64 each) numbered densely in the order first met."""

    def __init__(self, width: int) -> None:
        self.width = width
        self._words = np.empty((1024, width), dtype=np.int64)
        self.count = 0
        self._keys = SortedKeys()

    @property
    def words(self) -> np.ndarray:
        """The words of codes ``0 .. count - 1``, one row each."""
        return self._words[:self.count]

    def _key(self, words: np.ndarray) -> np.ndarray:
        if self.width == 1:
            return words[:, 0]
        h = np.zeros(len(words), dtype=np.uint64)
        with np.errstate(over="ignore"):
            for w in range(self.width):
                h ^= words[:, w].astype(np.uint64) * _MIX[w % len(_MIX)]
                h ^= h >> np.uint64(29)
        return h.view(np.int64)

    def find_or_add(self, words: np.ndarray) -> np.ndarray:
        """The code of each row of ``words``, new rows numbered in the order they come."""
        keys = self._key(words)
        found = self._keys.find(keys)
        miss = np.flatnonzero(found < 0)
        if miss.size:
            first = miss[first_occurrences(keys[miss])]
            ids = self.count + np.arange(first.size)
            if self.count + first.size > CAPACITY:
                raise Collision(f"more than {CAPACITY} plant states")
            self._grow(self.count + first.size)
            self._words[ids] = words[first]
            self.count += first.size
            self._keys.add(keys[first], ids)
            found = self._keys.find(keys)
        if self.width > 1 and not (self._words[found] == words).all():
            raise Collision("two plant states under one key")
        return found

    def _grow(self, need: int) -> None:
        if need > len(self._words):
            bigger = np.empty((max(need, 2 * len(self._words)), self.width), dtype=np.int64)
            bigger[:self.count] = self._words[:self.count]
            self._words = bigger
