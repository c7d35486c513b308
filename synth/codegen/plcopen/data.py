"""The data of an imported SFC POU that ``.g7`` can hold (``synth import``): integer and
Boolean local variables the chart's actions assign become ``.g7`` *internal variables*;
global names written with a dot (``GVL.IsSFCResetting``) become Boolean variables
``GVL_IsSFCResetting``; TON instances that only time a step's activity are step timers
(:mod:`synth.codegen.plcopen.timers`).

A local ``INT``/``SINT``/``DINT``/``UINT``/``USINT``/``BOOL`` that an action body assigns is
``internal NAME : <the IEC type's range> = <initialValue or 0>`` with a located warning (the
type's range is rarely the one the program needs); one ``synth sfc`` wrote (documentation
``internal 0..3`` or ``internal Boolean``) gets its range back without a warning. While a
chart is read, :data:`DATA` holds its :class:`DataScope`; the ST readers ask it.

Example
-------
>>> IEC_RANGES["USINT"], DataVar("cnt", "INT", 0, 3, 0, True, None).text()
((0, 255), 'internal cnt : 0..3 = 0')
"""

from __future__ import annotations

import contextvars
import re
from dataclasses import dataclass, field
from typing import Any, Callable

from synth.codegen.plcopen.vendor import Dialect
from synth.errors import InputError, Location, Severity

__all__ = ["FLAG_PREFIX", "duration", "IEC_RANGES", "DataVar", "DataScope", "DATA", "data_scope", "assigned_names", "strip_comments",
           "HelperChart"]

HelperChart = tuple[str, list[tuple[str, bool, list[str]]], list[tuple[list[str], list[str], str]]]
"""A partial grafcet the import adds: (name, steps (name, initial, actions), transitions
(sources, targets, receptivity))."""

IEC_RANGES: dict[str, tuple[int, int]] = {
    "BOOL": (0, 1), "SINT": (-128, 127), "USINT": (0, 255), "INT": (-32768, 32767), "UINT": (0, 65535),
    "DINT": (-2 ** 31, 2 ** 31 - 1)}
"""The IEC 61131-3 types read as internal variables, with their ranges."""


def strip_comments(text: str) -> str:
    """``text`` with its ST comments as spaces (offsets unchanged)."""
    return re.sub(r"\(\*.*?\*\)|//[^\n]*", lambda c: re.sub(r"[^\n]", " ", c[0]), text, flags=re.S)


def assigned_names(text: str) -> set[str]:
    """The names an ST body assigns (upper case), block call arguments left out."""
    clean = re.sub(r"[\w.]+\s*\([^()]*\)", " ", strip_comments(text))
    return {m[1].upper() for m in re.finditer(r"(?<![\w.])(\w+)\s*:=", clean)}


@dataclass
class DataVar:
    """A local variable read as an internal variable."""

    name: str
    iec: str
    low: int
    high: int
    initial: int
    documented: bool  # synth's own export: its range is the .g7 one
    el: Any
    output: bool = False  # an integer output: .g7 outputs are Boolean

    @property
    def boolean(self) -> bool:
        return self.iec == "BOOL"

    def text(self) -> str:
        return f"internal {self.name} : {'bool' if self.boolean else f'{self.low}..{self.high}'} = {self.initial}"


