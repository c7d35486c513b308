"""PLCopen TC6 XML in: the SFC POUs of a project back into ``.g7`` text (``synth import``).

Read: TC6 2.01 (``tc6_0201``, Beremiz and OpenPLC), 2.00 (``tc6_0200``, every CODESYS V3.5
export) and the 1.0 namespace ``tc6.xsd`` (old Beremiz projects). Every SFC POU is imported,
each as its own partial grafcet(s) (with several, their steps are prefixed by the POU's
name: ``Main_S1``); ``pou=`` selects one; :func:`list_pous` says what each POU holds and
what an import would lose. A POU that is not SFC is listed, never dropped silently.

:func:`import_sfc` reads an SFC as synth or a PLC IDE writes it (layout positions,
comments, vendor ``addData``, ``jumpStep``); what ``.g7`` cannot represent is an
:class:`~synth.errors.InputError` at its line in the XML. The mapping is the exporter's
(:mod:`synth.codegen.plcopen.export`).

Example
-------
>>> from synth.grafcet.language_check import parse_grafcet
>>> from synth.codegen.plcopen.export import sfc_project_xml
>>> g = parse_grafcet("grafcet G { initial step 0 step 1: A if b "
...                   "transition 0 -> 1 when ↑a transition 1 -> 0 when !a }", "g.g7")
>>> print(import_sfc(sfc_project_xml(g, version="0.1.0"), "g.xml").split("\\n", 1)[1])
inputs a, b
outputs A_1
<BLANKLINE>
grafcet G {
  initial step 0
  step 1: A_1 if b
  transition 0 -> 1 when ↑a
  transition 1 -> 0 when !a
}
<BLANKLINE>
"""

from __future__ import annotations

import contextvars
import re
from typing import Any

from synth.codegen.plcopen.actions import ACTION_WARNINGS, action_body
from synth.codegen.plcopen.assign import sum_text
from synth.codegen.plcopen.data import DATA, duration
from synth.codegen.plcopen.instances import separate_instances
from synth.codegen.plcopen.project import NAMESPACES, PouSummary, body_language, list_pous, pous_of, read_project, summaries
from synth.codegen.plcopen.sfc import Chart, Source, read_chart
from synth.codegen.plcopen.mirrors import merge_mirrors
from synth.codegen.plcopen.shared import MARK, merge_shared, shared_assignment, without_shared_or
from synth.codegen.plcopen.timers import prepare_scope
from synth.codegen.plcopen.vendor import IecQualifier, dialect_of
from synth.codegen.plcopen.tc6 import Qualifier
from synth.codegen.plcopen.st_condition import PREDICATES, ExprReader, st_text
from synth.errors import InputError, Location, Severity
from synth.version import version as synth_version

__all__ = ["import_sfc", "checked_pous", "list_pous", "PouSummary", "NAMESPACES"]

