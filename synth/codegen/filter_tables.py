"""The body of a filter block that runs the synthesis's chain of narrowings each cycle on
truth tables (:mod:`synth.filter.local`), for filters whose equations are too large to
print (docs/filter.md, "The chain on tables"): one fixed loop nest driven by constant
tables, so its length does not grow with the filter's.

The data (``VAR CONSTANT``, written once per block):

- per bag ``k``: ``TabKD[k]``, the offset of its table in ``TabD`` (entry ``v``: the bag's
  relation with its outputs at the bits of ``v``, bit 0 the output eliminated there, then
  its frontier; ``TabKD[n]`` the end), ``TabKM[k]`` the offset of the forward message
  ``F_{k-1}`` in ``TabF`` and of the backward message ``B_k`` in ``TabB`` (both tables over
  the previous bag's frontier; ``F_{-1}`` and ``B_n`` one entry each, TRUE), ``TabKP[k]``
  that of the projection giving, for each ``v``, the index of the previous bag's frontier
  valuation in it (where ``F_{k-1}`` and ``B_k`` are read and written);
- the functions the loop reads (each bag's relation, each criterion's ``g``, and the
  output itself for the outputs' search): ``TabUR[u]``, the offset of the function's row in
  ``TabR`` (the function at each valuation of the bag's outputs it reads, bit ``j`` the
  ``j``-th of them), ``TabUP[u]``, that of the projection of ``v`` on those outputs;
- ``TabP``: the projections, each once per tuple of bit positions;
- per step (each criterion ``Max(g)`` in order, then one per bag for its output):
  ``TabSK[s]`` its bag and ``TabSU[s]`` its function.

Each cycle the rows that depend on the cycle's inputs are computed (``TabR[i] := …``, one
line per cofactor that is not a constant: the constants are ``TabR``'s initial values), each
bag's table is read from its relation's row, then step after step: the messages the step's
bag reads are brought up to date (``TabVF``/``TabVB``: the last valid ones, a message being
computed again when a criterion removed an entry of a bag before (after) it since: ``TabCut``,
as :mod:`synth.filter.local` drops a message only when a bag changed), ``TabBest`` is
set when some entry of the bag with its messages and ``g`` is true, and for a criterion the
bag keeps the entries where ``g`` equals ``TabBest``; an output's step keeps ``TabBest`` in
``TabO``. Each output is then TRUE when an entry of its bag with the output at 1 is left
with its messages: the value :func:`synth.filter.local.run` gives at that cycle's point,
FALSE everywhere when no safe vector exists.

Every index is a ``DINT``; every loop is a ``WHILE`` (MATIEC's releases of June to November
2024 skip a ``FOR i := 0 TO 0``, and these bounds are read at run time).
"""

from __future__ import annotations

from typing import Callable

from synth.codegen.st import Declaration
from synth.filter.language_reader import filter_expression
from synth.filter.local import Plan, Symbolic
from synth.logic.bdd import Engine, Function
from synth.logic.expr import Expr

__all__ = ["table_names", "tables_body"]

_DATA = ("TabKD", "TabKM", "TabKP", "TabUR", "TabUP", "TabP", "TabSK", "TabSU")
_STATE = ("TabR", "TabD", "TabF", "TabB", "TabO", "TabS", "TabK", "TabU", "TabV", "TabJ", "TabE", "TabA",
          "TabPF", "TabPB", "TabPP", "TabPR", "TabPU", "TabVF", "TabVB", "TabBest", "TabCut")
_PER_LINE = 32
"""Values per line of a constant array's initial value."""

Writer = Callable[[Expr, dict[str, str]], str]
"""An expression in ST, the outputs at t mapped to other ST places."""


def table_names() -> tuple[str, ...]:
    """The block's own variables (a filter's names must differ from them)."""
    return _DATA + _STATE


