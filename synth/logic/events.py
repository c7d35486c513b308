"""Events: an edge of an input or output (``↑x``, ``↓x``) or a timer elapsing (``2s/X101``).

One type for every layer (plant transitions, Grafcet evolution, SYNC edges,
diagnosis, exports). An :class:`Event` *is* its printed text (a ``str``
subclass), so it sorts, hashes, prints and serialises to JSON exactly as the
text always did; callers read :attr:`Event.kind` and :attr:`Event.name` instead
of slicing the text.

Example
-------
>>> e = parse_event("^dcy")
>>> e, e.kind, e.name, e.rising
('↑dcy', <EventKind.RISE: 'rise'>, 'dcy', True)
>>> Event.edge("v10", False), Event.timer("2s/X101").kind
('↓v10', <EventKind.TIMER: 'timer'>)
"""

from __future__ import annotations

from enum import StrEnum

__all__ = ["EventKind", "Event", "parse_event", "event_text", "RISE_MARKS", "FALL_MARKS"]

RISE_MARKS = ("↑", "^")  # printed mark first, ASCII spelling second
FALL_MARKS = ("↓", "_")
SCAN_TEXT = "scan"


class EventKind(StrEnum):
    RISE = "rise"  # a variable goes 0 → 1
    FALL = "fall"  # a variable goes 1 → 0
    TIMER = "timer"  # ``t/Xi`` becomes true
    SCAN = "scan"  # a PLC cycle with no input change (IEC 61131-3 SFC: one evolution per scan)


class Event(str):
    """An event, equal to its printed text: ``↑x``, ``↓x`` or a timer id ``2s/X101``.

    >>> Event.rise("AVANCER1").name, Event.fall("v10").rising
    ('AVANCER1', False)
    """

    __slots__ = ()

    @classmethod
    def rise(cls, name: str) -> Event:
        return cls(RISE_MARKS[0] + name)

    @classmethod
    def fall(cls, name: str) -> Event:
        return cls(FALL_MARKS[0] + name)

    @classmethod
    def edge(cls, name: str, rising: bool) -> Event:
        """The edge of ``name``: rising (0 → 1) or falling."""
        return cls.rise(name) if rising else cls.fall(name)

    @classmethod
    def timer(cls, timer_id: str) -> Event:
        return cls(timer_id)

    @classmethod
    def scan(cls) -> Event:
        """A PLC scan in which no input changed (``--semantics sfc``)."""
        return cls(SCAN_TEXT)

    @property
    def kind(self) -> EventKind:
        head = self[:1]
        if head == RISE_MARKS[0]:
            return EventKind.RISE
        if head == FALL_MARKS[0]:
            return EventKind.FALL
        if self == SCAN_TEXT:
            return EventKind.SCAN
        return EventKind.TIMER

    @property
    def is_edge(self) -> bool:
        return self.kind in (EventKind.RISE, EventKind.FALL)

    @property
    def rising(self) -> bool:
        """True for ``↑x`` (the variable becomes true); False for falls and timers."""
        return self.kind is EventKind.RISE

    @property
    def name(self) -> str:
        """The variable of an edge; a timer's id."""
        return str.__str__(self[1:]) if self.is_edge else str.__str__(self)

    def __repr__(self) -> str:
        return str.__repr__(self)


def parse_event(text: str) -> Event:
    """``"↑dcy"``/``"^dcy"`` → ``↑dcy``, ``"↓v10"``/``"_v10"`` → ``↓v10``; anything else
    is a timer id.

    >>> parse_event("^dcy"), parse_event("↓ v10"), parse_event("2s/X101").kind.value
    ('↑dcy', '↓v10', 'timer')
    """
    t = text.strip()
    if t == SCAN_TEXT:
        return Event.scan()
    if t[:1] in RISE_MARKS:
        return Event.rise(t[1:].strip())
    if t[:1] in FALL_MARKS:
        return Event.fall(t[1:].strip())
    return Event.timer(t)


def event_text(event: Event) -> str:
    """The printed text of ``event`` (a plain ``str``)."""
    return str.__str__(event)
