"""The blocks of a transition network in a file written by Beremiz or the OpenPLC editor
(``synth import``), called as Beremiz's generator calls them.

Read on Beremiz (``PLCGenerator.py``: ``GenerateSFCTransition``, ``GenerateBlock``,
``ComputeProgram``): every block wired in an FBD/LD transition network, in the SFC body or in a
named transition's body, functions (``AND``, ``OR``, ``NOT``, ``SEL``) as well as function blocks,
is written once, in the order the generator meets it (transitions in file order, each block's
inputs before the block), into an action ``COMPUTE_FUNCTION_BLOCKS`` stored (qualifier ``S``)
on the first initial step; the transition reads the block's output variable (``TON3.Q``,
``_TMP_OR35_OUT``). Blocks in action bodies stay in their actions. MATIEC runs a scan as:
transitions evaluated, steps updated, actions run. So the blocks are called at every scan,
whatever the active steps, after the transitions, and a transition reads each block's output
of the previous scan.

Under ``--semantics sfc`` (one evolution per scan, of every grafcet at once) that is exactly a
partial grafcet per block whose steps are the block's states, read through its step variables:

* ``SR``/``RS`` ``I``: steps ``I_off``/``I_on`` (``Q1`` is ``XI_on``);
* ``R_TRIG`` ``I``: ``I_off`` (CLK was FALSE), ``I_q`` (``Q``: CLK rose), ``I_held``;
  ``F_TRIG``: ``I_off``, ``I_hi`` (CLK was TRUE), ``I_q`` (``Q``: CLK fell);
* ``TON`` ``I``: ``I_off``, ``I_timing`` (IN rose, ``PT`` not elapsed), ``I_q`` (``Q``);
* a function read by a transition: ``T<localId>`` (``_TMP_T<localId>_OUT``), steps ``_off``/``_on``.

An input wired to another block reads that block's output of this scan when Beremiz calls
that block first (its next state, as an expression), of the previous scan in a loop.

Example
-------
>>> rising_chart("R0", "go")[2]
[(['R0_off'], ['R0_q'], 'go'), (['R0_q'], ['R0_held'], 'go'), (['R0_q'], ['R0_off'], '!go'), (['R0_held'], ['R0_off'], '!go')]
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from typing import Any, Callable

from synth.codegen.plcopen.blocks import sel, warn_block
from synth.codegen.plcopen.data import DATA, DataScope, HelperChart, duration
from synth.codegen.plcopen.latch import LATCH_BLOCKS
from synth.codegen.plcopen.vendor import Dialect
from synth.errors import InputError, Location, Severity, SynthError
from synth.grafcet.language_reader import parse_receptivity
from synth.logic.expr import Var, evaluate, names

__all__ = ["SCAN_BLOCKS", "every_scan", "scan_block", "lagging", "rising_chart", "first_scan_guard", "negation",
           "settle_step_reads", "after_scan"]

SCAN_BLOCKS = {"AND": (), "OR": (), "NOT": ("IN",), "SEL": ("G", "IN0", "IN1"), "R_TRIG": ("CLK",),
               "F_TRIG": ("CLK",), "TON": ("IN", "PT"), **LATCH_BLOCKS}
"""The blocks read in a Beremiz transition network, with the inputs each needs."""

COMPUTE = ("Beremiz calls it at every scan whatever the active steps, after the transitions (its action "
           "COMPUTE_FUNCTION_BLOCKS, stored on the initial step), so a transition reads its output of the previous "
           "scan")


@dataclass
class Call:
    """One block of COMPUTE_FUNCTION_BLOCKS: its output after this scan's call (``now``, None
    while its inputs are read) and after the previous scan's (``before``, a step variable)."""

    name: str
    kind: str
    where: Location
    now: str | None = None
    before: str = ""
    register: bool = False  # a function whose previous output is read: its register grafcet is due
    label: str = ""  # how the warnings name it