@dataclass
class DataScope:
    """What the readers of one chart know of its data (see the module doc)."""

    pou: str
    at: Callable[[Any], Location]
    vars: dict[str, DataVar] = field(default_factory=dict)  # upper-case name -> variable
    used: dict[str, DataVar] = field(default_factory=dict)
    timers: dict[str, str] = field(default_factory=dict)  # upper-case alias -> .g7 timer (50ms/XS)
    timer_blocks: set[str] = field(default_factory=set)  # upper-case TON instances made step timers
    ton_charts: list[tuple[str, str, str, str, str, Any, str]] = field(default_factory=list)  # TONs as grafcets
    spelling: dict[str, str] = field(default_factory=dict)  # upper-case name -> declared name
    global_lists: set[str] = field(default_factory=set)  # upper-case names of the project's global lists
    inputs: set[str] = field(default_factory=set)  # upper-case names of the POU's inputVars
    inputs_out: dict[str, str] = field(default_factory=dict)  # an input the chart assigns -> its output
    globals_out: dict[str, str] = field(default_factory=dict)  # dotted name -> .g7 output name
    globals_in: dict[str, str] = field(default_factory=dict)  # dotted name -> .g7 input name
    warnings: list[InputError] = field(default_factory=list)
    step_timers: dict[str, dict[str, str]] = field(default_factory=dict)  # alias -> step -> timer (several steps)
    sources: tuple[str, ...] = ()  # the source steps of the transition being read
    prefix: str = ""  # of the step names (several POUs in one .g7)
    helper_charts: list[tuple[str, str, str, str]] = field(default_factory=list)  # (grafcet, off, on, .g7 condition)
    constants: dict[str, int] = field(default_factory=dict)  # upper-case name -> value (VAR CONSTANT)
    constant_durations: dict[str, str] = field(default_factory=dict)  # upper-case name -> .g7 duration
    one_scan: dict[str, str] = field(default_factory=dict)  # step left at once -> its receptivities
    current_step: str = ""  # the step whose actions are being read
    action_refs: list[str] = field(default_factory=list)  # names an action block references (outputs)
    extra_charts: list[HelperChart] = field(default_factory=list)  # SR/RS latches, LD blinkers
    blink_actions: set[str] = field(default_factory=set)  # upper-case LD actions read as a blinker
    dialect: tuple[Dialect, str] = (Dialect.OTHER, "")  # the tool that wrote the file, and how it says so
    scan_calls: dict[str, Any] = field(default_factory=dict)  # Beremiz: a block's path -> its call (fbscan.py)

    def every_scan(self, statement: str, action: str, where: Location) -> None:
        """``statement`` (data read) runs at every PLC scan while its step is active: an error,
        unless the step lasts one scan (:mod:`synth.codegen.plcopen.scan`): then a warning."""
        step = self.current_step
        if step not in self.one_scan:
            raise InputError(f"{statement} in {action}, run at every PLC scan while its step is active: .g7 assigns "
                             "once, on activation, on deactivation or on an event (use P1 or P0, or IF condition "
                             "THEN ... END_IF)", where)
        self.warnings.append(InputError(
            f"{statement} in {action} runs at every PLC scan while step {step} is active; the step is left at the "
            f"first scan (its transitions' receptivities {self.one_scan[step]} always hold), so it runs once: read "
            "as an assignment on activation", where, severity=Severity.WARNING))

    def find(self, name: str) -> DataVar | None:
        v = self.vars.get(name.upper())
        if v is not None and v.name.upper() not in self.used:
            self.used[v.name.upper()] = v
            if not v.documented:
                kind = "bool" if v.boolean else f"{v.low}..{v.high}"
                what = "output" if v.output else "local variable"
                self.warnings.append(InputError(
                    f"{what} {v.name} ({v.iec}) of POU {self.pou}, assigned by its actions, is the internal variable "
                    f"{v.name} : {kind} = {v.initial}" + ("" if v.boolean else ": give it the range it really has")
                    + (" (.g7 outputs are Boolean: it is not an output of the .g7)" if v.output else ""),
                    self.at(v.el), severity=Severity.WARNING))
        return v

    def global_name(self, dotted: str, output: bool, where: Location) -> str:
        """``GVL.X`` as the Boolean ``GVL_X`` (an output when assigned), with a warning once."""
        flat = dotted.replace(".", "_")
        table = self.globals_out if output else self.globals_in
        if dotted not in table:
            table[dotted] = flat
            self.warnings.append(InputError(
                f"the global {dotted} is {'assigned' if output else 'read'} here: .g7 names have no dot, so it is "
                f"the {'output' if output else 'input'} {flat}", where, severity=Severity.WARNING))
        return flat

    def member_read(self, dotted: str, where: Location) -> str:
        """``Inst.X``, a member of a variable of the POU (a block instance), read: the input ``Inst_X``."""
        flat = dotted.replace(".", "_")
        if dotted not in self.globals_in:
            self.globals_in[dotted] = flat
            self.warnings.append(InputError(
                f"{dotted}, a member of {dotted.split('.')[0]} (a variable of POU {self.pou}), is read here: .g7 names "
                f"have no dot, so it is the input {flat} (bind it to the member's value)", where,
                severity=Severity.WARNING))
        return flat

    def input_written(self, name: str, where: Location) -> str:
        """An input the chart assigns: the output ``NAME_out``, with a warning once."""
        declared = self.spelling.get(name.upper(), name)
        if declared not in self.inputs_out:
            self.inputs_out[declared] = f"{declared}_out"
            self.warnings.append(InputError(
                f"the chart assigns its input {declared}: .g7 inputs are read only, so it assigns the output "
                f"{declared}_out (bind it to what writes {declared}; transitions still read the input)", where,
                severity=Severity.WARNING))
        return self.inputs_out[declared]

    def declarations(self) -> list[str]:
        return [v.text() for v in self.used.values()]


DATA: contextvars.ContextVar[DataScope | None] = contextvars.ContextVar("DATA", default=None)
"""While a chart is read (``synth import``): its :class:`DataScope`."""


def _value(text: str, boolean: bool) -> int | None:
    t = re.sub(r"^\w+#", "", text.strip()).replace("_", "")
    if boolean:
        return {"TRUE": 1, "FALSE": 0, "1": 1, "0": 0}.get(t.upper())
    return int(t) if re.fullmatch(r"[-+]?\d+", t) else None


