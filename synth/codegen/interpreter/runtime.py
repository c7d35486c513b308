"""What the ST interpreter runs: arrays, declared variables, compiled POUs and their instances.

A :class:`Pou` is a PROGRAM or FUNCTION_BLOCK compiled into a closure over an
:class:`Instance` (its variables by name, case-insensitive as in IEC 61131-3); an instance of
a standard function block (``TON``, ``R_TRIG``, …) runs :mod:`synth.codegen.interpreter.standard`.
Instances reach their clock and the other POUs through a :class:`Host` (the loaded module).

Example
-------
>>> a = Array(((1, 2), (0, 1)), [False] * 4)
>>> a[2, 1] = True
>>> a.items
[False, False, False, True]
>>> a.offset((1, 1))
1
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property
from enum import StrEnum
from typing import Any, Callable, Mapping, Protocol

from synth.codegen.interpreter.standard import STANDARD_FBS

__all__ = ["Value", "Thunk", "Action", "VarSection", "Array", "Variable", "Pou", "Host", "Instance",
           "LoopExit", "BodyReturn"]

Value = Any  # bool | int | Array | Instance
Thunk = Callable[["Instance"], Value]  # an expression compiled
Action = Callable[["Instance"], None]  # a statement compiled


class VarSection(StrEnum):
    """The declaration block a variable comes from."""

    LOCAL = "VAR"
    INPUT = "VAR_INPUT"
    OUTPUT = "VAR_OUTPUT"
    IN_OUT = "VAR_IN_OUT"
    GLOBAL = "VAR_GLOBAL"
    TEMP = "VAR_TEMP"  # initialised again at every call: no memory from one scan to the next


class LoopExit(Exception):
    """``EXIT``: leave the innermost loop."""


class BodyReturn(Exception):
    """``RETURN``: leave the body."""


class Array:
    """An ST array: bounds per dimension and a flat list of values."""

    __slots__ = ("bounds", "items")

    def __init__(self, bounds: tuple[tuple[int, int], ...], items: list[Value]) -> None:
        self.bounds = bounds
        self.items = items

    def offset(self, index: tuple[int, ...]) -> int:
        if len(index) != len(self.bounds):
            raise IndexError(f"{len(index)} subscripts for {len(self.bounds)} dimensions")
        flat = 0
        for i, (lo, hi) in zip(index, self.bounds):
            if not lo <= i <= hi:
                raise IndexError(f"subscript {i} outside [{lo}..{hi}]")
            flat = flat * (hi - lo + 1) + (i - lo)
        return flat

    def __getitem__(self, index: tuple[int, ...]) -> Value:
        return self.items[self.offset(index)]

    def __setitem__(self, index: tuple[int, ...], value: Value) -> None:
        self.items[self.offset(index)] = value

    def copy(self) -> Array:
        return Array(self.bounds, list(self.items))

    def __eq__(self, other: object) -> bool:
        return isinstance(other, Array) and (self.bounds, self.items) == (other.bounds, other.items)

    def __repr__(self) -> str:
        return f"Array({self.bounds}, {self.items})"


class Host(Protocol):
    """What an instance needs from the module that made it: the clock (ms) and new instances."""

    @property
    def clock_ms(self) -> int: ...

    def instance(self, name: str) -> Instance: ...


@dataclass(frozen=True)
class Variable:
    """A declared variable: its section, type name (``BOOL``, ``TON``, ``FB_X``, ``ARRAY``), initial value maker."""

    name: str
    section: VarSection
    type: str
    initial: Callable[[Host], Value]
    constant: bool = False


@dataclass(frozen=True)
class Pou:
    """A compiled PROGRAM or FUNCTION_BLOCK."""

    name: str
    kind: str  # "PROGRAM" | "FUNCTION_BLOCK"
    variables: tuple[Variable, ...]
    body: Action

    @cached_property
    def temporaries(self) -> tuple[Variable, ...]:
        """The ``VAR_TEMP`` variables, initialised again at every call."""
        return tuple(v for v in self.variables if v.section is VarSection.TEMP)

    def variable(self, name: str) -> Variable | None:
        for v in self.variables:
            if v.name.upper() == name.upper():
                return v
        return None


class Instance:
    """One instance of a POU (or of a standard function block) with its variables.

    Names are case-insensitive, as in IEC 61131-3; :attr:`values` keeps declared spelling.
    """

    def __init__(self, module: Host, pou: Pou | None, type_name: str, values: dict[str, Value]) -> None:
        self.module = module
        self.pou = pou
        self.type = type_name
        self.values = values
        self._keys = {k.upper(): k for k in values}
        self.memory: dict[str, Any] = {}  # a standard function block's hidden memory (a timer's start)

    def key(self, name: str) -> str:
        try:
            return self._keys[name.upper()]
        except KeyError:
            raise KeyError(f"{self.type} has no variable {name}") from None

    def __getitem__(self, name: str) -> Value:
        return self.values[self.key(name)]

    def __setitem__(self, name: str, value: Value) -> None:
        self.values[self.key(name)] = value

    def __contains__(self, name: str) -> bool:
        return name.upper() in self._keys

    def cycle(self, inputs: Mapping[str, Value] | None = None) -> Instance:
        """Set the given variables (inputs, usually), then run the body once."""
        for k, v in (inputs or {}).items():
            self[k] = v
        self.run()
        return self

    def run(self) -> None:
        if self.pou is not None:
            for v in self.pou.temporaries:
                self.values[v.name] = v.initial(self.module)
            try:
                self.pou.body(self)
            except BodyReturn:
                pass
        else:
            STANDARD_FBS[self.type].step(self.values, self.memory, self.module.clock_ms)