def every_scan() -> bool:
    """Whether the chart being read comes from a file written by Beremiz or the OpenPLC editor."""
    scope = DATA.get()
    return scope is not None and scope.dialect[0] is Dialect.BEREMIZ


def lagging(text: str, steps: dict[str, str]) -> str | None:
    """The step timer of the chart that the block input ``text`` reads, if any: the PLC updates
    it before it calls the block (this scan's value), .g7 reads it before the scan. (A step flag
    is read as the PLC reads it: :func:`settle_step_reads`.)"""
    chart = set(steps.values())
    found = [m[0] for m in re.finditer(r"(?<!\w)\w+/X(\w+)", text) if m[1] in chart]
    return found[0] if found else None


def _atom(x: str) -> str:
    return x if re.fullmatch(r"!?[\w/.↑↓]+", x) or _top(x) == "" and x.startswith("(") else f"({x})"


def _top(x: str) -> str:
    """The operators of ``x`` outside parentheses ("&", "|", both or none)."""
    depth, found = 0, set()
    for ch in x:
        depth += {"(": 1, ")": -1}.get(ch, 0)
        if depth == 0 and ch in "&|":
            found.add(ch)
    return "".join(sorted(found))


def negation(x: str) -> str:
    if x in ("0", "1"):
        return "1" if x == "0" else "0"
    return x[1:] if re.fullmatch(r"![\w/.↑↓]+", x) else "!" + _atom(x)


def _and(*xs: str) -> str:
    if "0" in xs:
        return "0"
    return " & ".join(f"({x})" if "|" in _top(x) else x for x in xs if x != "1") or "1"


def _or(*xs: str) -> str:
    if "1" in xs:
        return "1"
    return " | ".join(x for x in xs if x != "0") or "0"


def _chart(name: str, steps: list[str], moves: list[tuple[str, str, str]]) -> HelperChart:
    """A partial grafcet: ``steps`` (the first initial), ``moves`` (source, target, receptivity)
    but those that never fire (receptivity 0)."""
    return (name, [(s, i == 0, []) for i, s in enumerate(steps)], [([a], [b], r) for a, b, r in moves if r != "0"])


def two_step(name: str, off: str, on: str, up: str, down: str) -> HelperChart:
    return _chart(name, [off, on], [(off, on, up), (on, off, down)])


def rising_chart(name: str, clk: str) -> HelperChart:
    """The partial grafcet of ``R_TRIG`` ``name`` of ``clk``: ``Q := CLK AND NOT M; M := CLK``."""
    off, q, held = f"{name}_off", f"{name}_q", f"{name}_held"
    return _chart(f"{name}_R_TRIG", [off, q, held],
                  [(off, q, clk), (q, held, clk), (q, off, negation(clk)), (held, off, negation(clk))])


def _falling_chart(name: str, clk: str) -> HelperChart:
    """``F_TRIG``: ``Q := NOT CLK AND M; M := CLK`` (M FALSE at the first call)."""
    off, hi, q = f"{name}_off", f"{name}_hi", f"{name}_q"
    return _chart(f"{name}_F_TRIG", [off, hi, q],
                  [(off, hi, clk), (hi, q, negation(clk)), (q, hi, clk), (q, off, negation(clk))])


def _ton_chart(name: str, on: str, pt: str) -> HelperChart:
    """MATIEC's ``TON``: STATE 0 -> 1 when IN rises (START_TIME := now), 1 -> 2 (Q) when IN and
    START_TIME + PT <= now, any -> 0 when IN is FALSE."""
    off, timing, q = f"{name}_off", f"{name}_timing", f"{name}_q"
    return _chart(f"{name}_TON", [off, timing, q], [(off, timing, on), (timing, off, negation(on)),
                                                    (timing, q, _and(on, f"{pt}/X{timing}")), (q, off, negation(on))])


