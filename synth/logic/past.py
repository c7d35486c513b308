"""Previous-cycle names: the value of ``x`` at the previous PLC cycle is the variable ``x^-1``.

Every language that speaks of the past (the filter's ``x^-1`` and ``pre(x)``, the edges
``↑x = !x^-1 & x``) and every writer that stores it (the ST variable ``x_1``) names it here.

Example
-------
>>> pre_name("A2"), base_name("A2^-1"), is_pre("A2"), st_past_name("A2^-1")
('A2^-1', 'A2', False, 'A2_1')
"""

from __future__ import annotations

__all__ = ["PRE_SUFFIX", "ST_PAST_SUFFIX", "pre_name", "base_name", "is_pre", "st_past_name"]

PRE_SUFFIX = "^-1"
ST_PAST_SUFFIX = "_1"


def pre_name(name: str) -> str:
    """The variable holding ``name`` at the previous cycle."""
    return name + PRE_SUFFIX


def is_pre(name: str) -> bool:
    """Whether ``name`` is a previous-cycle value ``x^-1``."""
    return name.endswith(PRE_SUFFIX)


def base_name(name: str) -> str:
    """``x`` for ``x^-1``, ``name`` itself otherwise."""
    return name[: -len(PRE_SUFFIX)] if is_pre(name) else name


def st_past_name(name: str) -> str:
    """The IEC 61131-3 variable of a name as synth writes it: ``x^-1`` is ``x_1``."""
    return base_name(name) + ST_PAST_SUFFIX if is_pre(name) else name
