"""DOT text for automata (pure functions; only :mod:`synth.report` calls Graphviz).

Example
-------
>>> print(dot_graph("g", [("a", "a", {}), ("b", "b", {"peripheries": "2"})],
...                 [("a", "b", "↑x", {})]).splitlines()[3])
  "a" [label="a"];
"""

from __future__ import annotations

from typing import Iterable, Mapping

from .plant import ElementAutomaton

__all__ = ["dot_graph", "dot_escape", "element_dot"]

CONTROLLABLE_STYLE = {"color": "#1f5fa8", "fontcolor": "#1f5fa8"}
UNCONTROLLABLE_STYLE = {"color": "#b03a2e", "fontcolor": "#b03a2e", "style": "dashed"}
HIGHLIGHT_STYLE = {"penwidth": "3", "color": "#e67e22", "fontcolor": "#e67e22"}


def dot_escape(text: str) -> str:
    return text.replace("\\", "\\\\").replace('"', '\\"').replace("\n", "\\n")


def _attrs(attrs: Mapping[str, str]) -> str:
    return ", ".join(f'{k}="{dot_escape(str(v))}"' for k, v in sorted(attrs.items()))


def dot_graph(
    name: str,
    nodes: Iterable[tuple[str, str, Mapping[str, str]]],
    edges: Iterable[tuple[str, str, str, Mapping[str, str]]],
    *,
    rankdir: str = "LR",
    node_defaults: Mapping[str, str] | None = None,
) -> str:
    """A digraph: nodes ``(id, label, attrs)``, edges ``(src, dst, label, attrs)``."""
    defaults = {"shape": "ellipse", "fontname": "Helvetica", "fontsize": "10"}
    defaults.update(node_defaults or {})
    out = [
        f'digraph "{dot_escape(name)}" {{',
        f'  rankdir="{rankdir}";',
        f"  node [{_attrs(defaults)}];",
        '  edge [fontname="Helvetica", fontsize="9"];',
    ]
    for nid, label, attrs in nodes:
        out.append(f'  "{dot_escape(nid)}" [{_attrs({"label": label, **attrs})}];')
    for src, dst, label, attrs in edges:
        out.append(f'  "{dot_escape(src)}" -> "{dot_escape(dst)}" [{_attrs({"label": label, **attrs})}];')
    out.append("}")
    return "\n".join(out) + "\n"


def element_dot(a: ElementAutomaton, highlight: Iterable[str] = ()) -> str:
    """An element automaton; controllable edges solid blue, uncontrollable dashed red;
    transitions whose event is in ``highlight`` drawn thick orange."""
    marked = set(highlight)
    nodes = []
    for k in range(a.size):
        attrs = {"peripheries": "2"} if k == a.initial else {}
        nodes.append((str(k), a.state_label(k), attrs))
    edges = []
    for t in range(a.src.size):
        ev = a.event(t)
        style = dict(CONTROLLABLE_STYLE if a.controllable[t] else UNCONTROLLABLE_STYLE)
        if ev in marked:
            style.update(HIGHLIGHT_STYLE)
        edges.append((str(int(a.src[t])), str(int(a.dst[t])), ev, style))
    return dot_graph(a.name, nodes, edges)