def data_scope(pou: Any, q: Callable[[str], str], at: Callable[[Any], Location], bodies: list[str],
               exclude: set[str]) -> DataScope:
    """The scope of ``pou``: its local variables of :data:`IEC_RANGES` types that synth wrote
    as internal or that an action body (``bodies``) assigns; ``exclude`` (upper case): names
    read otherwise (timer aliases)."""
    scope = DataScope(str(pou.get("name", "")), at)
    for v in pou.iterfind(f"{q('interface')}/*/{q('variable')}"):
        scope.spelling.setdefault(str(v.get("name", "")).upper(), str(v.get("name", "")))
    scope.global_lists = {str(g.get("name", "")).upper() for g in pou.getroottree().iter(q("globalVars"))
                          if g.get("name")}
    _constants(scope, pou, q)
    written = set().union(*(assigned_names(b) for b in bodies)) if bodies else set()
    scope.inputs = {str(v.get("name", "")).upper() for v in pou.iterfind(f"{q('interface')}/{q('inputVars')}/{q('variable')}")}
    outputs = list(pou.iterfind(f"{q('interface')}/{q('outputVars')}/{q('variable')}"))
    for var in [*pou.iterfind(f"{q('interface')}/{q('localVars')}/{q('variable')}"), *outputs]:
        typ = var.find(q("type"))
        kinds = [c for c in (typ if typ is not None else []) if isinstance(c.tag, str)]
        iec = kinds[0].tag.rsplit("}", 1)[-1] if len(kinds) == 1 else ""
        name = str(var.get("name", ""))
        if iec not in IEC_RANGES or name.upper() in exclude or (var in outputs and iec == "BOOL") \
                or name.upper().startswith(FLAG_PREFIX):
            continue
        doc = " ".join("".join(d.itertext()).split()) if (d := var.find(q("documentation"))) is not None else ""
        m = re.fullmatch(r"internal (-?\d+)\.\.(-?\d+)|internal (Boolean)", doc)
        if m is None and name.upper() not in written:
            continue
        low, high = IEC_RANGES[iec]
        if m is not None and m[1] is not None:
            low, high = int(m[1]), int(m[2])
        init = var.find(f"{q('initialValue')}/{q('simpleValue')}")
        initial = 0
        if init is not None:
            found = _value(str(init.get("value", "")), iec == "BOOL")
            if found is None or not low <= found <= high:
                raise InputError(f"the initial value '{init.get('value')}' of {name} is not a value of its type {iec} ({low}..{high})",
                                 at(init))
            initial = found
        scope.vars[name.upper()] = DataVar(name, iec, low, high, max(low, min(high, initial)), m is not None, var,
                                           var in outputs)
    return scope


FLAG_PREFIX = "_N_"
"""The prefix of a step's flag for an order several steps emit (``_N_RUN_S1``, see
:mod:`synth.codegen.plcopen.shared`): an order in the making, not data."""


_MS = {"ms": 1, "s": 1000, "m": 60_000, "h": 3_600_000, "d": 86_400_000}


def duration(text: str) -> str | None:
    """A TIME literal as a ``.g7`` duration, or None when ``text`` is not one."""
    m = re.fullmatch(r"\s*(?:T|TIME)#((?:\d+(?:\.\d+)?(?:ms|s|m|h|d)_?)+)\s*", text, re.I)
    if m is None:
        return None
    parts = re.findall(r"(\d+(?:\.\d+)?)(ms|s|m|h|d)", m[1].lower())
    if len(parts) == 1 and parts[0][1] != "d":
        number, unit = parts[0]
        return f"{number}{'min' if unit == 'm' else unit}"
    total = sum(float(n) * _MS[u] for n, u in parts)
    return f"{int(total)}ms" if total == int(total) else None


def _constants(scope: DataScope, pou: Any, q: Callable[[str], str]) -> None:
    """The constants in reach of ``pou`` (its ``VAR CONSTANT`` and the project's constant global
    variables, ``constant="true"``) with an integer or TIME initial value."""
    sections = [g for g in pou.getroottree().iter(q("globalVars")) if g.get("constant") in ("true", "1")]
    sections += [s for s in pou.iterfind(f"{q('interface')}/{q('localVars')}") if s.get("constant") in ("true", "1")]
    for section in sections:
        for var in section.iterfind(q("variable")):
            init = var.find(f"{q('initialValue')}/{q('simpleValue')}")
            if init is None:
                continue
            name, raw = str(var.get("name", "")).upper(), str(init.get("value", ""))
            number = _value(raw, False)
            if number is not None:
                scope.constants.setdefault(name, number)
            elif (d := duration(raw)) is not None:
                scope.constant_durations.setdefault(name, d)
