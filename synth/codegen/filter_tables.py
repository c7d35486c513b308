"""The body of a filter block that runs the synthesis's chain of narrowings each cycle on
truth tables (:mod:`synth.filter.local`), for filters whose equations are too large to
print (docs/filter.md, "The chain on tables").

Three ``ARRAY OF BOOL``: ``TabD`` holds each bag's table (entry ``v``: the bag's relation
with its outputs at the bits of ``v``, ``TabX0`` the output eliminated there, then its
frontier), ``TabF`` and ``TabB`` the forward and backward messages (``F_{-1}`` and ``B_n``
one entry each, TRUE). The body tabulates every bag from the cycle's inputs, then, per
criterion ``Max(g)`` of bag ``k``, sets ``TabBest`` when some entry of bag ``k`` with its
messages and ``g`` is true (the loop exits there) and narrows the bag by ``g = TabBest``;
a message is computed again before it is read when a bag it depends on may have been
narrowed since (a schedule fixed here, not at run time: recomputing a message that has
not changed gives it again). Each output is then TRUE when an entry of its bag with the
output at 1 is left with its messages: the value :func:`synth.filter.local.run` gives at
that cycle's point, FALSE everywhere when no safe vector exists.

Loop indices are ``INT`` (``TabV`` the entry, ``TabI`` a message's); the bits of an index are
``(TabV / 2^i) MOD 2``. No generated loop runs once (MATIEC's releases of June to November
2024 skip a ``FOR i := 0 TO 0``): one-entry loops are written without ``FOR``.
"""

from __future__ import annotations

from typing import Callable

from synth.codegen.st import Declaration
from synth.filter.language_reader import filter_expression
from synth.filter.local import Bag, Plan
from synth.logic.bdd import Engine, Function
from synth.logic.expr import Expr

__all__ = ["TABLE_NAMES", "tables_body"]

TABLE_NAMES = ("TabD", "TabF", "TabB", "TabV", "TabI", "TabBest")
"""The block's own variables (with ``TabX0``, ``TabX1``, … the bits of an entry)."""

Writer = Callable[[Expr, dict[str, str]], str]
"""An expression in ST, the outputs at t mapped to other ST places."""


def bit_names(width: int) -> tuple[str, ...]:
    """The names of an entry's bits."""
    return tuple(f"TabX{i}" for i in range(width))


