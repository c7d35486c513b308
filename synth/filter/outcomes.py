"""The outcomes of one PLC cycle in ``synth filter verify``'s exploration: an outcome
(the orders written, the memory after the cycle, the flags), the arrays over every
outcome found so far, and the lane masks of :meth:`~synth.filter.cycle.FilterCycle.lanes`
as numpy arrays.

Example
-------
>>> unpack(0b0110, 4).tolist(), lane_bits(1, 4)
([False, True, True, False], 12)
>>> arrays = OutcomeArrays(2)
>>> oc = Outcome((True, False), 0, False, False, (True, True), ("K",))
>>> targets, fallback, outside, aux, requests = arrays.update([oc])
>>> targets.tolist(), requests.tolist()
([[True, False]], [[True, True]])
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Sequence

import numpy as np

__all__ = ["Outcome", "OutcomeArrays", "unpack", "lane_bits"]


@dataclass(frozen=True)
class Outcome:
    """What one cycle does to the product; the requests are one witness (not compared:
    request vectors that give the same outputs, memory and flags are one outcome)."""

    targets: tuple[bool, ...]  # every plant order, in plant output order
    aux: int
    fallback: bool
    outside_care: bool
    requests: tuple[bool, ...] = field(compare=False)  # every plant order's request
    violated: tuple[str, ...] = field(compare=False)  # filter constraints the requests violate


def unpack(mask: int, count: int) -> np.ndarray:
    """A lane mask as a bool array (lane j at index j)."""
    raw = np.frombuffer(mask.to_bytes((count + 7) // 8, "little"), dtype=np.uint8)
    return np.unpackbits(raw, bitorder="little")[:count].astype(bool)


def lane_bits(i: int, count: int) -> int:
    """The lanes where free name ``i`` is true (bit i of the lane number)."""
    return sum(1 << j for j in range(count) if (j >> i) & 1)


class OutcomeArrays:
    """Arrays over the outcomes found so far, extended with the new ones only."""

    def __init__(self, width: int) -> None:
        self.targets = np.zeros((0, width), dtype=bool)
        self.fallback = np.zeros(0, dtype=bool)
        self.outside = np.zeros(0, dtype=bool)
        self.aux = np.zeros(0, dtype=np.int64)
        self.requests = np.zeros((0, width), dtype=bool)

    def update(self, outcomes: Sequence[Outcome]
               ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        new = outcomes[self.aux.size:]
        if new:
            self.requests = np.concatenate((self.requests, np.array([o.requests for o in new], dtype=bool)
                                            .reshape(len(new), self.requests.shape[1])))
            self.targets = np.concatenate((self.targets, np.array([o.targets for o in new], dtype=bool)
                                           .reshape(len(new), self.targets.shape[1])))
            self.fallback = np.concatenate((self.fallback, np.array([o.fallback for o in new], dtype=bool)))
            self.outside = np.concatenate((self.outside, np.array([o.outside_care for o in new], dtype=bool)))
            self.aux = np.concatenate((self.aux, np.array([o.aux for o in new], dtype=np.int64)))
        return self.targets, self.fallback, self.outside, self.aux, self.requests