class _Data:
    """The constant tables of a plan (module docstring)."""

    def __init__(self, p: Plan, engine: Engine, write: Writer) -> None:
        self.plan, self.engine, self.write = p, engine, write
        sizes = [1 << len(b.anchors) for b in p.bags]
        self.dom = _offsets(sizes)
        self.messages = _offsets([1] + [s >> 1 for s in sizes])  # F_{-1} and B_0, then F_k and B_(k+1)
        self.projection_size: dict[tuple[int, ...], int] = {}
        self.rows: dict[tuple[Function, tuple[str, ...]], int] = {}  # each row's offset in TabR
        self.row_values: list[bool] = []
        self.row_lines: list[str] = []
        self.functions: list[tuple[int, tuple[int, ...]]] = []
        self.function_of: dict[tuple[int, Function], int] = {}
        self.before = [self.positions(k) for k in range(len(p.bags))]
        for k, bag in enumerate(p.bags):
            self.function(k, bag.relation, f"bag {k + 1}'s relation")
        self.steps = [(k, self.function(k, g, f"criterion {n}")) for n, (k, g) in enumerate(p.steps, 1)]
        self.steps += [(k, self.function(k, engine.var(b.anchors[0]), b.anchors[0])) for k, b in enumerate(p.bags)]

    def positions(self, k: int) -> tuple[int, ...]:
        """The bit positions in bag ``k`` of the previous bag's frontier, registered."""
        anchors = self.plan.bags[k].anchors
        return self.projection(tuple(anchors.index(a) for a in self.plan.bags[k - 1].anchors[1:]) if k else (), k)

    def projection(self, bits: tuple[int, ...], k: int) -> tuple[int, ...]:
        size = 1 << len(self.plan.bags[k].anchors)
        self.projection_size[bits] = max(size, self.projection_size.get(bits, 0))
        return bits

    def function(self, k: int, u: Function, what: str) -> int:
        """The number of ``u`` read in bag ``k`` (its row and projection made once)."""
        key = (k, u)
        if key in self.function_of:
            return self.function_of[key]
        anchors = self.plan.bags[k].anchors
        read = set(self.engine.support(u))
        bits = tuple(i for i, a in enumerate(anchors) if a in read)
        names = tuple(anchors[i] for i in bits)
        row = self.rows.get((u, names))
        if row is None:
            row = self.rows[(u, names)] = self.row(u, names, what)
        self.functions.append((row, self.projection(bits, k)))
        self.function_of[key] = len(self.functions) - 1
        return len(self.functions) - 1

    def row(self, u: Function, names: tuple[str, ...], what: str) -> int:
        """``u``'s cofactors on ``names`` (its offset in ``TabR``): the constants kept as
        initial values, the others one line each (initially FALSE)."""
        e, offset = self.engine, len(self.row_values)
        for w, c in enumerate(Symbolic(e).table(u, names)):
            self.row_values.append(c == e.true)
            if c in (e.true, e.false):
                continue
            at = ", ".join(f"{n}={(w >> j) & 1}" for j, n in enumerate(names))
            text = self.write(filter_expression(e.text(c), "table"), {})
            self.row_lines.append(f"TabR[{offset + w}] := {text}; (* {what}{' at ' + at if at else ''} *)")
        return offset

    def projection_data(self) -> tuple[list[int], dict[tuple[int, ...], int]]:
        """``TabP`` and each projection's offset in it."""
        data: list[int] = []
        where: dict[tuple[int, ...], int] = {}
        for bits, size in sorted(self.projection_size.items(), key=lambda x: (len(x[0]), x[0])):
            where[bits] = len(data)
            data += [sum(((v >> b) & 1) << j for j, b in enumerate(bits)) for v in range(size)]
        return data, where


def _offsets(sizes: list[int]) -> list[int]:
    out = [0]
    for s in sizes:
        out.append(out[-1] + s)
    return out


def _array(name: str, values: list[int] | list[bool], comment: str, kind: str = "DINT") -> Declaration:
    texts = [("TRUE" if v else "FALSE") if kind == "BOOL" else str(v) for v in values]
    chunks = [", ".join(texts[i:i + _PER_LINE]) for i in range(0, len(texts), _PER_LINE)]
    init = "[" + ",\n        ".join(chunks) + "]" if len(chunks) > 1 else f"[{chunks[0]}]"
    return Declaration(name, f"ARRAY[0..{len(values) - 1}] OF {kind}", init, comment=comment)


