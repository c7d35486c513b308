"""An interpreter for the IEC 61131-3 Structured Text that synth emits, on blark's parse tree.

It is the independent half of the proof "what runs is what was proven": the generated
text is parsed by `blark <https://pypi.org/project/blark/>`_ (a lark-based IEC 61131-3
parser written by others), and its dataclass tree is executed cycle by cycle. Nothing
here reads synth's own models, so a wrong emitter cannot agree with itself.

The subset: ``PROGRAM`` and ``FUNCTION_BLOCK``; ``VAR``, ``VAR_INPUT``, ``VAR_OUTPUT``,
``VAR_IN_OUT``, ``VAR CONSTANT``; ``BOOL``, ``SINT``/``INT``/``DINT``/``LINT`` (and
unsigned), ``TIME``; ``ARRAY [a..b, …] OF`` those with initialisers (``3(FALSE)``);
``:=``, ``IF``/``ELSIF``/``ELSE``, ``WHILE``, ``REPEAT``, ``FOR``, ``EXIT``, ``RETURN``;
calls of user function blocks and of the standard ``TON``, ``TOF``, ``TP``, ``R_TRIG``,
``F_TRIG``, ``SR``, ``RS`` with named arguments (``q => x`` outputs too); ``AND``
(``&``), ``OR``, ``XOR``, ``NOT``, comparisons, ``+ - * / MOD``, ``T#…`` literals,
member access ``t.Q``, array indexing. Anything else is an :class:`~synth.errors.InputError`
at its line and column. Time is the module's clock in milliseconds, advanced by
:meth:`Module.advance`; ``TIME`` values are integers of milliseconds.

Example
-------
>>> mod = load_st('''
... FUNCTION_BLOCK FB_Latch
... VAR_INPUT set, reset : BOOL; END_VAR
... VAR_OUTPUT q : BOOL; END_VAR
... q := set OR (q AND NOT reset);
... END_FUNCTION_BLOCK''', "latch.st")
>>> fb = mod.instance("FB_Latch")
>>> fb.cycle({"set": True})["q"]
True
>>> fb.cycle({"set": False})["q"]
True
>>> fb.cycle({"reset": True})["q"]
False
"""

from __future__ import annotations

import operator
from dataclasses import dataclass
from enum import StrEnum
from typing import Any, Callable, Iterator, Mapping

from synth.errors import InputError, location_in

__all__ = ["VarSection", "Variable", "Pou", "Module", "Instance", "load_st", "Array"]

Value = Any  # bool | int | Array | Instance
Thunk = Callable[["Instance"], Value]
Action = Callable[["Instance"], None]

_INT_TYPES = {"SINT", "INT", "DINT", "LINT", "USINT", "UINT", "UDINT", "ULINT", "BYTE", "WORD", "DWORD", "LWORD"}
_STANDARD_FBS = ("TON", "TOF", "TP", "R_TRIG", "F_TRIG", "SR", "RS")
_MAX_LOOP = 100_000


class VarSection(StrEnum):
    """The declaration block a variable comes from."""

    LOCAL = "VAR"
    INPUT = "VAR_INPUT"
    OUTPUT = "VAR_OUTPUT"
    IN_OUT = "VAR_IN_OUT"
    GLOBAL = "VAR_GLOBAL"


class _Exit(Exception):
    """``EXIT``: leave the innermost loop."""


class _Return(Exception):
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

    def copy(self) -> "Array":
        return Array(self.bounds, list(self.items))

    def __eq__(self, other: object) -> bool:
        return isinstance(other, Array) and (self.bounds, self.items) == (other.bounds, other.items)

    def __repr__(self) -> str:
        return f"Array({self.bounds}, {self.items})"


@dataclass(frozen=True)
class Variable:
    """A declared variable: its section, type name (``BOOL``, ``TON``, ``FB_X``, ``ARRAY``) and a maker of its initial value."""

    name: str
    section: VarSection
    type: str
    initial: Callable[["Module"], Value]
    constant: bool = False


@dataclass(frozen=True)
class Pou:
    """A compiled PROGRAM or FUNCTION_BLOCK."""

    name: str
    kind: str  # "PROGRAM" | "FUNCTION_BLOCK"
    variables: tuple[Variable, ...]
    body: Action

    def variable(self, name: str) -> Variable | None:
        for v in self.variables:
            if v.name.upper() == name.upper():
                return v
        return None