def scan_block(el: Any, params: dict[str, tuple[Callable[[], str], Any]], by_block: bool, where: Location,
               pt_text: Callable[[], tuple[str, Location]] | None, lag: Callable[[str], str | None],
               edge: str = "") -> str:
    """The value of block ``el`` read by a transition (its output of the previous scan) or, when
    ``by_block``, by the input of a block Beremiz calls after it (of this scan, unless in a loop).
    ``params``: each input's reader (called in file order, as Beremiz does) and element. With
    ``edge`` (``rising``/``falling``), ``el`` is a contact or a block input with that edge, which
    Beremiz writes as an ``R_TRIG``/``F_TRIG`` of its variable (``params``: its ``CLK``)."""
    scope = DATA.get()
    assert scope is not None
    kind = ("R_TRIG" if edge == "rising" else "F_TRIG") if edge else str(el.get("typeName") or "").upper()
    path = el.getroottree().getpath(el)
    call = scope.scan_calls.get(path)
    if call is None:
        name = str(el.get("instanceName") or "") or f"{kind}{el.get('localId') or len(scope.scan_calls)}"
        full = f"{scope.prefix}{name}"
        state = f"X{full}_on" if kind in LATCH_BLOCKS else f"X{full}_q" if kind in ("R_TRIG", "F_TRIG", "TON") else ""
        call = scope.scan_calls[path] = Call(full, kind, where, before=state)  # its state: read in a loop
        _run(call, params, where, pt_text, lag, scope, f"the {edge} edge of {{}} (an {kind} Beremiz adds)" if edge else "")
    if by_block and call.now is not None:
        return call.now
    if not call.before:  # a function: its register
        call.before, call.register = f"X{call.name}_on", True
        _register(call, scope, where)
    return call.before


def _register(call: Call, scope: DataScope, where: Location) -> None:
    if call.now is None or not call.register:
        return  # read in its own loop: registered once its inputs are read
    scope.extra_charts.append(two_step(call.name, f"{call.name}_off", f"{call.name}_on", call.now, negation(call.now)))
    warn_block(f"the {call.kind} {call.name.removeprefix(scope.prefix)} in a transition network of a file written by "
               f"{_who(scope)}: {COMPUTE}; read as the partial grafcet {call.name}, whose step {call.name}_on is active "
               f"when {call.now} held at the previous scan", where)


def _who(scope: DataScope) -> str:
    return f"{scope.dialect[0].value} ({scope.dialect[1]})"


