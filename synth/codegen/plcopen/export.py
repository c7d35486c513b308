"""PLCopen TC6 XML (v2.01) out: Structured Text POUs and the Grafcet as an SFC.

* :func:`st_project_xml` wraps the POUs the generators hand over (``synth st --xml``,
  ``synth filter st --xml``) in a project: each ``PROGRAM``/``FUNCTION_BLOCK`` becomes a
  ``<pou>`` with its interface and an ``<ST>`` body, built from the declarations as data;
* :func:`sfc_project_xml` writes a Grafcet as one SFC ``<pou>`` (``synth sfc``): a ``<step>``
  per step (``initialStep``), a ``<transition>`` per transition with an inline ST condition,
  ``selectionDivergence``/``selectionConvergence`` for OR, ``simultaneousDivergence``/
  ``simultaneousConvergence`` for AND, an ``actionBlock`` per step with actions.

Mapping (:mod:`synth.codegen.plcopen.importer` reads it back):

=====================================  ===================================``.g7``                                SFC
=====================================  ===================================step ``12`` / ``wait``                  ``<step name="S12">`` / ``name="wait"``
``X12``                                 ``S12.X``
``2s/X12``                              ``(S12.T >= T#2s)`` (the TIME literal of ``synth st``)
``↑x`` / ``↓x``                         inputs ``_RE_x`` / ``_FE_x`` (set by the caller, see docs/codegen.md)
``A`` (continuous)                      qualifier ``N``, reference ``A``
``A if c``                              qualifier ``N``, inline ST ``A := c;``, and ``P0``,
                                        inline ST ``A := FALSE;`` (reset when the step is left)
``set A`` / ``reset A`` on activation   qualifier ``S`` / ``R``, reference ``A``
``set A on deactivation``               qualifier ``P0``, inline ST ``A := TRUE;``
``set A on ↑p``                         qualifier ``N``, inline ``IF _RE_p THEN A := TRUE; END_IF;``
=====================================  ===================================
Plant names differing only in case (``a`` and ``A``) are renamed as ``synth st`` renames
them (:func:`~synth.codegen.program.case_aliases`); the project's comment lists the renames.

Example
-------
>>> from synth.codegen.st import Declaration, Pou, PouKind, SectionKind, VarSection
>>> p = Pou(PouKind.PROGRAM, "P", (VarSection(SectionKind.INPUT, (Declaration("a"),)),), ("y := a;",))
>>> xml = st_project_xml([p], version="0.1.0")
>>> b'<pou name="P" pouType="program">' in xml, b'<variable name="a">' in xml
(True, True)
"""

from __future__ import annotations

from typing import Any, Sequence

from synth.codegen.plcopen.data import FLAG_PREFIX
from synth.codegen.plcopen.mirrors import mirror_flag, mirrored_steps
from synth.codegen.plcopen.tc6 import (
    SYNTH_DATA,
    Qualifier,
    element,
    interface,
    position,
    project,
    sfc_step_name,
    xhtml,
)
from synth.codegen.program import Configuration, case_aliases, check_variable_name, first_location, program_name, renamed_note
from synth.codegen.st import Pou, PouKind, st_expr, timer_literal
from synth.codegen.twincat import object_id
from synth.errors import InputError, Location
from synth.codegen.st_internals import compare_text, declarations as internal_declarations, sum_text
from synth.grafcet.language import (
    ASSIGN,
    CONDITIONAL,
    CONTINUOUS,
    ON_ACTIVATION,
    ON_DEACTIVATION,
    ON_EVENT,
    Action,
    Grafcet,
    Timer,
)
from synth.logic.expr import Compare, Edge, Expr, Var, names as expr_names
from synth.version import version as synth_version

__all__ = ["st_project_xml", "sfc_project_xml"]

CODESYS_DATA = "http://www.3s-software.com/plcopenxml/"
"""The prefix of the ``addData`` names CODESYS V3.5 writes in its PLCopenXML exports."""