class Instance:
    """One instance of a POU (or of a standard function block) with its variables.

    Names are case-insensitive, as in IEC 61131-3; :attr:`values` keeps declared spelling.
    """

    def __init__(self, module: "Module", pou: Pou | None, type_name: str, values: dict[str, Value]) -> None:
        self.module = module
        self.pou = pou
        self.type = type_name
        self.values = values
        self._keys = {k.upper(): k for k in values}
        self._state: dict[str, Any] = {}

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

    def cycle(self, inputs: Mapping[str, Value] | None = None) -> "Instance":
        """Set the given variables (inputs, usually), then run the body once."""
        for k, v in (inputs or {}).items():
            self[k] = v
        self.run()
        return self

    def run(self) -> None:
        if self.pou is not None:
            try:
                self.pou.body(self)
            except _Return:
                pass
        else:
            _STANDARD[self.type](self)

    def snapshot(self) -> dict[str, Value]:
        """The plain (BOOL/INT/TIME) variables by declared name."""
        return {k: v for k, v in self.values.items() if isinstance(v, (bool, int))}


class Module:
    """The POUs of one ST text and the clock their timers read."""

    def __init__(self, file: str, source: str, pous: dict[str, Pou]) -> None:
        self.file = file
        self.source = source
        self.pous = pous
        self.clock_ms = 0

    def advance(self, ms: int) -> None:
        """Let ``ms`` milliseconds pass (for ``TON``/``TOF``/``TP``)."""
        self.clock_ms += int(ms)

    def instance(self, name: str) -> Instance:
        """A fresh instance of the POU ``name`` (or of a standard function block)."""
        for key, pou in self.pous.items():
            if key.upper() == name.upper():
                return Instance(self, pou, pou.name, {v.name: v.initial(self) for v in pou.variables})
        if name.upper() in _STANDARD:
            return Instance(self, None, name.upper(), dict(_STANDARD_VARS[name.upper()]))
        raise KeyError(f"no POU named {name}; the file defines {', '.join(self.pous) or 'none'}")


# -- standard function blocks -------------------------------------------------------------

_STANDARD_VARS: dict[str, dict[str, Value]] = {
    "TON": {"IN": False, "PT": 0, "Q": False, "ET": 0},
    "TOF": {"IN": False, "PT": 0, "Q": False, "ET": 0},
    "TP": {"IN": False, "PT": 0, "Q": False, "ET": 0},
    "R_TRIG": {"CLK": False, "Q": False},
    "F_TRIG": {"CLK": False, "Q": False},
    "SR": {"S1": False, "R": False, "Q1": False},
    "RS": {"S": False, "R1": False, "Q1": False},
}


def _ton(fb: Instance) -> None:
    v, st, now = fb.values, fb._state, fb.module.clock_ms
    if v["IN"]:
        start = st.setdefault("start", now)
        v["ET"] = min(now - start, v["PT"])
        v["Q"] = now - start >= v["PT"]
    else:
        st.pop("start", None)
        v["ET"], v["Q"] = 0, False


def _tof(fb: Instance) -> None:
    v, st, now = fb.values, fb._state, fb.module.clock_ms
    if v["IN"]:
        st.pop("fall", None)
        v["ET"], v["Q"] = 0, True
    elif v["Q"]:
        fall = st.setdefault("fall", now)
        v["ET"] = min(now - fall, v["PT"])
        v["Q"] = now - fall < v["PT"]


def _tp(fb: Instance) -> None:
    v, st, now = fb.values, fb._state, fb.module.clock_ms
    if "start" not in st and v["IN"] and not st.get("in", False):
        st["start"] = now
    if "start" in st:
        v["ET"] = min(now - st["start"], v["PT"])
        v["Q"] = now - st["start"] < v["PT"]
        if not v["Q"] and not v["IN"]:
            del st["start"]
    else:
        v["ET"], v["Q"] = 0, False
    st["in"] = v["IN"]


def _r_trig(fb: Instance) -> None:
    m = fb._state.get("M", False)
    fb.values["Q"] = fb.values["CLK"] and not m
    fb._state["M"] = fb.values["CLK"]


