"""``synth filter verify --control PROG.st[:NAME]``: the requests of each scan computed by a
cyclic IEC 61131-3 PROGRAM, run by synth's ST interpreter (:mod:`synth.codegen.interpreter.machine`,
on blark's parse tree, whose ``load_st`` the caller gives in a :class:`StSource`) -- what
runs is what is verified.

One scan: the PROGRAM's ``VAR_INPUT`` s named like a plant input get that input's value (a
plant input the program does not declare is not given), one cycle runs, and the
``VAR_OUTPUT`` s named like the plant's outputs are the requests (a filter output the program
lacks is an error located at ``--control``; a pass-through plant output it lacks is 0).

The program's whole state is part of the closed loop's state: a :class:`Snapshot` is the
instance after a scan, compared by the canonical tuple of every variable (nested function
block instances, arrays, and the hidden memory of ``TON``/``TOF``/``TP``/``R_TRIG``/...) but
those no scan reads before writing them: the ``VAR_INPUT`` s the loop gives and the
``VAR_TEMP`` s (initialised again at every call; the ST synth generates keeps its evolution's
bookkeeping there). The
PLC clock does not advance; a *running* timer (``TON``/``TP`` started, ``TOF`` falling, its
preset not reached) may instead **elapse** as a cycle's event, like a Grafcet's ``2s/X1``: its
start is moved back by its preset, then one scan runs with the inputs unchanged. So a timer's
duration is abstracted (it elapses after any number of scans) and the state space is finite
when the program's variables are.

Example
-------
>>> split_control("ctl.st:Main"), split_control("ctl.st"), split_control("c:/x.st")
(('ctl.st', 'Main'), ('ctl.st', None), ('c:/x.st', None))
"""

from __future__ import annotations

import copy
import re
from dataclasses import dataclass, field
from typing import Any, Callable, Mapping, Protocol, Sequence

from synth.errors import InputError, Location, close_names

__all__ = ["CONTROL_OPTION", "TIMER_PREFIX", "split_control", "StVariable", "StPou", "StClock", "StInstance", "StModule",
           "StSource", "Snapshot", "StControl"]


# What is used of synth.codegen.interpreter.machine (synth.filter lies below synth.codegen: the caller
# gives its load_st, see StSource).
class StVariable(Protocol):
    """A declared variable of a POU."""

    @property
    def name(self) -> str: ...
    @property
    def section(self) -> str: ...  # "VAR", "VAR_INPUT", "VAR_OUTPUT", ...
    @property
    def type(self) -> str: ...
    @property
    def constant(self) -> bool: ...


class StPou(Protocol):
    """A compiled PROGRAM or FUNCTION_BLOCK."""

    @property
    def name(self) -> str: ...
    @property
    def kind(self) -> str: ...
    @property
    def variables(self) -> Sequence[StVariable]: ...
    def variable(self, name: str) -> StVariable | None: ...


class StClock(Protocol):
    """What an instance reads of its module: the clock (ms) of its timers."""

    @property
    def clock_ms(self) -> int: ...


class StInstance(Protocol):
    """An instance: its variables by name (case-insensitive) and a cycle."""

    @property
    def pou(self) -> StPou | None: ...
    @property
    def type(self) -> str: ...
    @property
    def values(self) -> dict[str, Any]: ...
    @property
    def memory(self) -> dict[str, Any]: ...
    @property
    def module(self) -> StClock: ...
    def __getitem__(self, name: str) -> Any: ...
    def cycle(self, inputs: Mapping[str, Any] | None = None) -> object: ...


class StModule(Protocol):
    """The POUs of one ST text and the clock of their timers."""

    @property
    def pous(self) -> Mapping[str, StPou]: ...
    @property
    def clock_ms(self) -> int: ...
    def instance(self, name: str) -> StInstance: ...


@dataclass(frozen=True)
class StSource:
    """``--control PROG.st[:NAME]`` and the function that parses and compiles ST text
    (``synth.codegen.interpreter.machine.load_st``: ``load(text, file)``)."""

    option: str
    load: Callable[[str, str], StModule]


CONTROL_OPTION = "--control"
"""The file name of the errors located at the ``--control`` option's text."""

TIMER_PREFIX = "timer "
"""A cycle's event where a running timer elapses: ``timer _Tmr1 (T#2s)``."""

_TIMERS = {"TON": "start", "TP": "start", "TOF": "fall"}  # the hidden memory of when it started
_NAME = re.compile(r"[A-Za-z_][A-Za-z0-9_]*")