def import_sfc(data: bytes | str, file: str = "<xml>", pou: str | None = None,
               notes: list[str] | None = None, warnings: list[InputError] | None = None) -> str:
    """The ``.g7`` text of the SFC POUs of a PLCopen XML project (``pou``: that one only).

    Layout (positions), comments, documentation and vendor ``addData`` are ignored;
    ``jumpStep`` is a link to its target step. Elements ``.g7`` cannot represent (macro-steps,
    LD objects, qualifiers other than N/S/R/P0/P1) are an :class:`~synth.errors.InputError`
    at their line. ``notes`` receives what was left out (POUs that are not SFC), ``warnings``
    where IEC 61131-3 SFC and IEC 60848 read the chart differently (located).
    """
    root, src, q = read_project(data, file)
    all_pous = pous_of(root, q)
    sfc_pous = [(p, p.find(f"{q('body')}/{q('SFC')}")) for p in all_pous]
    sfc_pous = [(p, s) for p, s in sfc_pous if s is not None]
    names = [str(p.get("name", "")) for p in all_pous]
    if pou is not None:
        chosen = [(p, s) for p, s in sfc_pous if p.get("name") == pou]
        if not chosen:
            from synth.errors import close_names

            raise InputError(f"no SFC POU named {pou} in this file", Location("--pou", 1, 1, pou, max(1, len(pou))),
                             expected=tuple(str(p.get("name")) for p, _ in sfc_pous) or ("(no SFC POU)",),
                             suggestions=close_names(pou, [str(p.get("name")) for p, _ in sfc_pous]))
        sfc_pous = chosen
    if not sfc_pous:
        raise InputError("no POU with an SFC body in this file", src.at(root),
                         notes=(("POUs: " + ", ".join(names)) if names else "the file has no POU",))
    if notes is not None:  # the whole file: every POU left out; one POU (--pou): the charts inside it left out
        notes += [f"POU {s.name} not imported: {s.note}" if not s.imported else f"POU {s.name}: {s.note}"
                  for s in summaries(root, q) if (pou is None and not s.imported or "SFC in its action" in s.note)
                  and (pou is None or s.name == pou)]
    several = len(sfc_pous) > 1
    charts = []
    for p, s in sfc_pous:
        token = PREDICATES.set({})  # comparisons become declared predicates while a chart is read
        action_warnings: list[InputError] = []
        token2 = ACTION_WARNINGS.set(action_warnings)
        held: list[tuple[str, str, Location]] = []
        token4 = HELD.set(held)
        prefix = f"{p.get('name')}_" if several else ""
        scope = prepare_scope(p, s, q, src.at, prefix, src.text_at)
        scope.dialect = dialect_of(root, q)
        token3 = DATA.set(scope)
        try:
            charts.append(read_chart(p, s, q, src, _read_action, prefix))
        finally:
            PREDICATES.reset(token)
            ACTION_WARNINGS.reset(token2)
            DATA.reset(token3)
            HELD.reset(token4)
        charts[-1].warnings.extend(action_warnings + scope.warnings + _held_warnings(charts[-1], held))
        charts[-1].internals = scope.declarations()
        charts[-1].outputs[:] = [o for o in charts[-1].outputs if o.upper() not in scope.used]
        charts[-1].outputs.extend(n for n in [*scope.action_refs, *scope.globals_out.values(), *scope.inputs_out.values()]
                                  if n not in charts[-1].outputs and n.upper() not in scope.used)
    for c in charts:
        merge_shared(c, src.at)
        merge_mirrors(c)
    if several:
        separate_instances(charts, [p for p, _ in sfc_pous], q, src.at)
    _feedback(charts, src)
    if warnings is not None:
        warnings += [w for c in charts for w in c.warnings]
    return _g7_text(charts, file, several)


def _feedback(charts: list[Chart], src: Source) -> None:
    """A name some chart assigns (an output) and some chart reads (a global such as
    ``GVL_xBusy``): the reads are of the input ``NAME_fb``, with a warning."""
    from synth.errors import Severity

    outputs = {n for c in charts for n in c.outputs}
    for c in charts:
        for name in [n for n in c.inputs if n in outputs]:
            fb = f"{name}_fb"
            pattern = re.compile(rf"(?<![\w/]){name}\b")
            c.inputs[c.inputs.index(name)] = fb
            first = None
            for i, (label, sources, targets, expr, el) in enumerate(c.transitions):
                if pattern.search(expr):
                    first = first if first is not None else el
                    c.transitions[i] = (label, sources, targets, pattern.sub(fb, expr), el)
            for st in c.steps:
                st.actions = [(m[1] + pattern.sub(fb, m[2])) if (m := re.fullmatch(r"(.*? (?:if|on) )(.*)", a)) else a
                              for a in st.actions]
            c.warnings.append(InputError(
                f"{name} is assigned by the imported chart and read by a transition: .g7 receptivities read inputs, "
                f"so it reads the input {fb} (bind it to the output's value)",
                src.at(first) if first is not None else None, severity=Severity.WARNING))