_POU_TYPE = {PouKind.PROGRAM: "program", PouKind.FUNCTION_BLOCK: "functionBlock"}


def st_project_xml(pous: Sequence[Pou], *, name: str = "synth", version: str | None = None, comment: str = "",
                   config: Configuration | None = None, codesys: bool = False) -> bytes:
    """PLCopen XML of generated POUs: their interfaces from their declarations, their ST bodies;
    with ``config`` (``--task``), the configuration that runs the program (TC6 ``<task>``).
    ``codesys``: with the ``addData`` CODESYS V3.5 writes and reads (each POU's ``ObjectId``, the
    project's ``ProjectStructure`` listing them), so its PLCopenXML import places every object."""
    out = []
    for p in pous:
        body = element("body", None, element("ST", None, xhtml("\n".join(p.body).strip("\n") + "\n")))
        pou = element("pou", {"name": p.name, "pouType": _POU_TYPE[p.kind]}, interface(p.sections), body)
        if codesys:
            ident = element("ObjectId")
            ident.text = object_id(p.name)
            pou.append(element("addData", None, element("data", {"name": CODESYS_DATA + "objectid",
                                                                 "handleUnknown": "discard"}, ident)))
        out.append(pou)
    extra = []
    if codesys:
        structure = element("ProjectStructure", None, *[element("Object", {"Name": p.name, "ObjectId": object_id(p.name)})
                                                       for p in pous])
        extra.append(element("data", {"name": CODESYS_DATA + "projectstructure", "handleUnknown": "discard"}, structure))
    configs = []
    if config is not None:
        task = element("task", {"name": config.task, "interval": config.interval, "priority": str(config.priority)},
                       element("pouInstance", {"name": config.instance, "typeName": config.program}))
        configs.append(element("configuration", {"name": config.name},
                               element("resource", {"name": config.resource}, task)))
    return project(name, version or synth_version(), comment, out, configs, extra)


def _program_name(name: str, default: bool, declared: Sequence[str]) -> str:
    """The ``PROGRAM``'s name, distinct from every name it declares (IEC 61131-3 ignores case:
    ``PROGRAM clamp`` cannot declare ``CLAMP``, MATIEC refuses it): a default name (the file's
    stem) gets ``_1``, ``_2``, ...; a name the user gave is a located error."""
    taken = {n.upper() for n in declared}
    if name.upper() not in taken:
        return name
    if not default:
        raise InputError(f"the program name {name} is also the name of a variable or step of the chart (IEC 61131-3 "
                         "ignores case)", Location("--name", 1, 1, name, max(1, len(name))),
                         notes=("choose another --name",))
    k = 1
    while f"{name}_{k}".upper() in taken:
        k += 1
    return f"{name}_{k}"


class _Names:
    """The SFC's names: steps ``S12``, timers, and the plant names after :func:`case_aliases`."""

    def __init__(self, g: Grafcet) -> None:
        self.steps = {s.name for s in g.steps}
        self.mirrored = mirrored_steps(g)
        self.timers = {t.id: t for t in g.timers}
        self.internals = {v.name: v for v in g.internals}
        self.alias = case_aliases([*g.inputs, *g.outputs, *self.internals], [sfc_step_name(s.name) for s in g.steps])

    def __call__(self, n: str) -> str:
        return self.alias.get(n, n)


def _sfc_expr(e: Expr, names: _Names) -> str:
    """A receptivity or condition in the SFC's ST: steps ``S12.X``, timers ``(S12.T >= T#2s)``,
    edges the flags ``_RE_x``/``_FE_x`` (the one ST expression printer, :func:`~synth.codegen.st.st_expr`)."""
    steps, timers = names.steps, names.timers

    def ref(x: Expr) -> str:
        if isinstance(x, Edge):
            return ("_RE_" if x.rising else "_FE_") + names(x.name)
        if isinstance(x, Compare):
            return compare_text(x, names)
        assert isinstance(x, Var)
        if x.name in timers:
            t = timers[x.name]
            return f"({sfc_step_name(t.step)}.T >= {timer_literal(t.id, t.seconds, t.loc)})"
        if x.name.startswith("X") and x.name[1:] in steps:
            step = x.name[1:]
            return mirror_flag(step) if step in names.mirrored else f"{sfc_step_name(step)}.X"
        return names(x.name)

    return st_expr(e, ref)