def split_control(text: str) -> tuple[str, str | None]:
    """``PROG.st:NAME`` as (file, NAME); ``PROG.st`` as (file, None)."""
    path, sep, name = text.rpartition(":")
    if sep and path and _NAME.fullmatch(name):
        return path, name
    return text, None


def _at(option: str, column: int = 1, width: int = 0) -> Location:
    return Location(CONTROL_OPTION, 1, column, option, width or max(1, len(option) - column + 1))


def _is_instance(x: Any) -> bool:
    return hasattr(x, "memory") and hasattr(x, "values")


def _canon(x: Any) -> Any:
    """A hashable value of an ST value: instances by their variables and hidden memory, arrays by their items."""
    if _is_instance(x):
        return tuple(_canon(v) for v in x.values.values()), tuple(sorted(x.memory.items()))
    if hasattr(x, "bounds") and hasattr(x, "items"):
        return tuple(x.items)
    return x


def _ms_text(ms: int) -> str:
    return f"T#{ms // 1000}s" if ms % 1000 == 0 else f"T#{ms}ms"


@dataclass(frozen=True, eq=False)
class Snapshot:
    """The program's instance after a scan, equal to another by its canonical variables."""

    key: tuple
    instance: StInstance = field(repr=False)

    def __eq__(self, other: object) -> bool:
        return isinstance(other, Snapshot) and self.key == other.key

    def __hash__(self) -> int:
        return hash(self.key)

    def text(self) -> str:
        """The program's ``VAR`` variables: the true BOOLs, the non-zero numbers, the timers
        that run or have elapsed (the situation column of a trace)."""
        inst, parts = self.instance, []
        assert inst.pou is not None
        for v in inst.pou.variables:
            x = inst.values[v.name]
            if v.section != "VAR" or v.constant:
                continue
            if isinstance(x, bool):
                parts += [v.name] if x else []
            elif isinstance(x, int):
                parts += [f"{v.name}={x}"] if x else []
            elif _is_instance(x) and x.type in _TIMERS and _TIMERS[x.type] in x.memory:
                since = inst.module.clock_ms - x.memory[_TIMERS[x.type]]
                parts.append(f"{v.name} {'elapsed' if since >= int(x.values['PT']) else 'running'}")
        return "{" + ", ".join(parts) + "}"


