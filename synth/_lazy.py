"""Lazy re-exports for package ``__init__`` files (PEP 562): ``from synth.plant import Plant``
works, yet importing a package costs nothing until a name is used.

Example
-------
>>> getattr_, names = lazy_exports("synth.logic", {"Var": "expr"})
>>> names, getattr_("Var").__name__
(['Var'], 'Var')
"""

from __future__ import annotations

from importlib import import_module
from typing import Any, Callable, Mapping

__all__ = ["lazy_exports"]


def lazy_exports(package: str, where: Mapping[str, str]) -> tuple[Callable[[str], Any], list[str]]:
    """A module ``__getattr__`` that imports ``package.<where[name]>`` on first use of
    ``name``, and the sorted ``__all__``."""

    def __getattr__(name: str) -> Any:
        if name in where:
            return getattr(import_module(f"{package}.{where[name]}"), name)
        raise AttributeError(f"module {package!r} has no attribute {name!r}")

    return __getattr__, sorted(where)
