"""DOT text for automata (pure functions; only :mod:`synth.output.html` calls Graphviz).

Example
-------
>>> print(dot_graph("g", [("a", "a", {}), ("b", "b", {"peripheries": "2"})],
...                 [("a", "b", "↑x", {})]).splitlines()[4])
  "a" [label="a"];
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Iterable, Mapping, Sequence

from synth.frozen import frozen

if TYPE_CHECKING:  # pragma: no cover
    from synth.grafcet.ass import ASS
    from synth.grafcet.language import Grafcet
    from synth.plant.composition import Plant
    from synth.plant.element import ElementAutomaton
    from synth.validation.sync import Sync

__all__ = ["Html", "dot_graph", "dot_escape", "element_dot", "element_neighbourhood", "trace_dot", "sup_neighbourhood_dot", "aggregated_dot", "ass_dot", "orders_text", "plant_dot", "grafcet_dot", "true_names"]

CONTROLLABLE_STYLE = {"color": "#1f5fa8", "fontcolor": "#1f5fa8"}
UNCONTROLLABLE_STYLE = {"color": "#b03a2e", "fontcolor": "#b03a2e", "style": "dashed"}
HIGHLIGHT_STYLE = {"penwidth": "3", "color": "#e67e22", "fontcolor": "#e67e22"}


@frozen
class Html:
    """An HTML-like Graphviz label, written ``<…>`` (its text escaped by the caller)."""

    text: str


def dot_escape(text: str) -> str:
    return text.replace("\\", "\\\\").replace('"', '\\"').replace("\n", "\\n")


def _attrs(attrs: Mapping[str, str | Html]) -> str:
    return ", ".join(f"{k}=<{v.text}>" if isinstance(v, Html) else f'{k}="{dot_escape(str(v))}"'
                     for k, v in sorted(attrs.items()))


def dot_graph(
    name: str,
    nodes: Iterable[tuple[str, str | Html, Mapping[str, str | Html]]],
    edges: Iterable[tuple[str, str, str, Mapping[str, str | Html]]],
    *,
    rankdir: str = "LR",
    node_defaults: Mapping[str, str] | None = None,
    graph_attrs: Mapping[str, str] | None = None,
) -> str:
    """A digraph: nodes ``(id, label, attrs)``, edges ``(src, dst, label, attrs)``."""
    defaults = {"shape": "ellipse", "fontname": "Helvetica", "fontsize": "10"}
    defaults.update(node_defaults or {})
    out = [
        f'digraph "{dot_escape(name)}" {{',
        f'  rankdir="{rankdir}";',
        *(f'  {k}="{dot_escape(v)}";' for k, v in (graph_attrs or {}).items()),
        f"  node [{_attrs(defaults)}];",
        '  edge [fontname="Helvetica", fontsize="9"];',
    ]
    for nid, label, attrs in nodes:
        out.append(f'  "{dot_escape(nid)}" [{_attrs({"label": label, **attrs})}];')
    for src, dst, label, attrs in edges:
        out.append(f'  "{dot_escape(src)}" -> "{dot_escape(dst)}" [{_attrs({"label": label, **attrs})}];')
    out.append("}")
    return "\n".join(out) + "\n"


def element_dot(a: "ElementAutomaton", highlight: Iterable[str] = (), current: int | None = None,
                keep: Iterable[int] | None = None) -> str:
    """An element automaton (or its states ``keep`` and the transitions among them);
    controllable edges solid blue, uncontrollable dashed red; transitions whose event is
    in ``highlight`` drawn thick orange; the local state ``current`` (e.g. the element's
    state in a blocking situation) filled."""
    marked = set(highlight)
    inside = set(range(a.size)) if keep is None else set(keep)
    nodes = []
    for k in sorted(inside):
        attrs = {"peripheries": "2"} if k == a.initial else {}
        if k == current:
            attrs.update({"style": "filled", "fillcolor": "#fadbd8", "color": "#c0392b", "penwidth": "2"})
        nodes.append((str(k), a.state_label(k), attrs))
    edges = []
    for t in range(a.src.size):
        src, dst = int(a.src[t]), int(a.dst[t])
        if src not in inside or dst not in inside:
            continue
        ev = a.event(t)
        style = dict(CONTROLLABLE_STYLE if a.controllable[t] else UNCONTROLLABLE_STYLE)
        if ev in marked:
            style.update(HIGHLIGHT_STYLE)
        edges.append((str(src), str(dst), ev, style))
    return dot_graph(a.name, nodes, edges)


def element_neighbourhood(a: "ElementAutomaton", path: Sequence[int], highlight: Iterable[str] = ()) -> frozenset[int]:
    """What a drawing of a trace's element needs: the states of ``path`` (the element's
    states along the trace) and their direct neighbours, and a shortest way from its last
    state to each ``highlight`` event (the awaited event, the orders that cause it) with
    that event's targets."""
    moves: dict[int, list[tuple[int, str]]] = {}
    for t in range(a.src.size):
        moves.setdefault(int(a.src[t]), []).append((int(a.dst[t]), a.event(t)))
    near = {d for s in path for d, _ in moves.get(s, ())}
    near |= {s for s, out in moves.items() for d, _ in out if d in path}
    core = set(path)
    if path:
        parent = {path[-1]: path[-1]}
        order = [path[-1]]
        for s in order:  # breadth-first: ``order`` grows while it is read
            for d, _ in moves.get(s, ()):
                if d not in parent:
                    parent[d] = s
                    order.append(d)
        for event in set(highlight):
            found = next((s for s in order if any(ev == event for _, ev in moves.get(s, ()))), None)
            if found is None:
                continue
            core.update(d for d, ev in moves[found] if ev == event)
            while found not in core:
                core.add(found)
                found = parent[found]
    return frozenset(core | near)


