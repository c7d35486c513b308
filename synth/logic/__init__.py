"""Boolean expressions, events and cubes: the vocabulary every language of synth shares.

The names below are re-exported lazily (on first use), so importing the package costs nothing.
"""

from __future__ import annotations

from importlib import import_module
from typing import Any

_WHERE = {
    "Expr": "expr",
    "Var": "expr",
    "Const": "expr",
    "Not": "expr",
    "And": "expr",
    "Or": "expr",
    "Edge": "expr",
    "Literal": "expr",
    "Monomial": "expr",
    "evaluate": "expr",
    "names": "expr",
    "disjunctive_normal_form": "expr",
}

__all__ = sorted(_WHERE)


def __getattr__(name: str) -> Any:
    if name in _WHERE:
        return getattr(import_module(f"{__name__}.{_WHERE[name]}"), name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