def _f_trig(fb: Instance) -> None:
    # IEC 61131-3: Q := NOT CLK AND NOT M; M := NOT CLK (M starts FALSE)
    m = fb._state.get("M", False)
    fb.values["Q"] = not fb.values["CLK"] and not m
    fb._state["M"] = not fb.values["CLK"]


def _sr(fb: Instance) -> None:
    v = fb.values
    v["Q1"] = v["S1"] or (v["Q1"] and not v["R"])


def _rs(fb: Instance) -> None:
    v = fb.values
    v["Q1"] = not v["R1"] and (v["S"] or v["Q1"])


_STANDARD: dict[str, Action] = {
    "TON": _ton, "TOF": _tof, "TP": _tp, "R_TRIG": _r_trig, "F_TRIG": _f_trig, "SR": _sr, "RS": _rs,
}


# -- compilation of blark's tree into closures ---------------------------------------------


def load_st(text: str, file: str = "<st>") -> Module:
    """Parse ``text`` with blark and compile its PROGRAMs and FUNCTION_BLOCKs."""
    from blark.parse import parse_source_code

    result = parse_source_code(text, fn=file)
    if result.exception is not None:
        exc = result.exception
        line, column = getattr(exc, "line", 1) or 1, getattr(exc, "column", 1) or 1
        expected = sorted(getattr(exc, "expected", None) or getattr(exc, "allowed", None) or ())
        raise InputError("not valid IEC 61131-3 Structured Text (blark)", location_in(file, text, line, column),
                         expected=tuple(expected)[:8])
    source = result.transform()
    compiler = _Compiler(file, text)
    pous: dict[str, Pou] = {}
    for item in source.items:
        kind = type(item).__name__
        if kind not in ("Program", "FunctionBlock"):
            raise compiler.error(item, f"{kind} is outside the subset synth executes (PROGRAM, FUNCTION_BLOCK)")
        pou = compiler.pou(item, "PROGRAM" if kind == "Program" else "FUNCTION_BLOCK")
        pous[pou.name] = pou
    compiler.pous = pous
    return Module(file, text, pous)


def _name(token: Any) -> str:
    return str(token)


