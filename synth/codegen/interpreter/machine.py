"""An interpreter for the IEC 61131-3 Structured Text that synth emits, on blark's parse tree.

It is the independent half of the proof "what runs is what was proven": the generated
text is parsed into the tree of `blark <https://pypi.org/project/blark/>`_ (a lark-based IEC
61131-3 parser written by others; :mod:`synth.codegen.interpreter.parsing` reads synth's own
ST faster with blark's rules under LALR, into the very tree blark's parser gives, which the
tests check against it), and blark's dataclass tree is executed cycle by cycle. Nothing
here reads synth's own models, so a wrong emitter cannot agree with itself.

The subset: ``PROGRAM`` and ``FUNCTION_BLOCK``; ``VAR``, ``VAR_INPUT``, ``VAR_OUTPUT``,
``VAR_IN_OUT``, ``VAR CONSTANT``, located variables (``a AT %IX0.0 : BOOL``); ``BOOL``,
``SINT``/``INT``/``DINT``/``LINT`` (and unsigned), ``TIME``; ``ARRAY [a..b, …] OF`` those
with initialisers (``3(FALSE)``); ``:=``, ``IF``/``ELSIF``/``ELSE``, ``WHILE``, ``REPEAT``, ``FOR``, ``EXIT``, ``RETURN``;
calls of user function blocks and of the standard ``TON``, ``TOF``, ``TP``, ``R_TRIG``,
``F_TRIG``, ``SR``, ``RS`` with named arguments (``q => x`` outputs too); ``AND``
(``&``), ``OR``, ``XOR``, ``NOT``, comparisons, ``+ - * / MOD``, ``T#…`` literals,
member access ``t.Q``, array indexing. Anything else is an :class:`~synth.errors.InputError`
at its line and column. Time is the module's clock in milliseconds, advanced by
:meth:`Module.advance`; ``TIME`` values are integers of milliseconds.

The compilation is a visitor on blark's dataclass types, in layers: expressions and places
(:mod:`synth.codegen.interpreter.expressions`), statements (:mod:`synth.codegen.interpreter.statements`),
declarations and POUs (here); what runs is in :mod:`synth.codegen.interpreter.runtime` and the
standard function blocks in :mod:`synth.codegen.interpreter.standard`.

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

from typing import Callable, Iterator

from blark import transform as tf

from synth.codegen.interpreter.expressions import Node, name_of
from synth.codegen.interpreter.runtime import Array, Host, Instance, Pou, Value, Variable, VarSection
from synth.codegen.interpreter.standard import STANDARD_FBS
from synth.codegen.interpreter.statements import StatementCompiler
from synth.errors import InputError, close_names, location_in

__all__ = ["Module", "load_st"]

_INT_TYPES = {"SINT", "INT", "DINT", "LINT", "USINT", "UINT", "UDINT", "ULINT", "BYTE", "WORD", "DWORD", "LWORD"}

# blark's exact declaration-block type -> the section its variables belong to
_SECTIONS: dict[type, VarSection] = {
    tf.VariableDeclarations: VarSection.LOCAL, tf.InputDeclarations: VarSection.INPUT,
    tf.OutputDeclarations: VarSection.OUTPUT, tf.InputOutputDeclarations: VarSection.IN_OUT,
    tf.StaticDeclarations: VarSection.LOCAL, tf.GlobalVariableDeclarations: VarSection.GLOBAL,
    tf.TemporaryVariableDeclarations: VarSection.TEMP, tf.LocatedVariableDeclarations: VarSection.LOCAL,
}
_POU_KINDS: dict[type, str] = {tf.Program: "PROGRAM", tf.FunctionBlock: "FUNCTION_BLOCK"}


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
        standard = STANDARD_FBS.get(name.upper())
        if standard is not None:
            return Instance(self, None, standard.name, standard.fresh())
        raise KeyError(f"no POU named {name}; the file defines {', '.join(self.pous) or 'none'}")


def load_st(text: str, file: str = "<st>") -> Module:
    """Parse ``text`` into blark's tree (:func:`~synth.codegen.interpreter.parsing.parse_st`)
    and compile its PROGRAMs and FUNCTION_BLOCKs."""
    from synth.codegen.interpreter.parsing import parse_st

    text = text.replace("\r\n", "\n").replace("\r", "\n")  # CRLF (Windows IDEs): the same lines and columns
    # trailing blanks dropped: blark's scanner is quadratic in a run of blanks (20 000: 15 s)
    text = "\n".join(line.rstrip(" \t") for line in text.split("\n"))
    stray = _comment_error(text, file) or _long_blanks(text, file)
    if stray is not None:
        raise stray
    try:
        result = parse_st(text, file)
    except (IndexError, RuntimeError, ValueError) as failure:  # blark's comment scanner on what _comment_error missed
        raise InputError(f"not valid IEC 61131-3 Structured Text (blark: {failure})",
                         location_in(file, text, 1, 1)) from None
    if result.exception is not None:
        exc = result.exception
        line, column = getattr(exc, "line", 1) or 1, getattr(exc, "column", 1) or 1
        if line < 1 or column < 1:  # lark's "unexpected end of input": the end of the text
            line = text.rstrip("\n").count("\n") + 1
            column = len(text.rstrip("\n").rsplit("\n", 1)[-1]) + 1
        expected = sorted(set(getattr(exc, "expected", None) or getattr(exc, "allowed", None) or ()))
        what = "unexpected end of the text" if getattr(exc, "line", 1) == -1 else "not valid IEC 61131-3 Structured Text (blark)"
        from synth.syntax import file_kind_hint

        hint = file_kind_hint("st", file, text)
        raise InputError(what, location_in(file, text, line, column), expected=tuple(expected)[:8],
                         notes=(hint,) if hint else ())
    source = result.transform()
    compiler = _Compiler(file, text)
    pous: dict[str, Pou] = {}
    for item in source.items:
        kind = _POU_KINDS.get(type(item))
        if kind is None:
            raise compiler.error(
                item, f"{type(item).__name__} is outside the subset synth executes (PROGRAM, FUNCTION_BLOCK)")
        pou = compiler.pou(item, kind)
        pous[pou.name] = pou
    known = {n.upper() for n in pous} | set(STANDARD_FBS)
    for decl, type_name in compiler.instances:
        if type_name.upper() not in known:
            names = ["BOOL", "TIME", *sorted(_INT_TYPES), *sorted(STANDARD_FBS), *pous]
            err = compiler.error(decl, f"unknown type {type_name}")
            raise InputError(err.message, err.location, suggestions=close_names(type_name, names))
    return Module(file, text, pous)


def _comment_error(text: str, file: str) -> InputError | None:
    """A ``*)`` that closes no comment, or a ``(*`` never closed, located (blark's comment
    scanner fails on both with an exception of its own). Strings are skipped."""
    depth, opened, i, quote = 0, 0, 0, ""
    while i < len(text):
        pair = text[i:i + 2]
        if quote:
            quote = "" if text[i] == quote else quote
        elif depth == 0 and text[i] in "'\"":
            quote = text[i]
        elif depth == 0 and pair == "//":
            end = text.find("\n", i)
            i = len(text) if end < 0 else end
            continue
        elif pair == "(*":
            opened = i if depth == 0 else opened
            depth, i = depth + 1, i + 2
            continue
        elif pair == "*)":
            if depth == 0:
                return _at_offset(file, text, i, "'*)' closes no comment", "remove it, or open the comment with '(*'")
            depth, i = depth - 1, i + 2
            continue
        i += 1
    if depth:
        return _at_offset(file, text, opened, "this comment is never closed", "close it with '*)'")
    return None


MAX_BLANKS = 1000
"""The longest run of blanks inside a line of ST synth parses (blark's time grows with its square)."""


def _long_blanks(text: str, file: str) -> InputError | None:
    """A run of more than :data:`MAX_BLANKS` spaces or tabs before the end of a line, located."""
    import re

    found = re.search(r"[ \t]{%d,}" % (MAX_BLANKS + 1), text)
    if found is None:
        return None
    return _at_offset(file, text, found.start(), f"{found.end() - found.start()} blanks in a row: more than the "
                      f"{MAX_BLANKS} synth parses in a line of Structured Text", "shorten the run of blanks")


def _at_offset(file: str, text: str, offset: int, message: str, note: str) -> InputError:
    line = text.count("\n", 0, offset) + 1
    column = offset - (text.rfind("\n", 0, offset) + 1) + 1
    return InputError(message, location_in(file, text, line, column), notes=(note,))


def _cast(type_name: str, x: Value) -> Value:
    return bool(x) if type_name == "BOOL" else x


class _Compiler(StatementCompiler):
    """Declarations and POUs; the bodies are :class:`StatementCompiler`'s."""

    def __init__(self, file: str, text: str) -> None:
        super().__init__(file, text)
        self.instances: list[tuple[Node, str]] = []  # (declaration, type name) of every instance variable

    def pou(self, node: Node, kind: str) -> Pou:
        variables: list[Variable] = []
        for block in node.declarations:
            section = _SECTIONS.get(type(block))
            if section is None:
                raise self.outside(block)
            attrs = str(getattr(block, "attrs", None) or "").upper()
            for decl in block.items:
                variables.extend(self.declaration(decl, section, "CONSTANT" in attrs))
        body = self.statements(node.body.statements if node.body is not None else [])
        return Pou(name_of(node.name), kind, tuple(variables), body)

    def declaration(self, decl: Node, section: VarSection, constant: bool) -> Iterator[Variable]:
        if type(decl) is tf.LocatedVariableDeclaration:  # a AT %IX0.0 : BOOL: the address is the runtime's business
            names, init = [name_of(decl.name)], decl.init
            decl = tf.VariableOneInitDeclaration(variables=[], init=init, meta=decl.meta)
        else:
            names = [name_of(d.variable.name) for d in decl.variables]
            init = decl.init
        make: Callable[[Host], Value]
        if type(decl) is tf.VariableOneInitDeclaration:
            if not hasattr(init.spec, "type"):
                raise self.error(decl, "this type specification is outside the subset synth executes")
            type_name = name_of(init.spec.type).upper()
            make = self.initial(decl, type_name, init.value)
        elif type(decl) is tf.FunctionBlockNameDeclaration:
            type_name = name_of(decl.spec).upper()
            make = self.initial(decl, type_name, None)
        elif type(decl) is tf.ArrayVariableInitDeclaration:
            type_name = "ARRAY"
            make = self.array(decl, init)
        else:
            raise self.outside(decl)
        for n in names:
            yield Variable(n, section, type_name, make, constant)

    def initial(self, decl: Node, type_name: str, value: Node | None) -> Callable[[Host], Value]:
        default: Value
        if type_name == "BOOL":
            default = False
        elif type_name in _INT_TYPES or type_name == "TIME":
            default = 0
        else:
            if value is not None:
                raise self.error(decl, f"initial values of {type_name} instances are outside the subset")
            self.instances.append((decl, type_name))  # checked once every POU is known (load_st)
            return lambda module: module.instance(type_name)
        if value is None:
            return lambda module: default
        thunk = self.expr(value)
        return lambda module: _cast(type_name, thunk(None))  # type: ignore[arg-type]  # constants only

    def array(self, decl: Node, init: Node) -> Callable[[Host], Value]:
        spec = init.spec
        bounds = []
        for sub in spec.subranges:
            if type(sub) is not tf.PartialSubrange:
                raise self.error(decl, "arrays need explicit bounds [a..b]")
            bounds.append((int(self.constant(sub.start)), int(self.constant(sub.stop))))
        elem = name_of(spec.type.type_name).upper()
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
                if type(inner) is tf.ArrayInitialization:
                    raise self.error(decl, "nested array initialisers are outside the subset")
                values.extend([_cast(elem, self.constant(inner))] * count)
        if len(values) > size:
            raise self.error(decl, f"{len(values)} initial values for an array of {size}")
        values += [default] * (size - len(values))
        frozen = tuple(values)
        return lambda module: Array(tuple(bounds), list(frozen))

    def _flat_elements(self, init: Node) -> Iterator[Node]:
        for element in init.elements:
            if type(element.element) is tf.ArrayInitialization and element.count is None:
                yield from self._flat_elements(element.element)
            else:
                yield element