def _run(call: Call, params: dict[str, tuple[Callable[[], str], Any]], where: Location,
         pt_text: Callable[[], tuple[str, Location]] | None, lag: Callable[[str], str | None], scope: DataScope,
         label: str) -> None:
    """Call the block once: read its inputs, make its partial grafcet, set ``call.now``
    (``label``: how to name it, ``{}`` standing for CLK, when it is an edge Beremiz adds)."""
    kind, name = call.kind, call.name
    missing = [p for p in SCAN_BLOCKS[kind] if p not in params]
    if missing:
        raise InputError(f"an FBD {kind} block without its input {missing[0]}", where)
    if kind in ("AND", "OR") and not params or kind == "NOT" and len(params) != 1:
        raise InputError(f"an FBD {kind} block with {len(params)} inputs", where)
    values = {p: read() for p, (read, _) in params.items() if p != "PT"}
    late = sorted({x for v in values.values() if (x := lag(v)) is not None})
    short = name.removeprefix(scope.prefix)
    named = call.label = label.format(values.get("CLK", "")) if label else f"the {kind} {short}"
    what = f"{named} in a transition network of a file written by {_who(scope)}: {COMPUTE}"
    if kind in ("AND", "OR", "NOT", "SEL"):
        args = list(values.values())
        call.now = (_and(*args) if kind == "AND" else _or(*args) if kind == "OR" else negation(args[0]) if kind == "NOT"
                    else sel(values["G"], values["IN0"], values["IN1"]))
        _register(call, scope, where)
    elif kind in LATCH_BLOCKS:
        s, r = (values[p] for p in LATCH_BLOCKS[kind])
        on = f"X{name}_on"
        up, down = (s, _and(r, negation(s))) if kind == "SR" else (_and(s, negation(r)), r)
        call.now = _or(s, _and(negation(r), on)) if kind == "SR" else _and(negation(r), _or(s, on))
        scope.extra_charts.append(two_step(f"{name}_{kind}", f"{name}_off", f"{name}_on", up, down))
        warn_block(f"{what}; read as the partial grafcet {name}_{kind} ({short}.Q1 is {on}: set when {up}, reset when "
                   f"{down}, {'set' if kind == 'SR' else 'reset'} dominant)", where)
    elif kind in ("R_TRIG", "F_TRIG"):
        clk = values["CLK"]
        chart = rising_chart(name, clk) if kind == "R_TRIG" else _falling_chart(name, clk)
        call.now = _and(f"X{name}_off", clk) if kind == "R_TRIG" else _and(f"X{name}_hi", negation(clk))
        scope.extra_charts.append(chart)
        warn_block(f"{what}; read as the partial grafcet {chart[0]}, whose step {name}_q is {short}.Q: CLK ({clk}) "
                   f"{'rose' if kind == 'R_TRIG' else 'fell'} at the previous scan"
                   + (" (the PLC's first call sees CLK TRUE as a rising edge, so does the grafcet)"
                      if kind == "R_TRIG" else ""), where)
    else:  # TON
        assert pt_text is not None  # a TON block, never an edge
        text, pt_at = pt_text()
        pt = duration(text) or scope.constant_durations.get(text.strip().upper())
        if pt is None:
            raise InputError(f"the PT of TON {short} is '{text.strip()}': a timer needs a constant duration such as "
                             "T#2s", pt_at)
        on = values["IN"]
        timing = f"X{name}_timing"
        call.now = _or(_and(timing, on, f"{pt}/{timing}"), _and(f"X{name}_q", on))
        scope.extra_charts.append(_ton_chart(name, on, pt))
        started = "IN is TRUE: a timer started at the first call, " if on == "1" else ""
        warn_block(f"{what}; read as the partial grafcet {name}_TON: {started}step {name}_timing from the scan IN "
                   f"({on}) rises, step {name}_q ({short}.Q) once {pt} have elapsed, both left when IN falls", where)
    for x in late:
        scope.warnings.append(InputError(
            f"{named} reads the step timer {x}, which the PLC's scan updates before it calls the block: the block "
            "sees this scan's value, the .g7 partial grafcet the previous scan's (one scan later)", where,
            severity=Severity.WARNING))


def after_scan(step: str, transitions: list[tuple[str, list[str], list[str], str, Any]]) -> str:
    """Whether ``step`` is active once this scan's transitions have fired: active and left by none
    of the transitions leaving it, or entered by one (each fires when its sources are active and
    its receptivity holds, every true one, as MATIEC fires them)."""
    def fires(sources: list[str], expr: str) -> str:
        return _and(*(f"X{s}" for s in sources), expr)

    leaving = [fires(s, e) for _, s, _, e, _ in transitions if step in s]
    return _or(_and(f"X{step}", negation(_or(*leaving))), *(fires(s, e) for _, s, t, e, _ in transitions if step in t))


def _moves(scope: DataScope, change: Callable[[str], str]) -> None:
    """Every move of the blocks' partial grafcets with its receptivity changed by ``change``."""
    firsts = {f"{c.name}_off" for c in scope.scan_calls.values()}
    scope.extra_charts[:] = [(c[0], c[1], [(a, b, change(r)) for a, b, r in c[2]]) if c[1][0][0] in firsts else c
                             for c in scope.extra_charts]