class _Ids:
    def __init__(self) -> None:
        self.n = 0

    def __call__(self) -> int:
        self.n += 1
        return self.n


def _branches(producers: Sequence[tuple[int, str | None]]) -> list[Any]:
    """A convergence's inputs: one ``connectionPointIn`` per converging branch, as the TC6
    example and Beremiz write them (Beremiz drops the branches of a convergence whose one
    ``connectionPointIn`` holds several connections)."""
    return [_conn_in(p) for p in producers]


def _conn_in(*producers: tuple[int, str | None]) -> Any:
    cp = element("connectionPointIn")
    for ref, formal in producers:
        attrib = {"refLocalId": str(ref)}
        if formal is not None:
            attrib["formalParameter"] = formal
        cp.append(element("connection", attrib))
    return cp


def sfc_project_xml(g: Grafcet, *, name: str | None = None, version: str | None = None, comment: str = "") -> bytes:
    """The Grafcet ``g`` as one PLCopen SFC ``PROGRAM`` (see the module doc for the mapping)."""
    for n in (*g.inputs, *g.outputs):
        check_variable_name(n, first_location(g, n))
    for v in g.internals:
        check_variable_name(v.name, v.loc)
    for s in g.steps:
        check_variable_name(sfc_step_name(s.name), s.loc)
    for t in g.transitions:
        if not t.sources or not t.targets:
            kind = "source" if not t.sources else "sink"
            raise InputError(f"a {kind} transition cannot be written as IEC 61131-3 SFC: there a transition "
                             f"always goes from steps to steps", t.loc,
                             notes=(f"Beremiz fails on it; model the {kind} with a step of its own, or use synth st",))
    names = _Names(g)
    steps = names.steps
    seen: dict[str, str] = {}
    for s in g.steps:  # step 12 is S12 in the SFC: a step named S12 as well would be the same
        other = seen.setdefault(sfc_step_name(s.name).upper(), s.name)
        if other != s.name:
            raise InputError(f"steps {other} and {s.name} would both be the SFC step {sfc_step_name(s.name)}", s.loc,
                             notes=("rename one of them",))
    ids = _Ids()
    step_id = {s.name: ids() for s in g.steps}
    trans_id = [ids() for _ in g.transitions]
    outgoing = {s: [i for i, t in enumerate(g.transitions) if s in t.sources] for s in steps}
    incoming = {s: [i for i, t in enumerate(g.transitions) if s in t.targets] for s in steps}
    sel_div = {s: ids() for s in steps if len(outgoing[s]) > 1}
    sel_conv = {s: ids() for s in steps if len(incoming[s]) > 1}
    sim_conv = {i: ids() for i, t in enumerate(g.transitions) if len(t.sources) > 1}
    sim_div = {i: ids() for i, t in enumerate(g.transitions) if len(t.targets) > 1}

    def producer_of_step(s: str, i: int) -> tuple[int, str | None]:
        """What transition ``i`` connects to, upstream of it, for its source step ``s``."""
        if s in sel_div:
            return sel_div[s], str(outgoing[s].index(i))
        return step_id[s], None

    def producer_of_transition(i: int, s: str) -> tuple[int, str | None]:
        """What step ``s`` (or its convergence) connects to, for its incoming transition ``i``."""
        if i in sim_div:
            return sim_div[i], str(g.transitions[i].targets.index(s))
        return trans_id[i], None

    shared = shared_orders(g)
    carriers = first_scan_steps(g) if shared else set()
    body = element("SFC")
    column: dict[str, int] = {p.name: k for k, p in enumerate(g.grafcets)}
    row: dict[str, int] = {}
    for p in g.grafcets:
        for r, s in enumerate(p.steps):
            row[s.name] = r
    for s in g.steps:
        x, y = 40 + 400 * column[s.grafcet], 40 + 160 * row[s.name]
        el = element("step", {"localId": str(step_id[s.name]), "name": sfc_step_name(s.name),
                         "initialStep": "true" if s.initial else "false"}, position(x, y))
        if s.name in sel_conv:
            el.append(_conn_in((sel_conv[s.name], None)))
        elif incoming[s.name]:
            el.append(_conn_in(producer_of_transition(incoming[s.name][0], s.name)))
        el.append(element("connectionPointOut", {"formalParameter": ""}))
        if s.actions or s.name in carriers or s.name in names.mirrored:
            el.append(element("connectionPointOutAction", {"formalParameter": ""}))
        data = element("data", {"name": SYNTH_DATA, "handleUnknown": "discard"}, element("grafcet", {"name": s.grafcet}))
        el.append(element("addData", None, data))
        body.append(el)
        if s.name in sel_conv:
            producers = [producer_of_transition(i, s.name) for i in incoming[s.name]]
            body.append(element("selectionConvergence", {"localId": str(sel_conv[s.name])}, position(x, y - 30),
                                *_branches(producers), element("connectionPointOut")))
        if s.name in sel_div:
            div = element("selectionDivergence", {"localId": str(sel_div[s.name])}, position(x, y + 50),
                     _conn_in((step_id[s.name], None)))
            for k in range(len(outgoing[s.name])):
                div.append(element("connectionPointOut", {"formalParameter": str(k)}))
            body.append(div)
        if s.actions or s.name in carriers or s.name in names.mirrored:
            block = element("actionBlock", {"localId": str(ids())}, position(x + 120, y), _conn_in((step_id[s.name], None)))
            for k, a in enumerate(s.actions):
                own = a.order in shared and a.kind in (CONTINUOUS, CONDITIONAL)
                block.extend(_actions(a, ids, k, names, (shared_flag(names(a.order), s.name),
                                                         _shared_or(a.order, shared[a.order], names)) if own else None))
            if s.name in carriers:
                for k, (order, emitters) in enumerate(shared.items(), len(s.actions)):
                    text = _shared_or(order, emitters, names)
                    block.append(element("action", {"localId": str(ids()), "qualifier": Qualifier.S},
                                         position(0, 30 * k, "relPosition"),
                                         element("inline", None, element("ST", None, xhtml(text)))))
            if s.name in names.mirrored:
                block.append(element("action", {"localId": str(ids()), "qualifier": Qualifier.N},
                                     position(0, 30 * (len(s.actions) + len(shared) * (s.name in carriers)), "relPosition"),
                                     element("reference", {"name": mirror_flag(s.name)})))
            body.append(block)
    for i, t in enumerate(g.transitions):
        col = column[t.grafcet]
        first = t.sources[0] if t.sources else (t.targets[0] if t.targets else None)
        x = 40 + 400 * col + (120 if t.sources and len(outgoing[t.sources[0]]) > 1
                              and outgoing[t.sources[0]].index(i) else 0)
        y = 40 + 160 * (row.get(first, 0) if first else 0) + 90
        if i in sim_conv:
            body.append(element("simultaneousConvergence", {"localId": str(sim_conv[i])}, position(x, y - 20),
                                *_branches([producer_of_step(s, i) for s in t.sources]), element("connectionPointOut")))
        el = element("transition", {"localId": str(trans_id[i])}, position(x, y))
        if i in sim_conv:
            el.append(_conn_in((sim_conv[i], None)))
        elif t.sources:
            el.append(_conn_in(producer_of_step(t.sources[0], i)))
        el.append(element("connectionPointOut"))
        label = t.label or ""
        inline = element("inline", {"name": label}, element("ST", None, xhtml(_sfc_expr(t.receptivity, names))))
        el.append(element("condition", None, inline))
        body.append(el)
        if i in sim_div:
            div = element("simultaneousDivergence", {"localId": str(sim_div[i])}, position(x, y + 20),
                     _conn_in((trans_id[i], None)))
            for k in range(len(t.targets)):
                div.append(element("connectionPointOut", {"formalParameter": str(k)}))
            body.append(div)
    pou_name = name or program_name(g.path)
    iface = element("interface")
    edges = sorted({(n.rising, n.name) for x in g.expressions() for n in expr_names(x) if isinstance(n, Edge)}, key=lambda e: (e[1], not e[0]))
    for key, declared in (("inputVars", g.inputs), ("outputVars", g.outputs)):
        vl = element(key)
        for n in declared:
            vl.append(element("variable", {"name": names(n)}, element("type", None, element("BOOL"))))
        if key == "inputVars":
            vl.extend(_edge_input(rising, n, names) for rising, n in edges)
        iface.append(vl)
    if g.internals:
        vl = element("localVars")
        for d in internal_declarations(g, names)[:len(g.internals)]:
            vl.append(element("variable", {"name": d.name}, element("type", None, element(d.type)),
                              element("initialValue", None, element("simpleValue", {"value": str(d.init)})),
                              element("documentation", None, xhtml(d.comment, cdata=False))))
        iface.append(vl)
    if shared:
        vl = element("localVars")
        for order, emitters in shared.items():
            for e in emitters:
                vl.append(element("variable", {"name": shared_flag(names(order), e)}, element("type", None, element("BOOL")),
                                  element("documentation", None, xhtml(f"{order} as step {e} emits it", cdata=False))))
        iface.append(vl)
    if names.mirrored:
        vl = element("localVars")
        for s in g.steps:
            if s.name in names.mirrored:
                vl.append(element("variable", {"name": mirror_flag(s.name)}, element("type", None, element("BOOL")),
                                  element("initialValue", None, element("simpleValue", {"value": str(s.initial).upper()})),
                                  element("documentation", None, xhtml(f"the flag of step {s.name}, read before the "
                                                                       "step's declaration", cdata=False))))
        iface.append(vl)
    pou_name = _program_name(pou_name, name is None, [*(str(v.get("name")) for v in iface.iter() if v.get("name")),
                                                      *(sfc_step_name(s.name) for s in g.steps)])
    pou = element("pou", {"name": pou_name, "pouType": "program"}, iface, element("body", None, body))
    if names.alias:
        comment = "\n".join(c for c in (comment, renamed_note(names.alias)) if c)
    return project(pou_name, version or synth_version(), comment, [pou])


