"""Selection divergences of an imported SFC: IEC 61131-3 tests the branches in priority order
(TC6's ``priority`` attribute, the smallest first, then left to right) and fires the first true
one, where a ``.g7`` fires every true branch; so the later branches' receptivities are made
exclusive, with a located warning that lists them and names MATIEC's own rule.
"""

from __future__ import annotations

from typing import Any

from synth.errors import InputError, Severity

__all__ = ["MATIEC_DIVERGENCE", "NO_PRIORITY", "priority", "exclusive_branches"]


MATIEC_DIVERGENCE = ("on MATIEC (the compiler of Beremiz and OpenPLC) every true branch fires, priorities ignored: "
                     "for a program that runs there, validate the receptivities as written, without this rewrite")
"""The runtime that reads a selection divergence otherwise than IEC 61131-3 (measured: two
tokens after a divergence whose branches were both true)."""

NO_PRIORITY = 2 ** 63
"""The rank of a transition without a ``priority`` attribute: after every written one."""


def priority(el: Any, src: Any) -> int:
    """The ``priority`` attribute of an SFC ``<transition>`` (TC6: the smaller, the earlier a
    selection divergence tests it), :data:`NO_PRIORITY` when absent; anything else than a
    non-negative integer is a located error."""
    text = el.get("priority")
    if text is None:
        return NO_PRIORITY
    if not text.strip().isdigit() or len(text.strip()) > 18:
        raise InputError(f"transition priority '{text[:40]}' is not a non-negative integer", src.at(el))
    return int(text)


def exclusive_branches(branches: dict[int, list[tuple[tuple[int, int, int], int]]], transitions: list,
                       elements: dict[int, Any], src: Any) -> list[InputError]:
    """Rewrite ``transitions`` (label, sources, targets, receptivity, element) so that each
    divergence of ``branches`` (its element id -> (rank key, transition index)) fires its
    first true branch only; one warning per divergence rewritten."""
    warnings = []
    for d, members in branches.items():  # IEC 61131-3: the first true branch, left to right; .g7: every one
        if len(members) < 2:
            continue
        ranked = [i for _, i in sorted(members)]
        prioritised = any(key[0] < NO_PRIORITY for key, _ in members)
        rewritten = []
        written = [transitions[i][3] for i in ranked]  # each branch excludes the earlier ones as written:
        for k, i in enumerate(ranked[1:], 1):         # their own rewrites would add nothing, and double at each
            label, sources, targets, expr, el = transitions[i]
            before = " & ".join(f"!({e})" for e in written[:k])
            transitions[i] = (label, sources, targets, f"({expr}) & {before}", el)
            rewritten.append(f"{' -> '.join([', '.join(sources), ', '.join(targets)])} when {transitions[i][3]}")
        rule = ("the true branch of highest priority (smallest `priority`, then left to right)" if prioritised
                 else "the first true branch (left to right)")
        warnings.append(InputError(
            f"a selection divergence: IEC 61131-3 SFC fires {rule}, .g7 every true "
            "branch; the later branches' receptivities are made exclusive", src.at(elements[d]),
            severity=Severity.WARNING, notes=(*rewritten, MATIEC_DIVERGENCE)))
    return warnings
