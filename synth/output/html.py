"""The only layer that calls Graphviz: DOT text → SVG, and the HTML report (each drawing
at its natural size in one scroll box).

Example
-------
>>> _figure("<svg></svg>", ident="chart", kind="whole")
'<div class="figure whole" id="chart"><svg></svg></div>'
"""

from __future__ import annotations

import shutil
from pathlib import Path
from typing import TYPE_CHECKING, Any, Mapping

from synth.errors import SynthError
from synth.output.files import write_atomic

if TYPE_CHECKING:
    from synth.validation.diagnosis import Diagnosis
    from synth.validation.result import Validation

__all__ = ["svg", "write_svg", "dot_available", "report_html", "write_report", "commission_html"]


def dot_available() -> bool:
    """Whether Graphviz's ``dot`` program is on the PATH."""
    return shutil.which("dot") is not None


def svg(dot_text: str) -> str:
    """Render DOT text to SVG text with Graphviz's ``dot``."""
    import graphviz

    if not dot_available():
        raise SynthError("Graphviz's 'dot' program is not installed (Debian: apt-get install graphviz)")
    try:
        out = graphviz.Source(dot_text).pipe(format="svg", encoding="utf-8")
    except graphviz.backend.ExecutableNotFound as exc:  # pragma: no cover - checked above
        raise SynthError(str(exc)) from None
    except graphviz.backend.CalledProcessError as exc:
        raise SynthError(f"Graphviz failed: {exc.stderr.decode('utf-8', 'replace') if exc.stderr else exc}") from None
    return out


def write_svg(path: str | Path, dot_text: str) -> Path:
    """Render and write an SVG file atomically."""
    return write_atomic(path, svg(dot_text))


def _template(name: str):
    """A template shipped in ``synth/output/templates`` (jinja2, HTML-escaped)."""
    import jinja2

    env = jinja2.Environment(
        loader=jinja2.PackageLoader("synth.output", "templates"),
        autoescape=True,
        keep_trailing_newline=True,
        undefined=jinja2.StrictUndefined,
    )
    return env.get_template(name)


MISSING_DOT_NOTE = ("drawing missing: Graphviz's dot program is not installed (Debian: apt-get install graphviz); "
                    "its DOT text follows")


def _drawing(dot_text: str) -> str:
    """The drawing as inline SVG at its natural size (Graphviz's 10 pt text is 13 px at
    100 %); without Graphviz, a note and the DOT text (folded away)."""
    if not dot_available():
        from markupsafe import escape

        return (f'<p class="note">{escape(MISSING_DOT_NOTE)}</p>'
                f"<details><summary>DOT</summary><pre>{escape(dot_text)}</pre></details>")
    text = svg(dot_text)
    start = text.find("<svg")
    return text[start:] if start >= 0 else text


def _figure(drawing: str, *, ident: str = "", kind: str = "") -> str:
    """A drawing in its one scroll box (``kind`` ``whole``: never cut in height)."""
    classes = "figure" + (f" {kind}" if kind else "") + ("" if drawing.startswith("<svg") else " missing")
    where = f' id="{ident}"' if ident else ""
    return f'<div class="{classes}"{where}>{drawing}</div>'


def _inline_svg(dot_text: str, *, kind: str = "") -> str:
    return _figure(_drawing(dot_text), kind=kind)


def _walk_step(event: str, state: dict) -> dict:
    """One trace step for the page's state panel: names of the true variables."""
    from synth.output.result import state_names

    true_e, true_z, proh = state_names(state)
    return {
        "event": event,
        "situation": state["situation"],
        "E": true_e,
        "Z": true_z,
        "ord": state["ord"],
        "proh": proh,
        "stored": state["stored"],
        "elapsed": state["elapsed"],
    }