def _edge_input(rising: bool, n: str, names: _Names) -> Any:
    """The input ``_RE_x`` (``_FE_x``) a receptivity ``↑x`` (``↓x``) reads: an SFC has no place
    before its transitions where the program could compute it (MATIEC runs the action bodies
    after the transitions, so an edge computed in an action is seen one scan late), so the
    caller computes it before each scan, from ``x`` and its value at the previous scan."""
    x = names(n)
    rule = f"{x} AND NOT {x}_previous" if rising else f"NOT {x} AND {x}_previous"
    doc = (f"{'rising' if rising else 'falling'} edge of {x}, set by the caller before each scan: {rule} "
           f"({x}_previous: {x} at the previous scan, {x} itself at the first scan: no edge then)")
    return element("variable", {"name": ("_RE_" if rising else "_FE_") + x}, element("type", None, element("BOOL")),
                   element("documentation", None, xhtml(doc, cdata=False)))


def shared_flag(order: str, step: str) -> str:
    """The local BOOL that step ``step`` drives for the shared order ``order``.

    >>> shared_flag("RUN", "12")
    '_N_RUN_S12'
    """
    return f"{FLAG_PREFIX}{order}_{sfc_step_name(step)}"


def shared_orders(g: Grafcet) -> dict[str, list[str]]:
    """The orders that several steps emit continuously or conditionally (``A``, ``A if c``),
    and that no stored action writes: order -> its emitting steps, in step order.

    MATIEC (Beremiz, OpenPLC) resets an ``N`` action's variable when one of its steps is left
    even while another keeps it (measured: the order off for one scan), so each emitting step
    drives a flag of its own (:func:`shared_flag`, with the action it has in the ``.g7``) and
    an ``S`` action on the initial steps (and the steps the first scan reaches,
    :func:`first_scan_steps`), run at every scan from the first one (as Beremiz runs its
    function blocks), writes the order as the OR of the flags."""
    emitters: dict[str, list[str]] = {}
    stored: set[str] = set()
    for s in g.steps:
        for a in s.actions:
            if a.kind in (CONTINUOUS, CONDITIONAL):
                emitters.setdefault(a.order, [])
                if s.name not in emitters[a.order]:
                    emitters[a.order].append(s.name)
            else:
                stored.add(a.order)
    return {o: steps for o, steps in emitters.items() if len(steps) > 1 and o not in stored}


