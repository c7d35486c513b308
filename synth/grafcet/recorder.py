"""Input values that remember which names the Grafcet machine read.

The machine (:class:`~synth.grafcet.machine.GrafcetMachine`) is deterministic, so its
answer on one valuation holds for every valuation that agrees on the inputs it read:
the ASS (:mod:`synth.grafcet.ass`) and the symbolic SYNC (:mod:`synth.symbolic`) each
run it once for a whole cube of valuations. The values are fetched only when the
machine first looks at one (a situation whose answer reads no input costs no fetch).

Example
-------
>>> rec = InputRecorder(lambda: {"a": True, "b": False})
>>> rec["a"], "b" in rec, rec.read
(True, True, {'a'})
>>> rec.cell()
{'a': True}
"""

from __future__ import annotations

from collections.abc import ItemsView, Iterator, Mapping, ValuesView
from typing import Callable

__all__ = ["InputRecorder"]


class InputRecorder(Mapping[str, bool]):
    """The values ``fetch()`` returns, fetched on first use; ``read`` holds the names
    looked up (a membership test reads nothing; ``items()`` and ``values()`` read all)."""

    __slots__ = ("read", "_values", "_fetch")

    def __init__(self, fetch: Callable[[], Mapping[str, bool]]) -> None:
        self.read: set[str] = set()
        self._values: Mapping[str, bool] | None = None
        self._fetch = fetch

    def _load(self) -> Mapping[str, bool]:
        if self._values is None:
            self._values = self._fetch()
        return self._values

    def __getitem__(self, name: str) -> bool:
        value = self._load()[name]
        self.read.add(name)
        return value

    def __contains__(self, name: object) -> bool:
        return name in self._load()

    def __iter__(self) -> Iterator[str]:
        return iter(self._load())

    def __len__(self) -> int:
        return len(self._load())

    def items(self) -> ItemsView[str, bool]:
        self.read.update(self._load())
        return self._load().items()

    def values(self) -> ValuesView[bool]:
        self.read.update(self._load())
        return self._load().values()

    def cell(self) -> dict[str, bool]:
        """The values of the names read, by name: the cube on which the answer holds."""
        values = self._load()
        return {n: values[n] for n in sorted(self.read)}