_LOOP = """\
TabF[0] := TRUE;
TabB[{last_b}] := TRUE;
(* each bag's table from its relation's row *)
TabK := 0;
WHILE TabK < {bags} DO
    TabA := TabKD[TabK];
    TabE := TabKD[TabK + 1] - TabA;
    TabPR := TabUR[TabK];
    TabPU := TabUP[TabK];
    TabV := 0;
    WHILE TabV < TabE DO
        TabD[TabA + TabV] := TabR[TabPR + TabP[TabPU + TabV]];
        TabV := TabV + 1;
    END_WHILE;
    TabK := TabK + 1;
END_WHILE;
(* the criteria in order, then each bag's output *)
TabVF := -1;
TabVB := {bags};
TabS := 0;
WHILE TabS < {steps} DO
    TabK := TabSK[TabS];
    WHILE TabVF < TabK - 1 DO (* F_(VF+1) from F_VF *)
        TabVF := TabVF + 1;
        TabA := TabKD[TabVF];
        TabE := TabKD[TabVF + 1] - TabA;
        TabPF := TabKM[TabVF];
        TabPB := TabKM[TabVF + 1];
        TabPP := TabKP[TabVF];
        TabJ := TabPB;
        WHILE TabJ < TabKM[TabVF + 2] DO
            TabF[TabJ] := FALSE;
            TabJ := TabJ + 1;
        END_WHILE;
        TabV := 0;
        WHILE TabV < TabE DO
            IF TabD[TabA + TabV] AND TabF[TabPF + TabP[TabPP + TabV]] THEN
                TabF[TabPB + TabV / 2] := TRUE;
            END_IF;
            TabV := TabV + 1;
        END_WHILE;
    END_WHILE;
    WHILE TabVB > TabK + 1 DO (* B_(VB-1) from B_VB *)
        TabVB := TabVB - 1;
        TabA := TabKD[TabVB];
        TabE := TabKD[TabVB + 1] - TabA;
        TabPF := TabKM[TabVB];
        TabPB := TabKM[TabVB + 1];
        TabPP := TabKP[TabVB];
        TabJ := TabPF;
        WHILE TabJ < TabPB DO
            TabB[TabJ] := FALSE;
            TabJ := TabJ + 1;
        END_WHILE;
        TabV := 0;
        WHILE TabV < TabE DO
            IF TabD[TabA + TabV] AND TabB[TabPB + TabV / 2] THEN
                TabB[TabPF + TabP[TabPP + TabV]] := TRUE;
            END_IF;
            TabV := TabV + 1;
        END_WHILE;
    END_WHILE;
    TabU := TabSU[TabS];
    TabA := TabKD[TabK];
    TabE := TabKD[TabK + 1] - TabA;
    TabPF := TabKM[TabK];
    TabPB := TabKM[TabK + 1];
    TabPP := TabKP[TabK];
    TabPR := TabUR[TabU];
    TabPU := TabUP[TabU];
    TabBest := FALSE;
    TabV := 0;
    WHILE TabV < TabE AND NOT TabBest DO
        TabBest := TabD[TabA + TabV] AND TabR[TabPR + TabP[TabPU + TabV]] AND TabF[TabPF + TabP[TabPP + TabV]]
                   AND TabB[TabPB + TabV / 2];
        TabV := TabV + 1;
    END_WHILE;
    IF TabS < {criteria} THEN (* a criterion: the bag keeps the entries where g = TabBest *)
        TabCut := FALSE;
        TabV := 0;
        WHILE TabV < TabE DO
            IF TabD[TabA + TabV] AND (TabR[TabPR + TabP[TabPU + TabV]] <> TabBest) THEN
                TabD[TabA + TabV] := FALSE;
                TabCut := TRUE;
            END_IF;
            TabV := TabV + 1;
        END_WHILE;
        IF TabCut AND TabVF > TabK - 1 THEN (* the messages past a narrowed bag *)
            TabVF := TabK - 1;
        END_IF;
        IF TabCut AND TabVB < TabK + 1 THEN
            TabVB := TabK + 1;
        END_IF;
    ELSE
        TabO[TabK] := TabBest;
    END_IF;
    TabS := TabS + 1;
END_WHILE;"""


def tables_body(p: Plan, engine: Engine, write: Writer,
                labels: list[str]) -> tuple[list[str], list[Declaration], list[Declaration]]:
    """The statements, local variables and constants of the block's body (module docstring);
    ``write`` renders an expression of the cycle's inputs; ``labels``: one comment per criterion."""
    d = _Data(p, engine, write)
    data, where = d.projection_data()
    n, steps = len(p.bags), len(d.steps)
    lines = [f"(* the criteria, steps 1 to {len(p.steps)} (then one step per bag for its output):",
             *[f"   {i}. bag {k + 1}: {label}" for i, ((k, _), label) in enumerate(zip(p.steps, labels), 1)],
             "*)", "(* the rows read from this cycle's inputs *)", *d.row_lines]
    lines += _LOOP.format(last_b=d.messages[n], bags=n, steps=steps, criteria=len(p.steps)).splitlines()
    lines += [f"{b.anchors[0]} := TabO[{k}];" for k, b in enumerate(p.bags)]
    decls = [
        _array("TabKD", d.dom, "each bag's table in TabD (and the end)"),
        _array("TabKM", d.messages, "F_(k-1) in TabF and B_k in TabB (F_(-1) first, B_n last)"),
        _array("TabKP", [where[b] for b in d.before], "each bag's projection on the previous frontier, in TabP"),
        _array("TabUR", [r for r, _ in d.functions], "each function's row in TabR"),
        _array("TabUP", [where[b] for _, b in d.functions], "each function's projection in TabP"),
        _array("TabP", data, "the projections: entry v to the index of some of its bits"),
        _array("TabSK", [k for k, _ in d.steps], "each step's bag"),
        _array("TabSU", [u for _, u in d.steps], "each step's function"),
    ]
    state = [
        _array("TabR", d.row_values, "the functions' rows (constants; the others each cycle)",
               "BOOL"),
        Declaration("TabD", f"ARRAY[0..{d.dom[-1] - 1}] OF BOOL", comment="each bag's table"),
        Declaration("TabF", f"ARRAY[0..{d.messages[-1] - 1}] OF BOOL", comment="the forward messages"),
        Declaration("TabB", f"ARRAY[0..{d.messages[-1] - 1}] OF BOOL", comment="the backward messages"),
        Declaration("TabO", f"ARRAY[0..{n - 1}] OF BOOL", comment="each bag's output"),
        *[Declaration(x, "DINT") for x in _STATE[5:-2]],
        Declaration("TabBest", comment="the step finds an entry"),
        Declaration("TabCut", comment="the criterion removed an entry"),
    ]
    return lines, state, decls
