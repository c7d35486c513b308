"""The ST interpreter's expressions and places, compiled from blark's parse tree into closures.

:class:`ExpressionCompiler` visits blark's dataclasses by their type (a table from each class
of the subset to its handler): literals (``TRUE``, ``42``, ``T#1s500ms``), variables, member
access ``t.Q``, array elements ``a[i, j]``, ``NOT``/``-``, ``AND`` (``&``), ``OR``, ``XOR``,
comparisons and ``+ - * / MOD``. A node of any other type is an
:class:`~synth.errors.InputError` at its line and column.

Example
-------
>>> from blark.parse import parse_source_code
>>> text = "PROGRAM P\\nVAR x : INT; END_VAR\\nx := 7 MOD 3 + 2 * 5;\\nEND_PROGRAM\\n"
>>> tree = parse_source_code(text).transform()
>>> assignment = tree.items[0].body.statements[0]
>>> ExpressionCompiler("p.st", text).expr(assignment.expression)(None)  # a constant needs no instance
11
"""

from __future__ import annotations

import operator
from typing import Any, Callable, Mapping, TypeVar

from blark import transform as tf

from synth.codegen.interpreter.runtime import Instance, Thunk, Value
from synth.errors import InputError, location_in

__all__ = ["ExpressionCompiler", "Store", "as_bool", "name_of"]

T = TypeVar("T")

Node = Any  # a blark.transform dataclass (blark ships no type information)
Store = Callable[[Instance, Value], None]
_Get = Callable[[Instance, Value], Value]
_Put = Callable[[Instance, Value, Value], None]


def name_of(token: Any) -> str:
    """The text of a blark identifier token."""
    return str(token)


def as_bool(x: Value) -> bool:
    """``x`` if it is a BOOL, else a ``TypeError``: ST does not read integers as conditions."""
    if isinstance(x, bool):
        return x
    raise TypeError(f"BOOL expected, got {x!r}")


class ExpressionCompiler:
    """Compiles blark expression nodes of one text into closures over an :class:`Instance`."""

    def __init__(self, file: str, text: str) -> None:
        self.file, self.text = file, text

    def error(self, node: Node, message: str) -> InputError:
        """``message`` located at ``node``'s line and column."""
        meta = getattr(node, "meta", None)
        line = getattr(meta, "line", None) or 1
        column = getattr(meta, "column", None) or 1
        return InputError(message, location_in(self.file, self.text, line, column))

    def outside(self, node: Node) -> InputError:
        return self.error(node, f"{type(node).__name__} is outside the subset synth executes")

    def dispatch(self, table: Mapping[type, Callable[[Any, Any], T]], node: Node) -> T:
        """The handler of ``node``'s exact blark type in ``table``; any other type is outside the subset."""
        handler = table.get(type(node))
        if handler is None:
            raise self.outside(node)
        return handler(self, node)

    # expressions
    def expr(self, node: Node) -> Thunk:
        return self.dispatch(_EXPRESSIONS, node)

    def constant(self, node: Node) -> Value:
        """The value of a constant expression (an initialiser, an array bound)."""
        return self.expr(node)(None)  # type: ignore[arg-type]  # constants read no instance

    def _boolean(self, node: Node) -> Thunk:
        v = str(node.value).upper() in ("TRUE", "1")
        return lambda inst: v

    def _integer(self, node: Node) -> Thunk:
        text = str(node.value).replace("_", "")
        iv = int(text, 0) if not text.isdigit() else int(text)
        return lambda inst: iv

    def _duration(self, node: Node) -> Thunk:
        ms = _duration_ms(node)
        return lambda inst: ms

    def _parenthesized(self, node: Node) -> Thunk:
        return self.expr(node.expr)

    def _unary(self, node: Node) -> Thunk:
        inner = self.expr(node.expr)
        op = str(node.op).upper()
        if op == "NOT":
            return lambda inst: not as_bool(inner(inst))
        if op == "-":
            return lambda inst: -inner(inst)
        if op == "+":
            return inner
        raise self.error(node, f"operator {op} is outside the subset")

    def _binary(self, node: Node) -> Thunk:
        left, right = self.expr(node.left), self.expr(node.right)
        op = str(node.op).upper()
        if op in ("AND", "&"):
            return lambda inst: as_bool(left(inst)) and as_bool(right(inst))
        if op == "OR":
            return lambda inst: as_bool(left(inst)) or as_bool(right(inst))
        if op == "XOR":
            return lambda inst: as_bool(left(inst)) != as_bool(right(inst))
        fn = _OPERATORS.get(op)
        if fn is None:
            raise self.error(node, f"operator {op} is outside the subset")
        return lambda inst: fn(left(inst), right(inst))

    # places
    def reference(self, node: Node) -> Thunk:
        """Read a variable, an array element or a field of an instance."""
        return self.dispatch(_REFERENCES, node)

    def _read_simple(self, node: Node) -> Thunk:
        name = name_of(node.name)

        def read(inst: Instance) -> Value:
            try:
                return inst[name]
            except KeyError:
                raise self.error(node, f"unknown variable {name}") from None

        return read

    def _read_multi(self, node: Node) -> Thunk:
        base = self.reference(node.name)
        steps = [self.element(e) for e in node.elements]

        def read_multi(inst: Instance) -> Value:
            x = base(inst)
            for get, _ in steps:
                x = get(inst, x)
            return x

        return read_multi

    def element(self, e: Node) -> tuple[_Get, _Put]:
        """Read and write one step of a path: a subscript list ``[i, j]`` or a field ``.Q``."""
        return self.dispatch(_ELEMENTS, e)

    def _subscripts(self, e: Node) -> tuple[_Get, _Put]:
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

    def _field(self, e: Node) -> tuple[_Get, _Put]:
        field = name_of(e.field.name)

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

    def target(self, node: Node) -> Store:
        """Write a variable, an array element or a field of an instance."""
        handler = _TARGETS.get(type(node))
        if handler is None:
            raise self.error(node, f"cannot assign to {type(node).__name__}")
        return handler(self, node)

    def _write_simple(self, node: Node) -> Store:
        name = name_of(node.name)

        def put(inst: Instance, value: Value) -> None:
            try:
                key = inst.key(name)
            except KeyError:
                raise self.error(node, f"unknown variable {name}") from None
            inst.values[key] = value

        return put

    def _write_multi(self, node: Node) -> Store:
        base = self.reference(node.name)
        steps = [self.element(e) for e in node.elements]
        *path, (_, last) = steps

        def put_multi(inst: Instance, value: Value) -> None:
            x = base(inst)
            for get, _ in path:
                x = get(inst, x)
            last(inst, x, value)

        return put_multi


