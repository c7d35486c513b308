"""The ST interpreter's statements, compiled from blark's parse tree into closures.

:class:`StatementCompiler` visits blark's statement dataclasses by their type: ``:=``,
``IF``/``ELSIF``/``ELSE``, ``WHILE``, ``REPEAT``, ``FOR``, ``EXIT``, ``RETURN``, the empty
statement, and calls of function block instances with named arguments (``q => x`` outputs
too). A loop that runs 100000 times is an error, so does a statement of any other type, at
its line and column.

Example
-------
>>> from blark.parse import parse_source_code
>>> from synth.codegen.interpreter.runtime import Instance
>>> text = '''PROGRAM P
... VAR i, n : INT; END_VAR
... FOR i := 1 TO 4 DO n := n + i; END_FOR;
... END_PROGRAM'''
>>> program = parse_source_code(text).transform().items[0]
>>> body = StatementCompiler("p.st", text).statements(program.body.statements)
>>> inst = Instance(None, None, "P", {"i": 0, "n": 0})  # no clock, no other POU needed
>>> body(inst)
>>> inst["n"]
10
"""

from __future__ import annotations

from typing import Callable

from blark import transform as tf

from synth.codegen.interpreter.expressions import ExpressionCompiler, Node, Store, as_bool, name_of
from synth.codegen.interpreter.runtime import Action, BodyReturn, Instance, LoopExit, Thunk, Value

__all__ = ["StatementCompiler"]

_MAX_LOOP = 100_000


def _nothing(inst: Instance) -> None:
    return None


class StatementCompiler(ExpressionCompiler):
    """Compiles blark statement nodes of one text into actions on an :class:`Instance`."""

    def statements(self, nodes: list[Node] | None) -> Action:
        """The statements of a body, in order, as one action."""
        actions = [self.statement(s) for s in (nodes or [])]

        def run(inst: Instance) -> None:
            for a in actions:
                a(inst)

        return run

    def statement(self, node: Node) -> Action:
        return self.dispatch(_STATEMENTS, node)

    def _body(self, node: Node) -> Action:
        """The action of a nested statement list (blark gives ``None`` for an empty one)."""
        return self.statements(node.statements if node is not None else [])

    def _assignment(self, node: Node) -> Action:
        value = self.expr(node.expression)
        targets = [self.target(v) for v in node.variables]

        def assign(inst: Instance) -> None:
            x = value(inst)
            for t in targets:
                t(inst, x)

        return assign

    def _if(self, node: Node) -> Action:
        branches = [(self.expr(node.if_expression), self._body(node.statements))]
        branches += [(self.expr(c.if_expression), self._body(c.statements)) for c in node.else_ifs]
        otherwise = self._body(node.else_clause.statements) if node.else_clause else None

        def if_(inst: Instance) -> None:
            for cond, body in branches:
                if as_bool(cond(inst)):
                    body(inst)
                    return
            if otherwise is not None:
                otherwise(inst)

        return if_

    def _while(self, node: Node) -> Action:
        cond, body = self.expr(node.expression), self._body(node.statements)
        return self._loop(node, lambda inst: as_bool(cond(inst)), body)

    def _repeat(self, node: Node) -> Action:
        cond, body = self.expr(node.expression), self._body(node.statements)
        first = [True]

        def again(inst: Instance) -> bool:
            if first[0]:
                first[0] = False
                return True
            return not as_bool(cond(inst))

        loop = self._loop(node, again, body)

        def repeat(inst: Instance) -> None:
            first[0] = True
            loop(inst)

        return repeat

    def _loop(self, node: Node, again: Callable[[Instance], bool], body: Action) -> Action:
        where = self.error(node, "loop did not terminate after 100000 iterations")

        def loop(inst: Instance) -> None:
            n = 0
            try:
                while again(inst):
                    body(inst)
                    n += 1
                    if n > _MAX_LOOP:
                        raise where
            except LoopExit:
                pass

        return loop

    def _for(self, node: Node) -> Action:
        control = self.target(node.control)
        read = self.expr(node.control)
        start, stop = self.expr(node.from_), self.expr(node.to)
        step: Thunk = self.expr(node.step) if node.step is not None else (lambda inst: 1)
        body = self._body(node.statements)

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
            except LoopExit:
                pass

        return for_

    def _call(self, node: Node) -> Action:
        target = self.reference(node.name)
        inputs: list[tuple[str, Thunk]] = []
        outputs: list[tuple[str, Store, bool]] = []
        for p in node.parameters or []:
            if type(p) is tf.InputParameterAssignment:
                if p.name is None:
                    raise self.error(node, "positional arguments are outside the subset: write NAME := value")
                inputs.append((name_of(p.name.name), self.expr(p.value)))
            elif type(p) is tf.OutputParameterAssignment:
                outputs.append((name_of(p.name.name), self.target(p.value), bool(p.inverted)))
            else:
                raise self.error(node, f"{type(p).__name__} is outside the subset synth executes")

        def call(inst: Instance) -> None:
            fb = target(inst)
            if not isinstance(fb, Instance):
                raise self.error(node, "only function block instances can be called")
            for n, f in inputs:
                try:
                    fb[n] = f(inst)
                except KeyError:
                    raise self.error(node, f"{fb.type} has no input {n}") from None
            fb.run()
            for n, set_, inverted in outputs:
                x: Value = fb[n]
                set_(inst, (not x) if inverted else x)

        return call

    def _exit(self, node: Node) -> Action:
        def exit_(inst: Instance) -> None:
            raise LoopExit

        return exit_

    def _return(self, node: Node) -> Action:
        def return_(inst: Instance) -> None:
            raise BodyReturn

        return return_

    def _no_op(self, node: Node) -> Action:
        return _nothing


# The visitor's table: blark's exact statement type -> handler.
_STATEMENTS: dict[type, Callable[[StatementCompiler, Node], Action]] = {
    tf.AssignmentStatement: StatementCompiler._assignment,
    tf.IfStatement: StatementCompiler._if,
    tf.WhileStatement: StatementCompiler._while,
    tf.RepeatStatement: StatementCompiler._repeat,
    tf.ForStatement: StatementCompiler._for,
    tf.FunctionCallStatement: StatementCompiler._call,
    tf.FunctionCall: StatementCompiler._call,
    tf.ExitStatement: StatementCompiler._exit,
    tf.ReturnStatement: StatementCompiler._return,
    tf.NoOpStatement: StatementCompiler._no_op,
}