class _Body:
    def __init__(self, p: Plan, engine: Engine, write: Writer) -> None:
        self.plan, self.engine, self.write = p, engine, write
        sizes = [1 << len(b.anchors) for b in p.bags]
        self.dom = [sum(sizes[:k]) for k in range(len(sizes) + 1)]
        fsizes = [1] + [s >> 1 for s in sizes]  # F_{-1}, F_0 … F_{n-1}
        self.fwd = [sum(fsizes[:k]) for k in range(len(fsizes) + 1)]
        bsizes = [1] + [s >> 1 for s in sizes]  # B_0 (over an empty frontier), B_1 … B_n
        self.bwd = [sum(bsizes[:k]) for k in range(len(bsizes) + 1)]
        self.lines: list[str] = []
        self.valid_f, self.valid_b = -1, len(p.bags)  # F_k valid for k ≤ valid_f, B_k for k ≥ valid_b
        self.texts: dict[Function, Expr] = {}

    # ---- places
    def d(self, k: int, index: str) -> str:
        return f"TabD[{self.dom[k]} + {index}]" if self.dom[k] else f"TabD[{index}]"

    def f(self, k: int, index: str) -> str:
        """``F_k`` (``k`` = -1: the constant first message)."""
        return f"TabF[{self.fwd[k + 1]} + {index}]" if self.fwd[k + 1] else f"TabF[{index}]"

    def b(self, k: int, index: str) -> str:
        return f"TabB[{self.bwd[k]} + {index}]" if self.bwd[k] else f"TabB[{index}]"

    def before(self, k: int) -> str:
        """The index of ``F_{k-1}`` (and ``B_k``) of entry ``TabV`` of bag ``k``."""
        bag = self.plan.bags[k]
        if k == 0:
            return "0"
        positions = [bag.anchors.index(a) for a in self.plan.bags[k - 1].anchors[1:]]
        terms = [_bit("TabV", b) + ("" if i == 0 else f" * {1 << i}") for i, b in enumerate(positions)]
        return " + ".join(terms) or "0"

    def expression(self, u: Function, bag: Bag) -> str:
        e = self.engine
        x = self.texts.get(u)
        if x is None:
            x = self.texts[u] = filter_expression(e.text(u), "table")
        return self.write(x, dict(zip(bag.anchors, bit_names(len(bag.anchors)))))

    def bits(self, u: Function, bag: Bag) -> list[str]:
        """The assignments of the bits of ``TabV`` that ``u`` reads."""
        read = set(self.engine.support(u))
        return [f"{name} := {_bit('TabV', i)} = 1;" for i, (a, name) in
                enumerate(zip(bag.anchors, bit_names(len(bag.anchors)))) if a in read]

    # ---- statements
    def loop(self, var: str, count: int, body: list[str]) -> None:
        if count == 1:
            self.lines += [line.replace(var, "0") for line in body]
        else:
            self.lines += [f"FOR {var} := 0 TO {count - 1} DO", *("    " + line for line in body), "END_FOR;"]

    def tabulate(self, k: int) -> None:
        bag = self.plan.bags[k]
        self.lines.append(f"(* bag {k + 1}: {', '.join(bag.anchors)} *)")
        self.loop("TabV", 1 << len(bag.anchors),
                  [*self.bits(bag.relation, bag), f"{self.d(k, 'TabV')} := {self.expression(bag.relation, bag)};"])

    def forward(self, k: int) -> None:
        n = len(self.plan.bags[k].anchors)
        self.loop("TabI", 1 << (n - 1), [f"{self.f(k, 'TabI')} := FALSE;"])
        self.loop("TabV", 1 << n, [f"IF {self.d(k, 'TabV')} AND {self.f(k - 1, self.before(k))} THEN",
                                   f"    {self.f(k, 'TabV / 2')} := TRUE;", "END_IF;"])

    def backward(self, k: int) -> None:
        n = len(self.plan.bags[k].anchors)
        self.loop("TabI", 1 << (len(self.plan.bags[k - 1].anchors) - 1) if k else 1, [f"{self.b(k, 'TabI')} := FALSE;"])
        self.loop("TabV", 1 << n, [f"IF {self.d(k, 'TabV')} AND {self.b(k + 1, 'TabV / 2')} THEN",
                                   f"    {self.b(k, self.before(k))} := TRUE;", "END_IF;"])

    def messages(self, k: int) -> None:
        """Make ``F_{k-1}`` and ``B_{k+1}`` valid."""
        for i in range(self.valid_f + 1, k):
            self.forward(i)
        self.valid_f = max(self.valid_f, k - 1)
        for i in range(self.valid_b - 1, k, -1):
            self.backward(i)
        self.valid_b = min(self.valid_b, k + 1)

    def entry(self, k: int) -> str:
        """Entry ``TabV`` of bag ``k`` with its messages."""
        return f"{self.d(k, 'TabV')} AND {self.f(k - 1, self.before(k))} AND {self.b(k + 1, 'TabV / 2')}"

    def criterion(self, number: int, k: int, g: Function, label: str) -> None:
        bag, size = self.plan.bags[k], 1 << len(self.plan.bags[k].anchors)
        self.messages(k)
        good = self.expression(g, bag)
        self.lines += [f"(* criterion {number}: {label} *)", "TabBest := FALSE;"]
        self.loop("TabV", size, [*self.bits(g, bag), f"IF {self.entry(k)} AND ({good}) THEN",
                                 "    TabBest := TRUE;", "    EXIT;", "END_IF;"] if size > 1 else
                  [*self.bits(g, bag), f"TabBest := {self.entry(k)} AND ({good});"])
        self.loop("TabV", size, [*self.bits(g, bag), f"{self.d(k, 'TabV')} := {self.d(k, 'TabV')} AND NOT (({good}) XOR TabBest);"])
        self.valid_f, self.valid_b = min(self.valid_f, k - 1), max(self.valid_b, k + 1)

    def output(self, k: int) -> None:
        o, size = self.plan.bags[k].anchors[0], 1 << len(self.plan.bags[k].anchors)
        self.messages(k)
        self.lines.append(f"{o} := FALSE;")
        self.loop("TabI", size >> 1, ["TabV := 2 * TabI + 1;", f"IF {self.entry(k)} THEN",
                                      f"    {o} := TRUE;", "    EXIT;", "END_IF;"] if size > 2 else
                  ["TabV := 1;", f"{o} := {self.entry(k)};"])


def _bit(index: str, i: int) -> str:
    return f"{index} MOD 2" if i == 0 else f"({index} / {1 << i}) MOD 2"


def tables_body(p: Plan, engine: Engine, write: Writer, labels: list[str]) -> tuple[list[str], list[Declaration]]:
    """The statements and local variables of the block's body (module docstring); ``write``
    renders an expression (outputs at t mapped to the entry's bits); ``labels``: one comment
    per criterion."""
    body = _Body(p, engine, write)
    body.lines += [f"{body.f(-1, '0')} := TRUE;", f"{body.b(len(p.bags), '0')} := TRUE;"]
    for k in range(len(p.bags)):
        body.tabulate(k)
    for number, ((k, g), label) in enumerate(zip(p.steps, labels), 1):
        body.criterion(number, k, g, label)
    for k in range(len(p.bags)):
        body.output(k)
    decls = [Declaration("TabD", f"ARRAY[0..{body.dom[-1] - 1}] OF BOOL", comment="each bag's table"),
             Declaration("TabF", f"ARRAY[0..{body.fwd[-1] - 1}] OF BOOL", comment="the forward messages"),
             Declaration("TabB", f"ARRAY[0..{body.bwd[-1] - 1}] OF BOOL", comment="the backward messages"),
             Declaration("TabV", "INT", comment="an entry of a bag"), Declaration("TabI", "INT"),
             Declaration("TabBest", comment="the criterion finds a solution")]
    decls += [Declaration(x) for x in bit_names(p.width)]
    return body.lines, decls