def true_names(names: Iterable[str], values: Mapping[str, bool]) -> str:
    """The variables that are true, by name (``v10 cp12``), ``-`` for none."""
    return " ".join(n for n in names if values[n]) or "-"


def grafcet_dot(g: "Grafcet") -> str:
    """The Grafcet as a chart: steps (initial ones double) with their actions, each
    transition a bar with its name and receptivity beside it (one node, so that no edge
    crosses the text). Step nodes are named ``step_<name>`` so that a page can mark the
    active steps."""
    from html import escape

    nodes: list[tuple[str, str | Html, Mapping[str, str | Html]]] = []
    edges: list[tuple[str, str, str, Mapping[str, str | Html]]] = []
    for step in g.steps:
        label = step.variable + ("\n" + "\n".join(a.text() for a in step.actions) if step.actions else "")
        attrs = {"shape": "box", "style": "filled", "fillcolor": "#ffffff"}
        if step.initial:
            attrs["peripheries"] = "2"
        nodes.append((f"step_{step.name}", label, attrs))
    for k, t in enumerate(g.transitions):
        bar = f"t{k}"
        text = escape(f"{t.name}: {t.receptivity.text()}", quote=False)
        nodes.append((bar, Html('<table border="0" cellborder="0" cellspacing="0" cellpadding="0"><tr>'
                                '<td port="bar" width="40" height="4" fixedsize="true" bgcolor="#222222"></td>'
                                f'<td align="left">&nbsp;{text}</td></tr></table>'), {"shape": "plaintext"}))
        for src in t.sources:
            edges.append((f"step_{src}", bar, "", {"arrowhead": "none", "headport": "bar"}))
        for dst in t.targets:
            edges.append((bar, f"step_{dst}", "", {"tailport": "bar"}))
    return dot_graph(g.path or "grafcet", nodes, edges, rankdir="TB")


def trace_dot(sync: "Sync", nodes: Iterable[int], events: Iterable[str], blocking: int | None = None) -> str:
    """A trace of the aggregated automaton drawn like the thesis's figure 2.10: each state
    with Sit, ORD, PROH, E and Z; the blocking state in red with a double border."""
    p = sync.plant
    nodes = list(nodes)
    out_nodes = []
    for k, i in enumerate(nodes):
        n = sync.nodes[i]
        val = p.valuation(n.plant)
        proh = ", ".join(f"{pr.order} ({', '.join(pr.constraints)})" for pr in n.proh)
        label = (
            f"{k}: Sit={n.situation.text()}\n"
            f"ORD={{{', '.join(n.ord)}}}  PROH={{{proh}}}\n"
            f"E: {true_names(p.inputs, val)}\nZ: {true_names(p.outputs, val)}"
        )
        attrs = {"shape": "box", "style": "rounded"}
        if k == 0:
            attrs["peripheries"] = "2"
        if i == blocking:
            attrs.update({"color": "#c0392b", "penwidth": "2", "peripheries": "2", "fontcolor": "#c0392b"})
        elif n.proh:
            attrs.update({"color": "#e67e22"})
        out_nodes.append((f"n{k}", label, attrs))
    edges = [(f"n{k}", f"n{k + 1}", ev, dict(UNCONTROLLABLE_STYLE)) for k, ev in enumerate(events)]
    return dot_graph("trace", out_nodes, edges, rankdir="TB")


