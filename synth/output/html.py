"""The only layer that calls Graphviz: DOT text → SVG, and atomic file output."""

from __future__ import annotations

import shutil
from pathlib import Path
from typing import TYPE_CHECKING

from synth.errors import SynthError
from synth.output.files import write_atomic

if TYPE_CHECKING:
    from synth.validation.validate import Validation

__all__ = ["svg", "write_svg", "dot_available", "report_html", "write_report"]


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


def _esc(text: str) -> str:
    import html

    return html.escape(text, quote=True)


def _inline_svg(dot_text: str) -> str:
    text = svg(dot_text)
    start = text.find("<svg")
    return f'<div class="figure">{text[start:] if start >= 0 else text}</div>'


_CSS = """
body { font-family: Helvetica, Arial, sans-serif; margin: 2em; color: #222; max-width: 1200px; }
h1 { margin-bottom: 0.2em; } .pass { color: #1e8449; } .fail { color: #c0392b; }
table { border-collapse: collapse; margin: 0.5em 0; } td, th { border: 1px solid #ccc; padding: 3px 8px; text-align: left; }
code, .mono { font-family: Menlo, Consolas, monospace; } .figure { overflow-x: auto; margin: 1em 0; }
.diag { background: #fdf2e9; border-left: 4px solid #e67e22; padding: 0.6em 1em; }
.problem { border-top: 2px solid #ddd; margin-top: 2em; padding-top: 1em; }
"""


def report_html(v: "Validation") -> str:
    """The self-contained HTML report of a validation (inline SVG made by Graphviz)."""
    from synth.output.dot import aggregated_dot, element_dot, sup_neighbourhood_dot, trace_dot
    from synth.output.result import prohibited_json, validation_json

    data = validation_json(v)
    a = v.analysis
    verdict = data["verdict"]
    parts = [
        "<!DOCTYPE html>",
        '<html lang="en"><head><meta charset="utf-8">',
        f"<title>synth validate: {_esc(Path(v.grafcet.path).name)}</title>",
        f"<style>{_CSS}</style></head><body>",
        f'<h1 class="{verdict}">{verdict.upper()}</h1>',
        f"<p>Grafcet <code>{_esc(v.grafcet.path)}</code>, plant <code>{_esc(v.rules.path)}</code>, "
        f"{data['mode']} mode.</p>",
        "<table><tr>" + "".join(f"<th>{_esc(k)}</th>" for k in data["stats"]) + "</tr><tr>"
        + "".join(f"<td>{val}</td>" for val in data["stats"].values()) + "</tr></table>",
        f"<p>{len(a.blocking)} blocking situation(s), {len(a.prohibited)} situation(s) with prohibited orders.</p>",
    ]
    for c in data["conflicts"]:
        parts.append(
            f"<p class='diag'>Transitions <code>{_esc(', '.join(c['transitions']))}</code> leaving step "
            f"<code>{_esc(c['step'])}</code> fired together after <code>{_esc(' '.join(c['trace']))}</code>: "
            "every branch of the divergence became active.</p>"
        )
    if data["unreached_steps"]:
        parts.append(
            "<p>Steps never active in a reachable stable situation: <code>"
            + _esc(", ".join(data["unreached_steps"]))
            + "</code></p>"
        )
    if data["constraints"]:
        parts.append("<details><summary>Constraints</summary><table>")
        for c in v.rules.constraints:
            parts.append(f"<tr><td>{_esc(c.id)}</td><td>{_esc(c.label)}</td><td><code>{_esc(c.text())}</code></td></tr>")
        parts.append("</table></details>")
    for k, (b, item) in enumerate(zip(a.blocking, data["blocking"]), 1):
        d = v.diagnoses[b]
        tr = a.traces[b]
        parts += [
            f'<div class="problem"><h2>Blocking {k}: situation {_esc(v.sync.nodes[b].situation.text())}</h2>',
            _state_table(item),
            f"<p>Trace: <code>{_esc(' '.join(tr.events) or '(initial state)')}</code></p>",
            f'<div class="diag"><b>{_esc(d.verdict)}</b>: {_esc(d.summary)}<ul>'
            + "".join(f"<li><code>{_esc(x.strip())}</code></li>" for x in d.details)
            + "</ul></div>",
            "<h3>Trace to the blocking state</h3>",
            _inline_svg(trace_dot(v.sync, tr.nodes, tr.events, blocking=b)),
        ]
        elements, events = _involved(v, b, d)
        for name in elements:
            axis = next(i for i, e in enumerate(v.plant.elements) if e.name == name)
            el = v.plant.elements[axis]
            here = v.sync.nodes[b].plant[axis]
            parts += [
                f"<h3>Element {_esc(name)}</h3>",
                f"<p>In the blocking state {_esc(name)} is in {_esc(el.state_label(here))} (filled); "
                "the awaited event and the orders that cause it are drawn thick.</p>",
                _inline_svg(element_dot(el, highlight=events, current=here)),
            ]
        parts += [
            "<h3>SUP around the blocking state</h3>",
            _inline_svg(sup_neighbourhood_dot(v.sync, v.sync.nodes[b].plant)),
            "</div>",
        ]
    for k, i in enumerate(a.prohibited, 1):
        tr = a.traces[i]
        items = prohibited_json(v, i)
        parts += [
            f'<div class="problem"><h2>Prohibited orders {k}: situation {_esc(v.sync.nodes[i].situation.text())}</h2>',
            _state_table(items[0]) if items else "",
            f"<p>Trace: <code>{_esc(' '.join(tr.events) or '(initial state)')}</code></p>",
            "".join(f'<div class="diag">{_esc(x["diagnosis"])}</div>' for x in items),
            _inline_svg(trace_dot(v.sync, tr.nodes, tr.events, blocking=None)),
            "</div>",
        ]
    if len(v.sync.nodes) <= 120:
        parts += ["<h2>Aggregated automaton</h2>", _inline_svg(aggregated_dot(v.sync, blocking=a.blocking))]
    parts.append("</body></html>")
    return "\n".join(parts) + "\n"


def _state_table(item: dict) -> str:
    e = " ".join(k for k, x in item["E"].items() if x) or "-"
    z = " ".join(k for k, x in item["Z"].items() if x) or "-"
    proh = ", ".join(f"{p['order']} ({', '.join(p['constraints'])})" for p in item["proh"]) or "-"
    rows = [("Sit", ", ".join(item["situation"])), ("E (true)", e), ("Z (true)", z), ("ORD", ", ".join(item["ord"]) or "-"), ("PROH", proh)]
    return "<table>" + "".join(f"<tr><th>{k}</th><td class='mono'>{_esc(val)}</td></tr>" for k, val in rows) + "</table>"


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
