"""The plant: the rules language, element automata, and their asynchronous composition.

The names below are re-exported lazily (on first use), so importing the package costs nothing.
"""

from __future__ import annotations

from importlib import import_module
from typing import Any

_WHERE = {
    "RuleSet": "rules",
    "Constraint": "rules",
    "ElementSpec": "rules",
    "load_rules": "rules",
    "parse_rules": "rules",
    "ElementAutomaton": "element",
    "element_automaton": "element",
    "Plant": "composition",
    "LocalTransition": "composition",
    "plant": "composition",
}

__all__ = sorted(_WHERE)


def __getattr__(name: str) -> Any:
    if name in _WHERE:
        return getattr(import_module(f"{__name__}.{_WHERE[name]}"), name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
