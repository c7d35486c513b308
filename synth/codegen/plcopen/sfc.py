"""One SFC POU of a PLCopen project read into steps, transitions and actions (``synth
import``): what :mod:`synth.codegen.plcopen.importer` turns into ``.g7`` text.

The SFC body's layout, comments, documentation and vendor ``addData`` are ignored;
``jumpStep`` is a link to its target step; a transition's condition is inline ST, a named
transition of the POU, or an FBD network wired to it (:mod:`synth.codegen.plcopen.fbd`).
Anything ``.g7`` cannot represent is an :class:`~synth.errors.InputError` at its line.

Example
-------
>>> Chart("Main", [], [], [], []).inputs
[]
"""

from __future__ import annotations

import re
from dataclasses import dataclass, field
from typing import Any, Callable

from synth.codegen.plcopen.data import DATA
from synth.codegen.plcopen.ids import number_ids
from synth.codegen.plcopen.scan import one_scan_steps
from synth.codegen.plcopen.timers import ton_chart
from synth.codegen.plcopen.divergence import exclusive_branches, priority
from synth.codegen.plcopen.vendor import chart_flag_warnings, step_actions
from synth.codegen.plcopen.fbd import FBD_ELEMENTS, fbd_condition, fbd_transition
from synth.codegen.plcopen.fbscan import first_scan_guard, settle_step_reads
from synth.codegen.plcopen.tc6 import SYNTH_DATA
from synth.codegen.plcopen.st_condition import PREDICATES, ExprReader, st_text
from synth.errors import InputError, Location, Severity, close_names

__all__ = ["Chart", "read_chart", "Source"]

_SUPPORTED = {*FBD_ELEMENTS, "step", "transition", "selectionDivergence", "selectionConvergence", "simultaneousDivergence",
              "simultaneousConvergence", "actionBlock", "jumpStep", "comment"}
_WHAT = {"macroStep": "a macro-step", "inVariable": "an FBD variable", "outVariable": "an FBD variable",
         "inOutVariable": "an FBD variable", "block": "an FBD block", "connector": "a connector",
         "continuation": "a continuation", "contact": "an LD contact", "coil": "an LD coil",
         "leftPowerRail": "an LD power rail", "rightPowerRail": "an LD power rail", "label": "a label",
         "jump": "an FBD jump", "return": "a return", "error": "a conversion error", "vendorElement": "vendor data"}


class Source:
    """The XML file's text, for locations: ``file:line:col`` of an element or of a text."""

    def __init__(self, file: str, text: str) -> None:
        self.file = file
        self.lines = text.split("\n")

    def at(self, el, width: int | None = None) -> Location:
        from lxml import etree

        line = el.sourceline or 1
        tag = etree.QName(el).localname
        raw = self.lines[line - 1] if 0 < line <= len(self.lines) else ""
        col = raw.find("<" + tag) + 1 if ("<" + tag) in raw else 1
        return Location(self.file, line, max(1, col), raw, width or len(tag) + 1)

    def text_at(self, el, text: str, offset: int, width: int = 1) -> Location:
        """Where character ``offset`` of ``text`` (the text of ``el`` or of its child) is."""
        start = el.sourceline or 1
        first = text.lstrip().split("\n")[0].strip()
        for n in range(start - 1, min(start + 20, len(self.lines))):
            if first and first in self.lines[n]:
                base_line, base_col = n + 1, self.lines[n].find(first) + 1
                lead = len(text) - len(text.lstrip())
                rel = text[lead:offset]
                if "\n" in rel:
                    line = base_line + rel.count("\n")
                    col = len(rel.rsplit("\n", 1)[1]) + 1
                else:
                    line, col = base_line, base_col + len(rel)
                raw = self.lines[line - 1] if line <= len(self.lines) else ""
                return Location(self.file, line, col, raw, width)
        return self.at(el)


@dataclass
class _ImportedStep:
    name: str
    initial: bool
    actions: list[str]
    grafcet: str | None
    el: object