class _Compiler:
    def __init__(self, file: str, text: str) -> None:
        self.file, self.text = file, text
        self.pous: dict[str, Pou] = {}

    def error(self, node: Any, message: str) -> InputError:
        meta = getattr(node, "meta", None)
        line = getattr(meta, "line", None) or 1
        column = getattr(meta, "column", None) or 1
        return InputError(message, location_in(self.file, self.text, line, column))

    # declarations
    def pou(self, node: Any, kind: str) -> Pou:
        variables: list[Variable] = []
        for block in node.declarations:
            section = {
                "VariableDeclarations": VarSection.LOCAL, "InputDeclarations": VarSection.INPUT,
                "OutputDeclarations": VarSection.OUTPUT, "InputOutputDeclarations": VarSection.IN_OUT,
                "StaticDeclarations": VarSection.LOCAL, "GlobalVariableDeclarations": VarSection.GLOBAL,
            }.get(type(block).__name__)
            if section is None:
                raise self.error(block, f"{type(block).__name__} is outside the subset synth executes")
            attrs = str(getattr(block, "attrs", None) or "").upper()
            for decl in block.items:
                variables.extend(self.declaration(decl, section, "CONSTANT" in attrs))
        body = self.statements(node.body.statements if node.body is not None else [])
        return Pou(_name(node.name), kind, tuple(variables), body)

    def declaration(self, decl: Any, section: VarSection, constant: bool) -> Iterator[Variable]:
        kind = type(decl).__name__
        names = [_name(d.variable.name) for d in decl.variables]
        init = decl.init
        if kind == "VariableOneInitDeclaration":
            type_name = _name(init.spec.type).upper() if hasattr(init.spec, "type") else None
            if type_name is None:
                raise self.error(decl, "this type specification is outside the subset synth executes")
            make = self.initial(decl, type_name, init.value)
        elif kind == "FunctionBlockNameDeclaration":
            type_name = _name(decl.spec).upper()
            make = self.initial(decl, type_name, None)
        elif kind == "ArrayVariableInitDeclaration":
            type_name = "ARRAY"
            make = self.array(decl, init)
        else:
            raise self.error(decl, f"{kind} is outside the subset synth executes")
        for n in names:
            yield Variable(n, section, type_name, make, constant)

    def initial(self, decl: Any, type_name: str, value: Any) -> Callable[[Module], Value]:
        if type_name == "BOOL":
            default: Value = False
        elif type_name in _INT_TYPES or type_name == "TIME":
            default = 0
        else:
            if value is not None:
                raise self.error(decl, f"initial values of {type_name} instances are outside the subset")
            return lambda module, t=type_name: module.instance(t)
        if value is None:
            return lambda module, d=default: d
        thunk = self.expr(value)
        return lambda module, f=thunk: _cast(type_name, f(None))  # constants only

    def array(self, decl: Any, init: Any) -> Callable[[Module], Value]:
        spec = init.spec
        bounds = []
        for sub in spec.subranges:
            if type(sub).__name__ != "PartialSubrange":
                raise self.error(decl, "arrays need explicit bounds [a..b]")
            bounds.append((int(self.expr(sub.start)(None)), int(self.expr(sub.stop)(None))))
        elem = _name(spec.type.type_name).upper()
        if elem != "BOOL" and elem not in _INT_TYPES and elem != "TIME":
            raise self.error(decl, f"arrays of {elem} are outside the subset synth executes")
        size = 1
        for lo, hi in bounds:
            size *= hi - lo + 1
        default: Value = False if elem == "BOOL" else 0
        values: list[Value] = []
        if init.value is not None:
            for element in self._flat_elements(init.value):
                count = int(str(element.count)) if element.count is not None else 1
                inner = element.element
                if type(inner).__name__ == "ArrayInitialization":
                    raise self.error(decl, "nested array initialisers are outside the subset")
                values.extend([_cast(elem, self.expr(inner)(None))] * count)
        if len(values) > size:
            raise self.error(decl, f"{len(values)} initial values for an array of {size}")
        values += [default] * (size - len(values))
        frozen = tuple(values)
        return lambda module: Array(tuple(bounds), list(frozen))

    def _flat_elements(self, init: Any) -> Iterator[Any]:
        for element in init.elements:
            if type(element.element).__name__ == "ArrayInitialization" and element.count is None:
                yield from self._flat_elements(element.element)
            else:
                yield element

    # statements
    def statements(self, nodes: Any) -> Action:
        actions = [self.statement(s) for s in (nodes or [])]

        def run(inst: Instance) -> None:
            for a in actions:
                a(inst)

        return run

    def _list(self, node: Any) -> Any:
        return node.statements if node is not None else []

    def statement(self, node: Any) -> Action:
        kind = type(node).__name__
        if kind == "AssignmentStatement":
            value = self.expr(node.expression)
            targets = [self.target(v) for v in node.variables]

            def assign(inst: Instance) -> None:
                x = value(inst)
                for t in targets:
                    t(inst, x)

            return assign
        if kind == "IfStatement":
            branches = [(self.expr(node.if_expression), self.statements(self._list(node.statements)))]
            branches += [(self.expr(c.if_expression), self.statements(self._list(c.statements))) for c in node.else_ifs]
            otherwise = self.statements(self._list(node.else_clause.statements)) if node.else_clause else None

            def if_(inst: Instance) -> None:
                for cond, body in branches:
                    if _bool(cond(inst)):
                        body(inst)
                        return
                if otherwise is not None:
                    otherwise(inst)

            return if_
        if kind == "WhileStatement":
            cond, body = self.expr(node.expression), self.statements(self._list(node.statements))
            return self._loop(node, lambda inst: _bool(cond(inst)), body, None)
        if kind == "RepeatStatement":
            cond, body = self.expr(node.expression), self.statements(self._list(node.statements))
            first = [True]

            def again(inst: Instance) -> bool:
                if first[0]:
                    first[0] = False
                    return True
                return not _bool(cond(inst))

            loop = self._loop(node, again, body, None)

            def repeat(inst: Instance) -> None:
                first[0] = True
                loop(inst)

            return repeat
        if kind == "ForStatement":
            return self.for_(node)
        if kind in ("FunctionCallStatement", "FunctionCall"):
            return self.call(node)
        if kind == "ExitStatement":
            def exit_(inst: Instance) -> None:
                raise _Exit

            return exit_
        if kind == "ReturnStatement":
            def return_(inst: Instance) -> None:
                raise _Return

            return return_
        if kind in ("NoOpStatement", "EmptyStatement"):
            return lambda inst: None
        raise self.error(node, f"{kind} is outside the subset synth executes")

    def _loop(self, node: Any, again: Callable[[Instance], bool], body: Action, step: Action | None) -> Action:
        where = self.error(node, "loop did not terminate after 100000 iterations")

        def loop(inst: Instance) -> None:
            n = 0
            try:
                while again(inst):
                    body(inst)
                    if step is not None:
                        step(inst)
                    n += 1
                    if n > _MAX_LOOP:
                        raise where
            except _Exit:
                pass

        return loop

    def for_(self, node: Any) -> Action:
        control = self.target(node.control)
        read = self.expr(node.control)
        start, stop = self.expr(node.from_), self.expr(node.to)
        step = self.expr(node.step) if node.step is not None else (lambda inst: 1)
        body = self.statements(self._list(node.statements))

        def for_(inst: Instance) -> None:
            control(inst, start(inst))
            limit, by = stop(inst), step(inst)
            if by == 0:
                raise self.error(node, "FOR with a step of 0")
            n = 0
            try:
                while (read(inst) <= limit) if by > 0 else (read(inst) >= limit):
                    body(inst)
                    control(inst, read(inst) + by)
                    n += 1
                    if n > _MAX_LOOP:
                        raise self.error(node, "loop did not terminate after 100000 iterations")
            except _Exit:
                pass

        return for_

    def call(self, node: Any) -> Action:
        target = self.reference(node.name)
        inputs: list[tuple[str, Thunk]] = []
        outputs: list[tuple[str, Callable[[Instance, Value], None], bool]] = []
        for p in node.parameters or []:
            kind = type(p).__name__
            if kind == "InputParameterAssignment":
                if p.name is None:
                    raise self.error(node, "positional arguments are outside the subset: write NAME := value")
                inputs.append((_name(p.name.name), self.expr(p.value)))
            elif kind == "OutputParameterAssignment":
                outputs.append((_name(p.name.name), self.target(p.value), bool(p.inverted)))
            else:
                raise self.error(node, f"{kind} is outside the subset synth executes")
        where = node

        def call(inst: Instance) -> None:
            fb = target(inst)
            if not isinstance(fb, Instance):
                raise self.error(where, "only function block instances can be called")
            for n, f in inputs:
                try:
                    fb[n] = f(inst)
                except KeyError:
                    raise self.error(where, f"{fb.type} has no input {n}") from None
            fb.run()
            for n, set_, inverted in outputs:
                x = fb[n]
                set_(inst, (not x) if inverted else x)

        return call

    # places
    def reference(self, node: Any) -> Thunk:
        """Read a variable, an array element or a field of an instance."""
        kind = type(node).__name__
        if kind == "SimpleVariable":
            name = _name(node.name)

            def read(inst: Instance) -> Value:
                try:
                    return inst[name]
                except KeyError:
                    raise self.error(node, f"unknown variable {name}") from None

            return read
        if kind == "MultiElementVariable":
            base = self.reference(node.name)
            steps = [self.element(e) for e in node.elements]

            def read_multi(inst: Instance) -> Value:
                x = base(inst)
                for get, _ in steps:
                    x = get(inst, x)
                return x

            return read_multi
        raise self.error(node, f"{kind} is outside the subset synth executes")

    def element(self, e: Any) -> tuple[Callable[[Instance, Value], Value], Callable[[Instance, Value, Value], None]]:
        kind = type(e).__name__
        if kind == "SubscriptList":
            subs = [self.expr(s) for s in e.subscripts]

            def get(inst: Instance, arr: Value) -> Value:
                try:
                    return arr[tuple(int(s(inst)) for s in subs)]
                except (IndexError, TypeError) as exc:
                    raise self.error(e, f"array access: {exc}") from None

            def put(inst: Instance, arr: Value, value: Value) -> None:
                try:
                    arr[tuple(int(s(inst)) for s in subs)] = value
                except (IndexError, TypeError) as exc:
                    raise self.error(e, f"array access: {exc}") from None

            return get, put
        if kind == "FieldSelector":
            field = _name(e.field.name)

            def get_field(inst: Instance, fb: Value) -> Value:
                try:
                    return fb[field]
                except (KeyError, TypeError):
                    raise self.error(e, f"no member {field}") from None

            def put_field(inst: Instance, fb: Value, value: Value) -> None:
                try:
                    fb[field] = value
                except (KeyError, TypeError):
                    raise self.error(e, f"no member {field}") from None

            return get_field, put_field
        raise self.error(e, f"{kind} is outside the subset synth executes")

    def target(self, node: Any) -> Callable[[Instance, Value], None]:
        kind = type(node).__name__
        if kind == "SimpleVariable":
            name = _name(node.name)

            def put(inst: Instance, value: Value) -> None:
                try:
                    key = inst.key(name)
                except KeyError:
                    raise self.error(node, f"unknown variable {name}") from None
                inst.values[key] = value

            return put
        if kind == "MultiElementVariable":
            base = self.reference(node.name)
            steps = [self.element(e) for e in node.elements]
            *path, (_, last) = steps

            def put_multi(inst: Instance, value: Value) -> None:
                x = base(inst)
                for get, _ in path:
                    x = get(inst, x)
                last(inst, x, value)

            return put_multi
        raise self.error(node, f"cannot assign to {kind}")

    # expressions
    def expr(self, node: Any) -> Thunk:
        kind = type(node).__name__
        if kind == "Boolean":
            v = str(node.value).upper() in ("TRUE", "1")
            return lambda inst: v
        if kind == "Integer":
            text = str(node.value).replace("_", "")
            iv = int(text, 0) if not text.isdigit() else int(text)
            return lambda inst: iv
        if kind in ("Duration", "Lduration"):
            ms = _duration_ms(node)
            return lambda inst: ms
        if kind == "ParenthesizedExpression":
            return self.expr(node.expr)
        if kind in ("SimpleVariable", "MultiElementVariable"):
            return self.reference(node)
        if kind == "UnaryOperation":
            inner = self.expr(node.expr)
            op = str(node.op).upper()
            if op == "NOT":
                return lambda inst: not _bool(inner(inst))
            if op == "-":
                return lambda inst: -inner(inst)
            if op == "+":
                return inner
            raise self.error(node, f"operator {op} is outside the subset")
        if kind == "BinaryOperation":
            return self.binary(node)
        raise self.error(node, f"{kind} is outside the subset synth executes")

    def binary(self, node: Any) -> Thunk:
        left, right = self.expr(node.left), self.expr(node.right)
        op = str(node.op).upper()
        if op in ("AND", "&"):
            return lambda inst: _bool(left(inst)) and _bool(right(inst))
        if op == "OR":
            return lambda inst: _bool(left(inst)) or _bool(right(inst))
        if op == "XOR":
            return lambda inst: _bool(left(inst)) != _bool(right(inst))
        table: dict[str, Callable[[Any, Any], Any]] = {
            "=": operator.eq, "<>": operator.ne, "<": operator.lt, ">": operator.gt, "<=": operator.le,
            ">=": operator.ge, "+": operator.add, "-": operator.sub, "*": operator.mul, "MOD": _mod, "/": _div,
        }
        fn = table.get(op)
        if fn is None:
            raise self.error(node, f"operator {op} is outside the subset")
        return lambda inst: fn(left(inst), right(inst))


def _bool(x: Value) -> bool:
    if isinstance(x, bool):
        return x
    raise TypeError(f"BOOL expected, got {x!r}")


def _cast(type_name: str, x: Value) -> Value:
    return bool(x) if type_name == "BOOL" else x


def _mod(a: int, b: int) -> int:
    return 0 if b == 0 else int(a - b * int(a / b))


def _div(a: int, b: int) -> int:
    return 0 if b == 0 else int(a / b)


def _duration_ms(node: Any) -> int:
    total = 0.0
    for field, scale in (("days", 86_400_000), ("hours", 3_600_000), ("minutes", 60_000), ("seconds", 1000),
                         ("milliseconds", 1)):
        part = getattr(node, field, None)
        if part is not None:
            total += float(str(part)) * scale
    return -round(total) if getattr(node, "negative", False) else round(total)