def _g7_text(charts: list[Chart], file: str, several: bool) -> str:
    """The ``.g7`` text of the charts: one ``grafcet`` block per connected part of each."""
    inputs = list(dict.fromkeys(n for c in charts for n in c.inputs))
    outputs = list(dict.fromkeys(n for c in charts for n in c.outputs))
    which = ", ".join(c.name for c in charts)
    lines = [f"# Imported by synth {synth_version()} from {file} (POU{'s' if several else ''} {which}): PLCopen SFC.",
             ""]
    if inputs:
        lines.insert(1, "inputs " + ", ".join(inputs))
    if outputs:
        lines.insert(1 + bool(inputs), "outputs " + ", ".join(outputs))
    internals = list(dict.fromkeys(d for c in charts for d in c.internals))
    if internals:
        lines[-1:-1] = internals
    count = 0
    for chart in charts:
        if several:
            count = 0
        parent: dict[str, str] = {s.name: s.name for s in chart.steps}

        def find(x: str) -> str:
            while parent[x] != x:
                parent[x] = parent[parent[x]]
                x = parent[x]
            return x

        for _, sources, targets, _, _ in chart.transitions:
            linked = sources + targets
            for a in linked[1:]:
                parent[find(a)] = find(linked[0])
        groups: dict[str, str] = {}
        for s in chart.steps:
            if s.grafcet:
                groups.setdefault(find(s.name), (f"{chart.name}_" if several else "") + s.grafcet)
        for s in chart.steps:
            if find(s.name) not in groups:
                count += 1
                groups[find(s.name)] = f"{chart.name}_G{count}" if several else f"G{count}"
        for gname in dict.fromkeys(groups[find(s.name)] for s in chart.steps):
            members = [s for s in chart.steps if groups[find(s.name)] == gname]
            lines.append(f"grafcet {gname} {{")
            for s in members:
                head = ("initial " if s.initial else "") + f"step {s.name}"
                actions = _paired(s.actions)
                lines.append("  " + head + (": " + ", ".join(actions) if actions else ""))
            names_in = {s.name for s in members}
            for label, sources, targets, expr, _ in chart.transitions:
                if set(sources + targets) & names_in:
                    lab = f"{label}: " if label and re.fullmatch(r"[A-Za-z][A-Za-z0-9_]*|\d+", label) else ""
                    lines.append(f"  transition {lab}{', '.join(sources)} -> {', '.join(targets)} when {expr}")
            lines.append("}")
    return "\n".join(lines) + "\n"


HELD: contextvars.ContextVar[list[tuple[str, str, Location]] | None] = contextvars.ContextVar("HELD", default=None)
"""While a chart is read: the ``N`` actions ``X := c;`` read as ``X if c`` (step, action, where)."""


def _held_warnings(chart: Chart, held: list[tuple[str, str, Location]]) -> list[InputError]:
    """``X := c;`` in an ``N`` action: the PLC assigns X while the step is active and keeps its
    last value once the step is left; ``X if c`` (continuous) lets X fall. The two agree when the
    step also resets X on deactivation (a ``P0`` action, as ``synth sfc`` writes it); otherwise a
    located warning says what changed."""
    actions = {s.name: s.actions for s in chart.steps}
    out = []
    for step, action, where in held:
        target, cond = action.split(" if ", 1)
        if f"reset {target} on deactivation" in actions.get(step, ()):
            continue
        out.append(InputError(
            f"an N action assigning {target} in step {step} is read as the continuous action '{action}': "
            f"{target} falls when the step is left, while the PLC keeps its last value",
            where, severity=Severity.WARNING,
            notes=(f"to keep the continuous meaning on the PLC, add a P0 action '{target} := FALSE;' to step {step}; "
                   f"for a stored order, write S/R actions (set {target} / reset {target})",)))
    return out


def _paired(actions: list[str]) -> list[str]:
    """``A if c`` is exported as an ``N`` body and a ``P0`` body ``A := FALSE;`` (its IEC
    meaning: reset when the step is left); read back, the pair is ``A if c`` alone."""
    conditional = {a.split(" if ", 1)[0] for a in actions if " if " in a}
    return [a for a in actions if not (a.startswith("reset ") and a.endswith(" on deactivation")
                                       and a[len("reset "):-len(" on deactivation")] in conditional)]