def first_scan_steps(g: Grafcet) -> set[str]:
    """The steps that can be active after the first scan: the initial steps and the targets of
    the transitions from initial steps only. Each carries the ``S`` action writing the shared
    orders: MATIEC sets an ``S`` action only while its step is active after the scan's
    evolution, so on an initial step alone the OR would never run once that step is left at
    the first scan (measured); whichever of them is active starts it, and it then runs at
    every scan."""
    initial = {s.name for s in g.steps if s.initial}
    return initial | {x for t in g.transitions if t.sources and set(t.sources) <= initial for x in t.targets}


def _shared_or(order: str, emitters: Sequence[str], names: _Names) -> str:
    """The statement writing a shared order as the OR of its steps' flags."""
    return f"{names(order)} := " + " OR ".join(shared_flag(names(order), e) for e in emitters) + ";"


def _actions(a: Action, ids: _Ids, k: int, names: _Names, flag: tuple[str, str] | None = None) -> list[Any]:
    """The SFC action(s) of one ``.g7`` action, with its IEC 61131-3 meaning: ``A if c`` is an
    ST body under ``N`` (run while the step is active) and a ``P0`` body ``A := FALSE;`` (run
    once when it is left), since a PLC does not run an action body again after its step is
    left (MATIEC, hence Beremiz and OpenPLC, run it only while the action is active).
    ``flag``: the step's own flag of a shared order, written instead of the order, and the
    statement writing the order from the flags, which an inline body repeats after its flag
    (MATIEC runs the bodies one after the other, the initial step's first: the OR there would
    read this flag as the previous scan left it)."""
    order, again = (flag[0], " " + flag[1]) if flag else (names(a.order), "")

    def new(qualifier: Qualifier, body: Any, row: int = 0) -> Any:
        el = element("action", {"localId": str(ids()), "qualifier": qualifier})
        el.append(position(0, 30 * (k + row), "relPosition"))
        el.append(body)
        return el

    def st(text: str) -> Any:
        return element("inline", None, element("ST", None, xhtml(text)))

    value = "TRUE" if a.value else "FALSE"
    if a.kind == ASSIGN:
        assert a.assign is not None
        value = sum_text(names.internals[a.order], a.assign, names)
    if a.kind == ASSIGN and a.when == ON_ACTIVATION:
        return [new(Qualifier.P1, st(f"{order} := {value};"))]
    if a.kind == CONTINUOUS:
        return [new(Qualifier.N, element("reference", {"name": order}))]
    if a.kind == CONDITIONAL:
        assert a.condition is not None
        return [new(Qualifier.N, st(f"{order} := {_sfc_expr(a.condition, names)};{again}")),
                new(Qualifier.P0, st(f"{order} := FALSE;{again}"), 1)]
    if a.when == ON_ACTIVATION:
        return [new(Qualifier.S if a.value else Qualifier.R, element("reference", {"name": order}))]
    if a.when == ON_DEACTIVATION:
        return [new(Qualifier.P0, st(f"{order} := {value};"))]
    assert a.when == ON_EVENT and a.condition is not None
    return [new(Qualifier.N, st(f"IF {_sfc_expr(a.condition, names)} THEN {order} := {value}; END_IF;"))]