class StControl:
    """The PROGRAM of ``option`` (``PROG.st`` or ``PROG.st:NAME``) wired to the plant's
    ``inputs`` and ``outputs``; ``required``: the filter's outputs (the program must have them)."""

    def __init__(self, source: StSource, inputs: Sequence[str], outputs: Sequence[str], required: Sequence[str],
                 filter_file: str) -> None:
        from synth.syntax import read_source

        self.option = option = source.option
        self.file, name = split_control(option)
        text = read_source(self.file, _at(option, 1, len(self.file)))
        self.module = source.load(text, self.file)
        pou = self._program(name, option)
        self.program = pou.name
        self.memo: dict[int, object] = {id(self.module): self.module}
        self.memo.update({id(p): p for p in self.module.pous.values()})
        self.inputs: dict[str, str] = {}  # plant input -> the VAR_INPUT given its value
        for n in inputs:
            v = pou.variable(n)
            if v is not None and v.section == "VAR_INPUT":
                self._bool(v.name, v.type, "VAR_INPUT")
                self.inputs[n] = v.name
        self.outputs: dict[str, str] = {}  # plant output -> the VAR_OUTPUT read as its request
        for o in outputs:
            v = pou.variable(o)
            if v is not None and v.section == "VAR_OUTPUT":
                self._bool(v.name, v.type, "VAR_OUTPUT")
                self.outputs[o] = v.name
            elif o in required:
                have = [w.name for w in pou.variables if w.section == "VAR_OUTPUT"]
                how = "no VAR_OUTPUT" if v is None else f"{v.name} in {v.section}, not in VAR_OUTPUT, and no VAR_OUTPUT"
                raise InputError(f"PROGRAM {pou.name} of {self.file} has {how} {o}: the request of the output {o} "
                                 f"of {filter_file}", _at(option), suggestions=close_names(o, have))
        self.observable = frozenset(v.name.upper() for v in pou.variables if v.type == "BOOL" and not v.constant)
        self.pou = pou
        # written before they are read in every scan: the VAR_INPUTs the loop gives, the VAR_TEMPs
        given = {v.upper() for v in self.inputs.values()}
        self.rewritten = tuple(v.section == "VAR_TEMP" or v.name.upper() in given for v in pou.variables)
        self.known: dict[tuple, Snapshot] = {}

    def _program(self, name: str | None, option: str) -> StPou:
        programs = {p.name.upper(): p for p in self.module.pous.values() if p.kind == "PROGRAM"}
        listed = ", ".join(p.name for p in programs.values())
        if name is not None:
            found = programs.get(name.upper())
            if found is None:
                where = "none" if not programs else listed
                raise InputError(f"no PROGRAM {name} in {self.file} (its PROGRAMs: {where})",
                                 _at(option, len(option) - len(name) + 1, len(name)),
                                 suggestions=close_names(name, [p.name for p in programs.values()]))
            return found
        if len(programs) == 1:
            return next(iter(programs.values()))
        if not programs:
            raise InputError(f"{self.file} has no PROGRAM: --control runs a cyclic PROGRAM (its POUs: "
                             f"{', '.join(self.module.pous) or 'none'})", _at(option))
        raise InputError(f"{self.file} has {len(programs)} PROGRAMs ({listed}): name one, "
                         f"{CONTROL_OPTION} {self.file}:NAME", _at(option))

    def _bool(self, name: str, type_name: str, section: str) -> None:
        if type_name != "BOOL":
            raise InputError(f"{section} {name} of PROGRAM {self.program} is {type_name}: a plant's signal is a "
                             "BOOL", _at(self.option))

    # ------------------------------------------------------------------ the closed loop's side
    def snapshot(self, inst: StInstance) -> Snapshot:
        values, state = _canon(inst)  # the program's own variables, but for what no scan reads before writing
        key = tuple(x for x, skip in zip(values, self.rewritten) if not skip), state
        snap = self.known.get(key)
        if snap is None:
            snap = self.known[key] = Snapshot(key, inst)
        return snap

    def initial(self) -> Snapshot:
        """A fresh instance (no scan has run)."""
        return self.snapshot(self.module.instance(self.program))

    def copy(self, snap: Snapshot) -> StInstance:
        """A copy of the instance of ``snap`` (the module and its POUs shared)."""
        inst: StInstance = copy.deepcopy(snap.instance, dict(self.memo))
        return inst

    def react(self, snap: Snapshot, events: tuple[str, ...], inputs: Mapping[str, bool]) -> Snapshot:
        """The instance after one scan on ``inputs`` (plant names); when ``events`` is one
        timer's, that timer elapses first."""
        inst = self.copy(snap)
        if len(events) == 1 and events[0].startswith(TIMER_PREFIX):
            fb = self._timers(inst)[events[0]]
            fb.memory[_TIMERS[fb.type]] = self.module.clock_ms - int(fb.values["PT"])
        given = {self.inputs[n]: v for n, v in inputs.items() if n in self.inputs}
        try:
            inst.cycle(given)
        except (TypeError, ValueError, ArithmeticError, IndexError, KeyError, RecursionError) as exc:
            raise InputError(f"PROGRAM {self.program} of {self.file} fails in a scan: {exc}", _at(self.option)) \
                from None
        return self.snapshot(inst)

    def timers(self, snap: Snapshot) -> tuple[str, ...]:
        """The events of the timers running in ``snap`` (their preset not reached)."""
        return tuple(self._timers(snap.instance))

    def _timers(self, inst: StInstance) -> dict[str, StInstance]:
        out: dict[str, StInstance] = {}
        stack: list[tuple[str, StInstance]] = [("", inst)]
        while stack:
            path, node = stack.pop(0)
            for n, x in node.values.items():
                if not _is_instance(x):
                    continue
                here = f"{path}{n}"
                key = _TIMERS.get(x.type) if x.pou is None else None
                if key is None:
                    stack.append((here + ".", x))
                elif key in x.memory and self.module.clock_ms - x.memory[key] < int(x.values["PT"]):
                    out[f"{TIMER_PREFIX}{here} ({_ms_text(int(x.values['PT']))})"] = x
        return out

    def orders(self, snap: Snapshot) -> dict[str, bool]:
        """The requests of ``snap``: its VAR_OUTPUTs by plant output name."""
        return {o: bool(snap.instance.values[v]) for o, v in self.outputs.items()}

    def observe(self, snap: Snapshot, names: Sequence[str]) -> dict[str, bool]:
        """The BOOL variables ``names`` of the program (the filter's observers)."""
        return {n: bool(snap.instance[n]) for n in names}