def _read_action(a: Any, src: Source, steps: dict[str, str], q: Any, pou_actions: dict[str, Any], step: str,
                 named: tuple[IecQualifier, str] | None = None) -> list[str]:
    """The ``.g7`` actions of one SFC action (an action block's line) of step ``step``, or of a
    vendor step action ``named`` (qualifier, action name) located at ``a``."""
    if named is None:
        raw = a.get("qualifier", "N")
        if raw not in set(IecQualifier):
            raise InputError(f"unknown action qualifier {raw}", src.at(a), expected=tuple(IecQualifier))
        qualifier, ref = IecQualifier(raw), a.find(q("reference"))
        name = ref.get("name") if ref is not None else None
    else:
        qualifier, name = named
    if qualifier == IecQualifier.P:  # IEC 61131-3: a pulse when the step becomes active, as P1
        qualifier = IecQualifier.P1
    if qualifier in (IecQualifier.SD, IecQualifier.DS, IecQualifier.SL):
        raise InputError(f"action qualifier {qualifier} (stored and timed) cannot be represented in .g7: a .g7 "
                         "timer belongs to a step, not to a stored action", src.at(a),
                         expected=tuple(k for k in IecQualifier if k not in ("SD", "DS", "SL")))
    if name is not None and "." in name:
        raise InputError(f"action {name} belongs to the instance {name.rsplit('.', 1)[0]} of another block: .g7 "
                         "holds this chart's Boolean actions, not another block's code", src.at(a))
    if name is not None and name in pou_actions:
        if qualifier in (IecQualifier.D, IecQualifier.L):
            raise InputError(f"qualifier {qualifier} on action {name}: a timed action's body of stored assignments "
                             "has no .g7 form (a stored action's event cannot be a timer)", src.at(a))
        return _pou_action(a, name, pou_actions[name], qualifier, src, q, steps)
    if named is not None:
        raise InputError(f"step action {name} is not an action of this POU", src.at(a),
                         expected=tuple(pou_actions) or ("(the POU has no actions)",))
    if qualifier == IecQualifier.D and (scope := DATA.get()) is not None and str(name).upper() in scope.timers:
        return []  # a local Boolean read as its step timer (plcopen.delayed)
    if qualifier in (IecQualifier.D, IecQualifier.L):
        d = duration(a.get("duration", ""))
        if name is None or d is None:
            raise InputError(f"a {qualifier} action needs a reference to an output and a duration such as T#2s",
                             src.at(a))
        timer = f"{d}/X{step}"
        return [f"{name} if {timer}" if qualifier == IecQualifier.D else f"{name} if !{timer}"]
    action = _one_action(a, src, steps, q, qualifier)
    if qualifier == IecQualifier.N and " if " in action and (held := HELD.get()) is not None:
        held.append((step, action, src.at(a)))  # X := c; the PLC keeps X once the step is left
    return [action]


def _pou_action(a: Any, name: str, action: Any, qualifier: IecQualifier, src: Source, q: Any,
                steps: dict[str, str]) -> list[str]:
    """A reference to a POU action: its ST body's Boolean assignments
    (:func:`~synth.codegen.plcopen.actions.action_body`)."""
    st = action.find(f"{q('body')}/{q('ST')}")
    if st is None and qualifier == IecQualifier.N and (scope := DATA.get()) is not None and \
            name.upper() in scope.blink_actions:
        return []  # its partial grafcet (plcopen.blink) does it
    if st is None and action.find(f"{q('body')}/{q('LD')}") is not None:
        raise InputError(f"action {name} referenced here has an LD body that is not a blinker run by an N action "
                         "(two TONs that set and reset one variable, each timing its other value): .g7 reads the ST "
                         "bodies' Boolean assignments", src.at(a))
    if st is None:
        raise InputError(f"action {name} referenced here has no ST body: .g7 reads Boolean assignments only",
                         src.at(a))
    text = st_text(st)

    def where(off: int, width: int) -> Location:
        return src.text_at(st, text, off, width)

    return action_body(name, text, qualifier, where, steps)


