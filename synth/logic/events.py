"""Events: an edge of an input or output (``↑x``, ``↓x``) or a timer elapsing (``2s/X101``).

Example
-------
>>> parse_event("^dcy"), event_text(("v10", False))
(('dcy', True), '↓v10')
"""

from __future__ import annotations

from synth.logic.expr import edge_text

__all__ = ["Event", "parse_event", "event_text"]

# (input name, rising) for an input edge, or a timer id
Event = tuple[str, bool] | str

def parse_event(text: str) -> Event:
    """``"↑dcy"``/``"^dcy"`` → ``("dcy", True)``, ``"↓v10"``/``"_v10"`` → ``("v10", False)``,
    a timer ``"2s/X101"`` stays a string.

    >>> parse_event("^dcy"), parse_event("↓v10"), parse_event("2s/X101")
    (('dcy', True), ('v10', False), '2s/X101')
    """
    t = text.strip()
    if t[:1] in ("↑", "^"):
        return (t[1:].strip(), True)
    if t[:1] in ("↓", "_"):
        return (t[1:].strip(), False)
    return t


def event_text(event: Event) -> str:
    """``("dcy", True)`` → ``"↑dcy"``; a timer id is returned as is."""
    return event if isinstance(event, str) else edge_text(event[1], event[0])
