"""Validation: SUP × ASS (SYNC), its analysis (blocking, traps, traces), diagnosis and the validation result.

The names below are re-exported lazily (on first use), so importing the package costs nothing.
"""

from __future__ import annotations

from importlib import import_module
from typing import Any

_WHERE = {
    "Validation": "validate",
    "validate": "validate",
    "reduced_controller": "validate",
}

__all__ = sorted(_WHERE)


def __getattr__(name: str) -> Any:
    if name in _WHERE:
        return getattr(import_module(f"{__name__}.{_WHERE[name]}"), name)
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