def sup_neighbourhood_dot(sync: "Sync", local: tuple[int, ...]) -> str:
    """The plant state ``local`` and its one-step plant neighbours: transitions SUP keeps
    (solid) and controllable ones it forbids (dotted, with the constraint ids)."""
    p = sync.plant
    oracle = sync.oracle
    centre = p.label(local)
    nodes = [("c", centre, {"shape": "box", "color": "#c0392b", "penwidth": "2"})]
    edges: list[tuple[str, str, str, Mapping[str, str | Html]]] = []
    for k, (t, nxt) in enumerate(p.successors(local)):
        nid = f"s{k}"
        label = p.label(nxt)
        if t.controllable:
            ok, why = oracle.move(t, local)
        else:
            ok, why = oracle.kept(nxt), oracle.threatened(nxt)
        if ok:
            style = dict(CONTROLLABLE_STYLE if t.controllable else UNCONTROLLABLE_STYLE)
            nodes.append((nid, label, {"shape": "box"}))
            edges.append(("c", nid, t.event, style))
        else:
            nodes.append((nid, label, {"shape": "box", "color": "#999999", "fontcolor": "#999999"}))
            edges.append(("c", nid, f"{t.event} ✗ {', '.join(why)}", {"style": "dotted", "color": "#c0392b", "fontcolor": "#c0392b"}))
    return dot_graph("sup", nodes, edges)


def aggregated_dot(sync: "Sync", keep: Iterable[int] | None = None, blocking: Iterable[int] = ()) -> str:
    """The aggregated automaton (or its sub-graph ``keep``): one state per region."""
    p = sync.plant
    chosen = sorted(set(keep)) if keep is not None else list(range(len(sync.nodes)))
    inside = set(chosen)
    bad = set(blocking)
    nodes = []
    for i in chosen:
        n = sync.nodes[i]
        val = p.valuation(n.plant)
        attrs = {"shape": "box", "style": "rounded"}
        if i == 0:
            attrs["peripheries"] = "2"
        if i in bad:
            attrs.update({"color": "#c0392b", "penwidth": "2"})
        label = (f"q{i}: {n.situation.text()}\nORD={{{', '.join(n.ord)}}}\n"
                 f"E: {true_names(p.inputs, val)}\nZ: {true_names(p.outputs, val)}")
        nodes.append((f"q{i}", label, attrs))
    edges = [
        (f"q{e.source}", f"q{e.target}", e.event, dict(UNCONTROLLABLE_STYLE))
        for e in sync.edges
        if e.source in inside and e.target in inside
    ]
    # top to bottom, tight: its many BFS levels side by side made the 90 states of the box
    # sorting 10 900 px wide and 94 % white (docs/validate-json.md, "The HTML report")
    return dot_graph("aggregated", nodes, edges, rankdir="TB", graph_attrs={"nodesep": "0.2", "ranksep": "0.35"})


def orders_text(orders: Sequence[str], conditional: Sequence[str] = ()) -> str:
    """``A, B?`` (``?`` marks an order emitted only under some inputs); ``-`` for none."""
    if not orders:
        return "-"
    return ", ".join(o + ("?" if o in conditional else "") for o in orders)


def _dot_string(text: str) -> str:
    return f'"{dot_escape(text)}"'


def ass_dot(ass: "ASS", title: str = "ASS") -> str:
    """Graphviz DOT text of the ASS (pure function)."""
    lines = [f"digraph {_dot_string(title)} {{", "  rankdir=TB;", '  node [shape=box, fontname="Helvetica"];',
             '  edge [fontname="Helvetica", fontsize=10];']
    for s in ass.states:
        label = f"S{s.id}\n{s.situation.text()}\n{orders_text(s.orders, s.conditional)}"
        extra = ", peripheries=2" if s.id == ass.initial else ""
        lines.append(f"  S{s.id} [label={_dot_string(label)}{extra}];")
    for t in ass.transitions:
        label = t.event if t.condition == "any" else f"{t.event}\n[{t.condition}]"
        lines.append(f"  S{t.source} -> S{t.target} [label={_dot_string(label)}];")
    lines.append("}")
    return "\n".join(lines) + "\n"


def plant_dot(p: "Plant") -> str:
    """The whole plant automaton (small plants only: one node per state)."""
    nodes = []
    keep = p.reachable.ravel() if p.reads else None  # elements reading each other: reachable states only
    for code in range(p.size):
        if keep is not None and not keep[code]:
            continue
        local = p.local(code)
        nodes.append((str(code), p.label(local), {"peripheries": "2"} if local == p.initial else {}))
    edges = []
    for t, src, dst in p.transition_arrays(p.reachable if p.reads else None):
        style = CONTROLLABLE_STYLE if t.controllable else UNCONTROLLABLE_STYLE
        for s, d in zip(src.tolist(), dst.tolist()):
            edges.append((str(s), str(d), t.event, style))
    edges.sort(key=lambda e: (int(e[0]), e[2]))
    return dot_graph("plant", nodes, edges)