@dataclass
class Chart:
    """One SFC POU as read: its interface, steps (in file order) and transitions."""

    name: str
    inputs: list[str]
    outputs: list[str]
    steps: list[_ImportedStep]
    transitions: list[tuple[str, list[str], list[str], str, object]]
    warnings: list[InputError] = field(default_factory=list)
    internals: list[str] = field(default_factory=list)  # internal declarations (.g7 text)


_SECTIONS = ("inputVars", "outputVars", "inOutVars", "localVars", "tempVars", "externalVars")


def _check_names(pou: Any, q: Callable[[str], str], src: Source, transitions: list, steps: set[str],
                 inputs: list[str], outputs: list[str], warnings: list[InputError]) -> None:
    """Every variable a receptivity reads is declared in the POU: an input, or a local (and the
    like) read as an input with a warning; anything else is an error at the transition."""
    declared: dict[str, Any] = {}
    for section in _SECTIONS:
        for v in pou.iterfind(f"{q('interface')}/{q(section)}/{q('variable')}"):
            declared.setdefault(str(v.get("name")), (section, v))
    scope = DATA.get()
    for i, (label, sources, targets, expr, el) in enumerate(transitions):
        for name in dict.fromkeys(re.findall(r"(?<![\w/])[A-Za-z_]\w*", expr)):
            if name.startswith("X") and name[1:] in steps or name in inputs:
                continue
            if scope is not None and name.upper() in scope.used:
                continue
            if scope is not None and name in scope.globals_in.values():
                inputs.append(name)
                continue
            if name not in declared:
                raise InputError(f"a transition reads '{name}', which the POU {pou.get('name')} does not declare",
                                 src.at(el), suggestions=close_names(name, declared))
            section, var = declared[name]
            if name in outputs or section == "outputVars":
                feedback = f"{name}_fb"
                if feedback in declared:
                    raise InputError(f"a transition reads the output '{name}', and {feedback} (its feedback input) is "
                                     "already declared", src.at(el))
                expr = re.sub(rf"(?<![\w/]){name}\b", feedback, expr)
                transitions[i] = (label, sources, targets, expr, el)
                if feedback not in inputs:
                    inputs.append(feedback)
                    warnings.append(InputError(
                        f"a transition reads the output '{name}' of POU {pou.get('name')}: .g7 receptivities read "
                        f"inputs, so it reads the input {feedback} (bind it to the output's value)", src.at(el),
                        severity=Severity.WARNING))
                continue
            inputs.append(name)
            warnings.append(InputError(f"'{name}', declared in <{section}> of POU {pou.get('name')}, is read as an "
                                       "input: nothing the chart does assigns it",
                                       src.at(var), severity=Severity.WARNING))


def _declare_predicates(inputs: list[str], warnings: list[InputError]) -> None:
    """The comparisons read so far (:data:`~synth.codegen.plcopen.st_condition.PREDICATES`) as inputs."""
    for ident, (text, where) in (PREDICATES.get() or {}).items():
        if ident not in inputs:
            inputs.append(ident)
            warnings.append(InputError(
                f"declared predicate {ident} stands for '{text}': a Boolean input of the imported Grafcet (.g7 "
                "reads no numeric values); bind it to a sensor of the plant, or leave it free", where,
                severity=Severity.WARNING))


def _x(el: Any) -> int:
    pos = next((c for c in el if isinstance(c.tag, str) and c.tag.endswith("position")), None)
    try:
        return int(float(pos.get("x", "0"))) if pos is not None else 0
    except ValueError:
        return 0