def _mod(a: int, b: int) -> int:
    return 0 if b == 0 else int(a - b * int(a / b))


def _div(a: int, b: int) -> int:
    return 0 if b == 0 else int(a / b)


def _duration_ms(node: Node) -> int:
    total = 0.0
    for field, scale in (("days", 86_400_000), ("hours", 3_600_000), ("minutes", 60_000), ("seconds", 1000),
                         ("milliseconds", 1)):
        part = getattr(node, field, None)
        if part is not None:
            total += float(str(part)) * scale
    return -round(total) if getattr(node, "negative", False) else round(total)


_OPERATORS: dict[str, Callable[[Any, Any], Any]] = {
    "=": operator.eq, "<>": operator.ne, "<": operator.lt, ">": operator.gt, "<=": operator.le,
    ">=": operator.ge, "+": operator.add, "-": operator.sub, "*": operator.mul, "MOD": _mod, "/": _div,
}

# The visitor's tables: blark's exact node type -> handler (a subclass, such as HexInteger, is not
# in the subset unless listed).
_EXPRESSIONS: dict[type, Callable[[ExpressionCompiler, Node], Thunk]] = {
    tf.Boolean: ExpressionCompiler._boolean,
    tf.Integer: ExpressionCompiler._integer,
    tf.Duration: ExpressionCompiler._duration,
    tf.Lduration: ExpressionCompiler._duration,
    tf.ParenthesizedExpression: ExpressionCompiler._parenthesized,
    tf.SimpleVariable: ExpressionCompiler.reference,
    tf.MultiElementVariable: ExpressionCompiler.reference,
    tf.UnaryOperation: ExpressionCompiler._unary,
    tf.BinaryOperation: ExpressionCompiler._binary,
}
_REFERENCES: dict[type, Callable[[ExpressionCompiler, Node], Thunk]] = {
    tf.SimpleVariable: ExpressionCompiler._read_simple,
    tf.MultiElementVariable: ExpressionCompiler._read_multi,
}
_ELEMENTS: dict[type, Callable[[ExpressionCompiler, Node], tuple[_Get, _Put]]] = {
    tf.SubscriptList: ExpressionCompiler._subscripts,
    tf.FieldSelector: ExpressionCompiler._field,
}
_TARGETS: dict[type, Callable[[ExpressionCompiler, Node], Store]] = {
    tf.SimpleVariable: ExpressionCompiler._write_simple,
    tf.MultiElementVariable: ExpressionCompiler._write_multi,
}