def report_html(v: "Validation") -> str:
    """The self-contained HTML report of a validation (inline SVG made by Graphviz; no
    network requests): the problems first, each trace step clickable to show its state
    and the Grafcet's active steps, then what was checked, a legend and the drawings."""
    from markupsafe import Markup

    from synth.output.dot import aggregated_dot, element_dot, element_neighbourhood, grafcet_dot, sup_neighbourhood_dot, trace_dot
    from synth.output.glossary import GLOSSARY_TERMS
    from synth.output.result import prohibited_json, validation_json

    data = validation_json(v)
    a = v.analysis
    chart = _drawing(grafcet_dot(v.grafcet))
    blocking = []
    walks: dict[str, list[dict]] = {}
    for k, (b, item) in enumerate(zip(a.blocking, data["blocking"]), 1):
        d = v.diagnoses[b]
        tr = a.traces[b]
        names, events = _involved(v, b, d)
        elements = []
        for name in names:
            axis = next(i for i, e in enumerate(v.plant.elements) if e.name == name)
            el = v.plant.elements[axis]
            here = v.sync.nodes[b].plant[axis]
            near = element_neighbourhood(el, [v.sync.nodes[n].plant[axis] for n in tr.nodes], events)
            whole = len(near) == el.size
            elements.append({"name": name, "state": el.state_label(here), "size": el.size,
                             "svg": Markup(_inline_svg(element_dot(el, highlight=events, current=here, keep=near))),
                             "full_svg": None if whole else Markup(_inline_svg(element_dot(el, highlight=events, current=here)))})
        steps = [_walk_step(ev, st) for ev, st in zip(["initial"] + list(tr.events), item["trace_states"])]
        walks[f"b{k}"] = steps
        blocking.append({
            "situation": v.sync.nodes[b].situation.text(),
            "item": item,
            "steps": steps,
            "diagnosis": d,
            "fix": step_to_fix(d),
            "trace_svg": Markup(_inline_svg(trace_dot(v.sync, tr.nodes, tr.events, blocking=b), kind="whole")),
            "elements": elements,
            "sup_svg": Markup(_inline_svg(sup_neighbourhood_dot(v.sync, v.sync.nodes[b].plant))),
        })
    prohibited = []
    for i in a.prohibited:
        tr = a.traces[i]
        prohibited.append({
            "situation": v.sync.nodes[i].situation.text(),
            "entries": prohibited_json(v, i),
            "trace": tr.events,
            "trace_svg": Markup(_inline_svg(trace_dot(v.sync, tr.nodes, tr.events, blocking=None), kind="whole")),
        })
    keep = None
    if a.blocking:  # the part that leads to the blocking states
        keep = {n for b in a.blocking for n in a.traces[b].nodes} | {n for b in a.blocking for n in a.components[b]}
    shown = len(keep) if keep is not None else len(v.sync.nodes)
    aggregated = Markup(_inline_svg(aggregated_dot(v.sync, keep=keep, blocking=a.blocking))) if shown <= 120 else None
    steps_total = len(v.grafcet.steps)
    return _template("report.html.j2").render(
        grafcet_name=Path(v.grafcet.path).name,
        data=data,
        constraints=v.rules.constraints,
        blocking=blocking,
        prohibited=prohibited,
        aggregated_svg=aggregated,
        grafcet_svg=Markup(_figure(chart, ident="grafcet", kind="fit")),
        fixes={f"b{k}": list(b["fix"]["steps"]) if b["fix"] else [] for k, b in enumerate(blocking, 1)},
        glossary=GLOSSARY_TERMS,
        aggregated_cut=keep is not None,
        aggregated_states=shown,
        situations=len({n.situation for n in v.sync.nodes}),
        steps_covered=steps_total - len(data["unreached_steps"]),
        steps_total=steps_total,
        walks=walks,
        state_table=_state_table,
    )


def step_to_fix(d: "Diagnosis") -> dict | None:
    """A missing order's step (the source steps of the awaited transition whose cause is an
    order not emitted, the one the diagnosis names): its steps, names and why; else None.

    >>> from synth.validation.diagnosis import Diagnosis, Verdict
    >>> step_to_fix(Diagnosis(Verdict.DEAD_END, "no transition leaves X1")) is None
    True
    """
    from synth.validation.diagnosis import Verdict

    if d.verdict is not Verdict.MISSING_ORDER:
        return None
    for a in d.awaited:
        for c in a.causes:
            if c.changes and not c.emitted and not c.free and a.sources:
                ch = c.changes[0]
                why = f"missing order {ch.name}" if ch.rising else f"order {ch.name} must be released"
                return {"steps": list(a.sources), "names": [f"X{s}" for s in a.sources], "why": why}
    return None


def _state_table(item: dict):
    """Sit, E, Z, ORD and PROH of one state, as an HTML table."""
    from markupsafe import Markup, escape

    from synth.output.result import state_names

    true_e, true_z, proh = state_names(item)
    rows = [("Sit", ", ".join(item["situation"])), ("E (true)", " ".join(true_e) or "-"),
            ("Z (true)", " ".join(true_z) or "-"), ("ORD", ", ".join(item["ord"]) or "-"), ("PROH", proh or "-")]
    return Markup("<table>" + "".join(f"<tr><th>{k}</th><td class='mono'>{escape(val)}</td></tr>" for k, val in rows) + "</table>")


def _involved(v: "Validation", b: int, d) -> tuple[list[str], set[str]]:
    elements: list[str] = []
    events: set[str] = set()
    for aw in d.awaited:
        for c in aw.causes:
            if c.element and c.element not in elements:
                elements.append(c.element)
            events.add(c.event)
            events.update(c.changes)
    for pr in v.sync.nodes[b].proh:
        owner = v.plant.owner.get(pr.order)
        if owner is not None and v.plant.elements[owner].name not in elements:
            elements.append(v.plant.elements[owner].name)
        events.add(pr.event)
    return elements, events


def write_report(directory: str | Path, v: "Validation") -> Path:
    """Write ``DIRECTORY/index.html`` atomically; returns its path."""
    return write_atomic(Path(directory) / "index.html", report_html(v))


def commission_html(data: Mapping[str, Any]) -> str:
    """The report of ``synth commission --report``, from its JSON (``commission.json``): each run
    and walk, the closed-loop trace of every walk that did not pass, the coverage."""
    return _template("commission.html.j2").render(data=data)
