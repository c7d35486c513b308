"""The Grafcet (IEC 60848): the ``.g7`` language, its evolution machine, and the automaton of its stable situations (ASS).

The names below are re-exported lazily (on first use), so importing the package costs nothing.
"""

from __future__ import annotations

from importlib import import_module
from typing import Any

_WHERE = {
    "Grafcet": "language",
    "PartialGrafcet": "language",
    "Step": "language",
    "Transition": "language",
    "Action": "language",
    "Timer": "language",
    "load_grafcet": "language",
    "parse_grafcet": "language",
    "GrafcetMachine": "machine",
    "Situation": "machine",
}

__all__ = sorted(_WHERE)


def __getattr__(name: str) -> Any:
    if name in _WHERE:
        return getattr(import_module(f"{__name__}.{_WHERE[name]}"), name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
