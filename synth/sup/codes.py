"""Dense codes for SUP's exploration: a mixed-radix code over the local states that SUP
can hold (:class:`Layout`), read in groups of digits through small tables, and a bitmap of
the codes met, allocated block by block (:class:`Visited`).

Example
-------
>>> import numpy as np
>>> lay = Layout([np.array([True, False, True]), np.array([True, True])], (2, 1))
>>> lay.size, lay.plant_codes(np.arange(4)).tolist()
(4, [0, 1, 4, 5])
"""

from __future__ import annotations

from typing import Sequence

import numpy as np

__all__ = ["Layout", "Visited", "GROUP_BITS"]

GROUP_BITS = 16
"""Consecutive digits are read together while their codes number at most 2^GROUP_BITS."""

_ONES = np.array([bin(b).count("1") for b in range(256)], dtype=np.uint8)  # set bits per byte value
_LOWEST = np.array([(b & -b).bit_length() - 1 for b in range(256)], dtype=np.int64)  # its lowest set bit


class Layout:
    """The code of the states whose local states are all in ``kept`` (one boolean array
    per element): mixed radix, the elements' order and the plant's, so sorted codes are
    sorted plant codes. Its digits form *groups* of consecutive elements; a state's group
    codes give each digit (``digit_table``) and its plant code (``plant_part``) by lookups."""

    def __init__(self, kept: Sequence[np.ndarray], strides: Sequence[int]) -> None:
        self.local = [np.flatnonzero(k) for k in kept]  # digit -> local state, per element
        self.radices = [int(loc.size) for loc in self.local]
        self.size = 1
        for r in self.radices:
            self.size *= r
        groups: list[list[int]] = []
        for a in reversed(range(len(self.radices))):
            if groups and self._modulus(groups[-1]) * self.radices[a] <= 1 << GROUP_BITS:
                groups[-1].insert(0, a)
            else:
                groups.append([a])
        self.groups = groups  # least significant first
        self.moduli = [self._modulus(g) for g in groups]
        self.group_of = {a: g for g, axes in enumerate(groups) for a in axes}
        self.digit_table: dict[int, np.ndarray] = {}
        self.plant_part: list[np.ndarray] = []
        self.offsets: dict[int, int] = {}  # the code's stride of each digit
        stride = 1
        for g, axes in enumerate(groups):
            inner = 1
            code = np.arange(self.moduli[g], dtype=np.int64)
            part = np.zeros(self.moduli[g], dtype=np.int64)
            for a in reversed(axes):
                self.digit_table[a] = self.local[a][(code // inner) % self.radices[a]]
                part += self.digit_table[a] * strides[a]
                self.offsets[a] = stride * inner
                inner *= self.radices[a]
            self.plant_part.append(part)
            stride *= inner

    def _modulus(self, axes: Sequence[int]) -> int:
        out = 1
        for a in axes:
            out *= self.radices[a]
        return out

    def code(self, local: Sequence[int]) -> int | None:
        """The code of a plant state (its local states), None if one is not kept."""
        code = 0
        for loc, k, (a, stride) in zip(self.local, local, sorted(self.offsets.items())):
            pos = np.flatnonzero(loc == k)
            if not pos.size:
                return None
            code += int(pos[0]) * stride
        return code

    def split(self, codes: np.ndarray) -> list[np.ndarray]:
        """The group codes of each code, least significant group first."""
        out: list[np.ndarray] = []
        q = codes
        for m in self.moduli[:-1]:
            up = q // m
            out.append(q - up * m)
            q = up
        out.append(q)
        return out

    def plant_codes(self, codes: np.ndarray) -> np.ndarray:
        out = np.zeros(codes.shape, dtype=np.int64)
        for part, group in zip(self.plant_part, self.split(codes)):
            out += part[group]
        return out


class Visited:
    """A set of codes in ``[0, size)``: a bitmap cut in blocks of ``2^shift`` codes, one
    block allocated per block of codes met, so memory follows the set, not ``size``. A
    set of at most :data:`FLAT_BITS` codes has one block; blocks are found through a
    table of at most :data:`MAX_TABLE` entries, or past that (codes of more than
    ``2^(MAX_SHIFT + log2 MAX_TABLE)`` values) by a binary search among the blocks met.

    >>> v = Visited(10**12)
    >>> v.add(np.array([5, 7, 3 * 10**6 + 1], dtype=np.int64))
    >>> v.test(np.array([5, 6, 7, 3 * 10**6 + 1], dtype=np.int64)).tolist(), v.blocks
    ([True, False, True, True], 2)
    >>> v.codes().tolist()
    [5, 7, 3000001]
    """

    FLAT_BITS = 1 << 27
    MIN_SHIFT = 13
    MAX_SHIFT = 16
    MAX_TABLE = 1 << 24

    def __init__(self, size: int) -> None:
        bits = max(size - 1, 1).bit_length()
        # a block holds at least one byte (8 codes): a plant of fewer than 8 codes has one block
        self.shift = max(3, bits) if size <= self.FLAT_BITS else max(self.MIN_SHIFT, bits - self.MAX_TABLE.bit_length() + 1)
        self.table: np.ndarray | None = None  # per block, the offset of its bytes (0: the empty block)
        if self.shift <= self.MAX_SHIFT or size <= self.FLAT_BITS:
            self.table = np.zeros(((size - 1) >> self.shift) + 1, dtype=np.int32)  # int64 past 2 GiB of bits
        else:
            self.shift = self.MAX_SHIFT
        self.met = np.array([-1], dtype=np.int64)  # without the table: the blocks met, sorted
        self.offsets = np.zeros(1, dtype=np.int64)  # and their offsets
        self.row_bytes = (1 << self.shift) // 8
        self.bits = np.zeros(2 * self.row_bytes, dtype=np.uint8)
        self.rows = 1

    @property
    def blocks(self) -> int:
        """Blocks allocated."""
        return self.rows - 1

    def _offset(self, blocks: np.ndarray) -> np.ndarray:
        if self.table is not None:
            return self.table[blocks]
        pos = np.minimum(np.searchsorted(self.met, blocks), self.met.size - 1)
        return np.where(self.met[pos] == blocks, self.offsets[pos], 0)

    def _index(self, codes: np.ndarray) -> np.ndarray:
        """The byte of each code (codes in unallocated blocks read the empty block)."""
        return self._offset(codes >> self.shift) + ((codes >> 3) & (self.row_bytes - 1))

    def test(self, codes: np.ndarray) -> np.ndarray:
        byte = self.bits[self._index(codes)]
        np.right_shift(byte, np.bitwise_and(codes, 7, dtype=np.uint8, casting="unsafe"), out=byte)
        return np.bitwise_and(byte, 1, out=byte).view(bool)

    def add(self, codes: np.ndarray) -> None:
        """Add sorted, distinct codes."""
        if not codes.size:
            return
        blocks = codes >> self.shift
        new = blocks[np.concatenate(([True], blocks[1:] != blocks[:-1]))]
        new = new[self._offset(new) == 0]
        if new.size:
            need = (self.rows + new.size) * self.row_bytes
            if need > self.bits.size:
                grown = np.zeros(max(need, 2 * self.bits.size), dtype=np.uint8)
                grown[:self.bits.size] = self.bits
                self.bits = grown
            offsets = np.arange(self.rows, self.rows + new.size, dtype=np.int64) * self.row_bytes
            if self.table is not None:
                if self.bits.size >= 1 << 31:
                    self.table = self.table.astype(np.int64)
                self.table[new] = offsets
            else:
                met, at = np.concatenate([self.met, new]), np.concatenate([self.offsets, offsets])
                order = np.argsort(met, kind="stable")
                self.met, self.offsets = met[order], at[order]
            self.rows += new.size
        byte = self._index(codes)
        starts = np.flatnonzero(np.concatenate(([True], byte[1:] != byte[:-1])))
        self.bits[byte[starts]] |= np.bitwise_or.reduceat(np.left_shift(1, codes & 7).astype(np.uint8), starts)

    SLICE = 1 << 13
    """Bytes of the bitmap unpacked at once by :meth:`codes` (per block, at most)."""

    def codes(self) -> np.ndarray:
        """Every code in the set, sorted (no array of the set's size but the result)."""
        if self.table is not None:
            blocks = np.flatnonzero(self.table)
            offsets = self.table[blocks].astype(np.int64)
        else:
            blocks, offsets = self.met[1:], self.offsets[1:]
        step = min(self.row_bytes, self.SLICE)  # a block read in slices of ``step`` bytes
        shift = step.bit_length() - 1
        per = self.row_bytes // step
        starts = ((blocks << self.shift)[:, None] + np.arange(per, dtype=np.int64)[None, :] * (8 * step)).reshape(-1)
        at = (offsets[:, None] + np.arange(per, dtype=np.int64)[None, :] * step).reshape(-1)
        slices = self.bits[:self.rows * self.row_bytes].reshape(-1, step)
        out = np.empty(int(_ONES[slices].sum(dtype=np.int64)), dtype=np.int64)
        n = 0
        for lo in range(0, at.size, 1024):
            flat = slices[at[lo:lo + 1024] // step].reshape(-1)  # the slices' bytes, in code order
            nz = np.flatnonzero(flat)
            values = flat[nz]
            base = starts[lo:lo + 1024][nz >> shift] + ((nz & (step - 1)) << 3)  # the code of each byte's bit 0
            count = _ONES[values].astype(np.int64)
            pos = n + np.cumsum(count) - count  # where each byte's codes go, lowest bit first
            n += int(count.sum())
            while values.size:
                out[pos] = base + _LOWEST[values]
                values = values & (values - 1)
                more = values != 0
                values, base, pos = values[more], base[more], pos[more] + 1
        return out