def read_chart(pou: Any, sfc: Any, q: Callable[[str], str], src: Source,
               read_action: Callable[..., list[str]], prefix: str = "") -> Chart:
    """The chart of ``pou`` (its SFC body ``sfc``); step names get ``prefix`` (several POUs
    imported into one ``.g7``)."""
    from lxml import etree

    pou_actions = {str(x.get("name")): x for x in pou.iterfind(f"{q('actions')}/{q('action')}")}
    for v in pou.iterfind(f"{q('interface')}//{q('variable')}"):
        if not (v.get("name") or "").strip():
            raise InputError(f"a variable of POU {pou.get('name', '')}'s interface has no name", src.at(v),
                             notes=('write it <variable name="...">',))
    inputs = [v.get("name") for v in pou.iterfind(f"{q('interface')}/{q('inputVars')}/{q('variable')}")
              if v.find(f"{q('type')}/{q('derived')}") is None]  # a block instance is no Boolean input
    # synth sfc's edge inputs _RE_x/_FE_x (set by the caller) are the edges ↑x/↓x of the input x
    inputs = [n for n in inputs if not (n[:4] in ("_RE_", "_FE_") and n[4:] in inputs)]
    outputs = [v.get("name") for v in pou.iterfind(f"{q('interface')}/{q('outputVars')}/{q('variable')}")]
    named_conditions: dict[str, tuple[Any, str]] = {}
    named_fbd: dict[str, tuple[Any, Any]] = {}
    for t in pou.iterfind(f"{q('transitions')}/{q('transition')}"):
        body = t.find(q("body"))
        st = body.find(q("ST")) if body is not None else None
        fbd = body.find(q("FBD")) if body is not None else None
        if fbd is None and body is not None:
            fbd = body.find(q("LD"))  # OpenPLC writes a named transition in LD: a coil named after it
        if st is not None:
            named_conditions[t.get("name")] = (st, st_text(st))
        elif fbd is not None:
            named_fbd[t.get("name")] = (t, fbd)
        else:
            raise InputError("a named transition whose body is neither ST, FBD nor LD", src.at(t))

    number_ids(sfc, q, src.at)
    elements: dict[int, Any] = {}  # localId -> lxml element
    for el in sfc:
        if not isinstance(el.tag, str):
            continue  # an XML comment or processing instruction
        local = etree.QName(el).localname
        if local in ("addData", "documentation"):
            continue
        if local not in _SUPPORTED:
            what = _WHAT.get(local, "an element")
            raise InputError(f"unsupported SFC element <{local}> ({what}): .g7 cannot represent it", src.at(el),
                             expected=tuple(f"<{s}>" for s in sorted(_SUPPORTED)))
        if local == "comment":
            continue
        lid = el.get("localId")
        if lid is None or not re.fullmatch(r"[0-9]+", lid):
            raise InputError(f"<{local}> without a numeric localId", src.at(el))
        elements[int(lid)] = el

    def kind(el) -> str:
        return etree.QName(el).localname

    def producers(el) -> list[tuple[int, Any]]:
        out = []
        for cp in el.iterfind(q("connectionPointIn")):
            if cp.find(q("expression")) is not None:
                raise InputError("a connection given as an expression cannot be read", src.at(cp))
            for c in cp.iterfind(q("connection")):
                text = c.get("refLocalId", "")
                if not re.fullmatch(r"\s*-?[0-9]+\s*", text):
                    raise InputError(f"a connection's refLocalId must be a number, not '{text[:40]}'", src.at(c))
                ref = int(text)
                if ref not in elements:
                    raise InputError(f"connection to unknown localId {c.get('refLocalId')}", src.at(c))
                out.append((ref, c))
        return out

    consumers: dict[int, list[int]] = {}
    for lid, el in elements.items():
        if kind(el) == "actionBlock":
            continue
        for ref, _ in producers(el):
            consumers.setdefault(ref, []).append(lid)

    # steps
    steps: dict[int, _ImportedStep] = {}
    sfc_names: dict[str, str] = {}  # SFC step name -> .g7 step name
    for lid, el in elements.items():
        if kind(el) != "step":
            continue
        sname = el.get("name", "")
        g7 = sname[1:] if re.fullmatch(r"S\d+", sname) else sname
        if not re.fullmatch(r"[A-Za-z][A-Za-z0-9_]*|\d+", g7):
            raise InputError(f"step name '{sname}' is not a .g7 step name (letters, digits, _)", src.at(el))
        g7 = prefix + g7
        if g7 in sfc_names.values():
            raise InputError(f"duplicate step '{sname}'", src.at(el))
        sfc_names[sname] = g7
        gdata = el.find(f"{q('addData')}/{q('data')}[@name='{SYNTH_DATA}']/{q('grafcet')}")
        steps[lid] = _ImportedStep(g7, el.get("initialStep", "false") in ("true", "1"), [],
                                   gdata.get("name") if gdata is not None else None, el)
    by_sfc_name = {sfc: g7 for sfc, g7 in sfc_names.items()}

    def back(lid: int, seen: frozenset[int] = frozenset()) -> list[str]:
        """Source steps upstream of a transition's input."""
        el = elements[lid]
        k = kind(el)
        if lid in seen:
            raise InputError("a cycle of divergences/convergences without a step", src.at(el))
        if k == "step":
            return [steps[lid].name]
        if k in ("selectionDivergence", "simultaneousConvergence"):
            out: list[str] = []
            for ref, _ in producers(el):
                out += [s for s in back(ref, seen | {lid}) if s not in out]
            return out
        raise InputError(f"a transition cannot follow <{k}>", src.at(el))

    def fwd(lid: int, seen: frozenset[int] = frozenset()) -> list[str]:
        """Target steps downstream of a transition's output."""
        out: list[str] = []
        for c in consumers.get(lid, []):
            el = elements[c]
            k = kind(el)
            if c in seen:
                raise InputError("a cycle of divergences/convergences without a step", src.at(el))
            if k == "step":
                found = [steps[c].name]
            elif k == "jumpStep":
                target = el.get("targetName", "")
                if target not in by_sfc_name:
                    raise InputError(f"jump to unknown step '{target}'", src.at(el),
                                     suggestions=close_names(target, by_sfc_name))
                found = [by_sfc_name[target]]
            elif k in ("selectionConvergence", "simultaneousDivergence"):
                found = fwd(c, seen | {lid})
            elif k == "transition":
                raise InputError("two transitions in a row (a step is missing between them)", src.at(el))
            else:
                raise InputError(f"a transition cannot lead to <{k}>", src.at(el))
            out += [s for s in found if s not in out]
        return out

    # transitions
    transitions: list[tuple[str, list[str], list[str], str, object]] = []
    branches: dict[int, list[tuple[tuple[int, int, int], int]]] = {}  # selection divergence -> (order, transition)
    warnings: list[InputError] = []
    for lid, el in elements.items():
        if kind(el) != "transition":
            continue
        sources: list[str] = []
        for ref, _ in producers(el):
            sources += [s for s in back(ref) if s not in sources]
        targets = fwd(lid)
        cond = el.find(q("condition"))
        if cond is None:
            raise InputError("a transition without a condition", src.at(el))
        negate = cond.get("negated", "false") in ("true", "1")
        inline, ref, label = cond.find(q("inline")), cond.find(q("reference")), ""
        fbd_named: tuple[Any, Any] | None = None
        if inline is not None:
            st = inline.find(q("ST"))
            if st is None:
                raise InputError("a condition in a language other than ST", src.at(inline))
            label = inline.get("name", "")
            holder, ctext = st, st_text(st)
        elif ref is not None and ref.get("name") in named_fbd:
            holder, fbd_named = None, named_fbd[ref.get("name")]
        elif ref is not None:
            label = ""
            if ref.get("name") not in named_conditions:
                raise InputError(f"condition '{ref.get('name')}' is not defined in the POU's <transitions>",
                                 src.at(ref), suggestions=close_names(ref.get("name", ""), named_conditions))
            holder, ctext = named_conditions[ref.get("name")]
            m = re.fullmatch(r"\s*(?:\w+\s*)?:=\s*(.*?);?\s*", ctext, re.S)  # NAME := c; or := c;
            if m:
                ctext = m[1]
        elif cond.find(q("connectionPointIn")) is not None or cond.find(q("connection")) is not None:  # TC6 1.0
            holder = None
        else:
            raise InputError("a transition condition with neither ST nor a connection", src.at(cond))
        if DATA.get() is not None:
            DATA.get().sources = tuple(sources)  # type: ignore[union-attr]
        if holder is None and fbd_named is not None:
            expr = fbd_transition(fbd_named[0], fbd_named[1], q, src, by_sfc_name, tuple(sources))
        elif holder is None:
            expr = fbd_condition(cond, elements, q, src, by_sfc_name, tuple(sources))
        else:
            reader = ExprReader(ctext, lambda off, w, h=holder, t=ctext: src.text_at(h, t, off, w), by_sfc_name)
            expr = reader.whole()
        if negate:
            expr = f"!({expr})"
        transitions.append((label, sources, targets, expr, el))
        div = [(ref, c) for ref, c in producers(el) if kind(elements[ref]) == "selectionDivergence"]
        if len(div) == 1:
            branch = div[0][1].get("formalParameter", "")
            key = (priority(el, src), int(branch) if branch.strip().isdigit() else 10 ** 6, _x(el))
            branches.setdefault(div[0][0], []).append((key, len(transitions) - 1))
        if sources and sources == targets and "↑" not in expr and "↓" not in expr:
            warnings.append(InputError(
                f"a jump from step {sources[0]} back to itself on a level condition ({expr}): IEC 61131-3 SFC "
                "re-activates the step at every PLC scan while it holds, IEC 60848 (.g7) never stabilises there",
                src.at(el), severity=Severity.WARNING,
                notes=("validate it as the PLC runs it with --semantics sfc (validate, run, st), or make the "
                       "condition an edge, or add a step",)))
    helpers: list[_ImportedStep] = []
    scope = DATA.get()
    first = next((st for st in steps.values() if st.initial), None)
    if scope is not None and first is not None:
        settle_step_reads(transitions, {st.name for st in steps.values()})
        starts = {n: initial for c in scope.extra_charts for n, initial, _ in c[1]}
        warnings += first_scan_guard(transitions, first.name, src.at(first.el), starts)
    for gname, hsteps, htrans in ton_chart(scope, by_sfc_name, src.text_at) if scope is not None else []:
        helpers += [_ImportedStep(n, initial, list(acts), gname, pou) for n, initial, acts in hsteps]
        transitions += [("", a, b, expr, pou) for a, b, expr in htrans]
    _declare_predicates(inputs, warnings)
    _check_names(pou, q, src, transitions, {st.name for st in [*steps.values(), *helpers]}, inputs, outputs, warnings)
    warnings += chart_flag_warnings(pou, q, src.at)
    written_by_synth = any(st.grafcet for st in steps.values())  # its .g7 is the meaning: no rewriting
    if not written_by_synth:
        warnings += exclusive_branches(branches, transitions, elements, src)

    # actions: CODESYS/TwinCAT step actions (vendor addData), then the action blocks
    if scope is not None:
        scope.one_scan = one_scan_steps(transitions, scope)
    for st in steps.values():
        if scope is not None:
            scope.current_step = st.name
        for which, name, attr in step_actions(st.el, q):
            st.actions.extend(read_action(attr, src, by_sfc_name, q, pou_actions, st.name, (which.qualifier, name)))
    for lid, el in elements.items():
        if kind(el) != "actionBlock":
            continue
        owners = [ref for ref, _ in producers(el) if ref in steps]
        if len(owners) != 1:
            raise InputError("an action block must be connected to exactly one step", src.at(el))
        owner = steps[owners[0]]
        if scope is not None:
            scope.current_step = owner.name
        for a in el.iterfind(q("action")):
            owner.actions.extend(read_action(a, src, by_sfc_name, q, pou_actions, owner.name))

    # partial grafcets: synth's addData, else the connected components
    parent: dict[str, str] = {s.name: s.name for s in [*steps.values(), *helpers]}

    def find(x: str) -> str:
        while parent[x] != x:
            parent[x] = parent[parent[x]]
            x = parent[x]
        return x

    for _, sources, targets, _, _ in transitions:
        linked = sources + targets
        for a in linked[1:]:
            parent[find(a)] = find(linked[0])
    order = [s for s in sorted(steps.values(), key=lambda s: int(s.el.sourceline or 0))]  # type: ignore[attr-defined]
    groups: dict[str, str] = {}
    for s in order:
        if s.grafcet:
            groups.setdefault(find(s.name), s.grafcet)
    for s in order:
        if find(s.name) not in groups:
            groups[find(s.name)] = f"G{len(set(groups.values())) + 1}"
    order = sorted(steps.values(), key=lambda s: int(s.el.sourceline or 0))  # type: ignore[attr-defined]
    _declare_predicates(inputs, warnings)  # those met in the actions' conditions
    return Chart(str(pou.get("name", "")), inputs, outputs, order + helpers, transitions, warnings)