def settle_step_reads(transitions: list[tuple[str, list[str], list[str], str, Any]], chart: set[str]) -> None:
    """A block input reading the flag ``XS`` of a step of the chart reads it as the PLC does, once
    the scan's transitions have fired (MATIEC updates the steps before it runs the actions): each
    such flag in the blocks' moves becomes :func:`after_scan` of ``S``."""
    scope = DATA.get()
    if scope is None or not scope.scan_calls:
        return
    flag = re.compile(r"(?<![\w/])X(\w+)")
    for call in scope.scan_calls.values():
        read = sorted({m[1] for c in scope.extra_charts if c[1][0][0] == f"{call.name}_off"
                       for _, _, r in c[2] for m in flag.finditer(r) if m[1] in chart})
        for step in read:
            scope.warnings.append(InputError(
                f"{call.label} reads X{step}, which MATIEC updates before it calls the block: read as step {step} once "
                f"the scan's transitions have fired, {after_scan(step, transitions)}", call.where,
                severity=Severity.WARNING))
    _moves(scope, lambda r: flag.sub(lambda m: f"({after_scan(m[1], transitions)})" if m[1] in chart else m[0], r))


def first_scan_guard(transitions: list[tuple[str, list[str], list[str], str, Any]], initial: str, at: Location,
                     helper_steps: dict[str, bool]) -> list[InputError]:
    """When a transition leaving ``initial`` (the step that stores COMPUTE_FUNCTION_BLOCKS) may
    fire at the first scan (``helper_steps``: the blocks' steps, each with whether it is initial;
    timers not elapsed then), the PLC calls no block until ``initial`` is active after a scan:
    the partial grafcet ``COMPUTE_FUNCTION_BLOCKS`` (its step ``_on``: the action stored) and
    each block's moves guarded by it, with a located warning."""
    scope = DATA.get()
    if scope is None or not scope.scan_calls:
        return []
    may = next((e for _, s, _, e, _ in transitions if initial in s and _may_hold(e, helper_steps)), None)
    if may is None:
        return []
    after = after_scan(initial, transitions)
    name = f"{scope.prefix}COMPUTE_FUNCTION_BLOCKS"
    _moves(scope, lambda r: _and(f"(X{name}_on | {after})", r))
    scope.extra_charts.append(_chart(name, [f"{name}_off", f"{name}_on"], [(f"{name}_off", f"{name}_on", after)]))
    return [InputError(
        f"Beremiz stores COMPUTE_FUNCTION_BLOCKS (the blocks of the transition networks) on initial step {initial}: "
        f"the PLC calls them at the end of each scan after which {initial} is active, then at every scan; a transition "
        f"leaving {initial} may fire at the first scan ({may}), so the blocks' partial grafcets move only when step "
        f"{name}_on of the partial grafcet {name} (the action stored) is active or {initial} is active after the scan",
        at, severity=Severity.WARNING)]


def _may_hold(expr: str, helper_steps: dict[str, bool]) -> bool:
    """Whether ``expr`` may hold in the initial situation: helper steps at their initial
    activity, timers not elapsed, edges possible, at most 12 other names tried every way (more: it may)."""
    try:
        e = parse_receptivity(expr, "<receptivity>")
    except SynthError:  # a receptivity the grafcet checks later: assume it may hold
        return True
    free = sorted({a.name for a in names(e) if isinstance(a, Var) and not _fixed(a.name, helper_steps)})
    if len(free) > 12:
        return True
    for bits in range(1 << len(free)):
        values = {n: bool(bits >> i & 1) for i, n in enumerate(free)}
        if evaluate(e, lambda n: values.get(n, _initial(n, helper_steps)), lambda _: True):
            return True
    return False


def _fixed(name: str, helper_steps: dict[str, bool]) -> bool:
    return "/" in name or (name.startswith("X") and name[1:] in helper_steps)


def _initial(name: str, helper_steps: dict[str, bool]) -> bool:
    return name.startswith("X") and helper_steps.get(name[1:], False)