def _one_action(a: Any, src: Source, steps: dict[str, str], q: Any, qualifier: str) -> str:
    ref, inline = a.find(q("reference")), a.find(q("inline"))
    if ref is not None:
        name = ref.get("name", "")
        if (scope := DATA.get()) is not None and name not in scope.action_refs:
            scope.action_refs.append(name)  # an output, even when the POU declares it local
        if qualifier == Qualifier.N:
            return name
        if qualifier == Qualifier.S:
            return f"set {name}"
        if qualifier == Qualifier.R:
            return f"reset {name}"
        raise InputError(f"qualifier {qualifier} with a reference: use an inline body '{name} := TRUE;'", src.at(a))
    if inline is None or inline.find(q("ST")) is None:
        raise InputError("an action without a reference or an inline ST body", src.at(a))
    st = inline.find(q("ST"))
    body = without_shared_or(st_text(st).strip())
    where = lambda off, w, h=st, t=st_text(st): src.text_at(h, t, off, w)  # noqa: E731
    m = re.fullmatch(r"(\w+)\s*:=\s*(TRUE|FALSE|1|0)\s*;?", body, re.I)  # 1, 0: BOOL literals
    scope = DATA.get()
    data = re.fullmatch(r"(\w+)\s*:=\s*([^;]*?)\s*;?", body, re.S)
    target = scope.find(data[1]) if scope is not None and data is not None else None
    several = len([x for x in body.split(";") if x.strip()]) > 1
    if_body = qualifier == Qualifier.N and re.match(r"IF\b", body, re.I)  # IF c THEN X := TRUE; END_IF;
    if several and qualifier in (Qualifier.N, Qualifier.P0, Qualifier.P1) and not if_body:
        return ", ".join(action_body(f"{qualifier} (inline)", st_text(st), IecQualifier(qualifier), where, steps))
    if qualifier in (Qualifier.P0, Qualifier.P1) and target is not None and data is not None and scope is not None:
        raw = st_text(st)
        value = sum_text(scope, target, data[2], lambda o, w: where(raw.find(data[2]) + o, w))
        return f"{target.name} := {value}" + (" on deactivation" if qualifier == Qualifier.P0 else "")
    if qualifier in (Qualifier.P0, Qualifier.P1):
        if not m:
            raise InputError(f"a {qualifier} action body must be 'NAME := TRUE;' or 'NAME := FALSE;' (or assign an "
                             "integer local variable)", where(0, 1))
        verb = "set" if m[2].upper() in ("TRUE", "1") else "reset"
        return f"{verb} {m[1]} on {'deactivation' if qualifier == Qualifier.P0 else 'activation'}"
    if qualifier == Qualifier.N:
        ev = re.fullmatch(r"IF\s+(.*?)\s+THEN\s+(\w+)\s*:=\s*(.*?)\s*;\s*END_IF\s*;?", body, re.I | re.S)
        if ev:
            raw = st_text(st)
            off = raw.find(ev[1])
            cond = ExprReader(ev[1], lambda o, w: where(off + o, w), steps, "an action body").whole()
            v = scope.find(ev[2]) if scope is not None else None
            if v is not None and scope is not None:
                value = sum_text(scope, v, ev[3], lambda o, w: where(raw.find(ev[3], off) + o, w))
                return f"{v.name} := {value} on {cond}"
            if ev[3].upper() in ("TRUE", "FALSE"):
                verb = "set" if ev[3].upper() == "TRUE" else "reset"
                return f"{verb} {ev[2]} on {cond}"
        cm = re.fullmatch(r"(\w+)\s*:=\s*(.*?)\s*;?", body, re.S)
        if cm and target is not None and scope is not None:
            raw = st_text(st)
            value = sum_text(scope, target, cm[2], lambda o, w: where(raw.find(cm[2]) + o, w))
            if re.search(r"[A-Za-z]", value):
                scope.every_scan(body.strip(), "an N action", where(0, len(cm[1])))
            return f"{target.name} := {value}"
        if m:  # X := TRUE; at every scan while the step is active, kept once it is left: stored
            return f"{'set' if m[2].upper() in ('TRUE', '1') else 'reset'} {m[1]} on activation"
        if cm:
            raw = st_text(st)
            off = raw.find(cm[2])
            if re.search(r"[+\-*/]|\b(MOD|ADD|SUB|MUL|DIV)\b", cm[2], re.I):
                raise InputError(f"an assignment of data in an action body ({body.strip()}): {cm[1]} is not a local "
                                 "variable of an integer type (.g7 internal variables are the chart's own)",
                                 where(0, len(body.strip())))
            cond = ExprReader(cm[2], lambda o, w: where(off + o, w), steps, "an action body").whole()
            return f"{cm[1]} if {cond}"
    if qualifier == Qualifier.S and (shared := shared_assignment(body)) is not None:
        return f"{MARK}{shared[0]} := {' '.join(shared[1])}"
    raise InputError(f"a {qualifier} action body that .g7 cannot represent (expected 'NAME := condition;')",
                     where(0, 1))


def checked_pous(data: bytes | str, file: str = "<xml>") -> list[PouSummary]:
    """:func:`list_pous` with each SFC POU imported on its own: a POU the import refuses is
    listed as not imported, with the first line of the reason (``synth import --list``)."""
    out = []
    for s in list_pous(data, file):
        if s.imported:
            try:
                import_sfc(data, file, pou=s.name)
            except InputError as err:
                reason = err.render().splitlines()[0].split(": error: ", 1)[-1]
                s = PouSummary(s.name, s.kind, s.language, False, "refused: " + reason)
        out.append(s)
    return out
