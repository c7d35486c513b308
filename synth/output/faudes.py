"""Export to libFAUDES ``.gen`` files (a ``System``: controllable events flagged ``+C+``).

libFAUDES symbols must be ASCII, so ``↑X`` is written ``X_up`` and ``↓X`` ``X_down``.
All states are marked: SUP is a closed-behaviour notion and language comparisons
(``faudes.LanguageEquality``) then compare prefix-closed languages.

Example
-------
>>> from synth.plant.rules_check import load_rules
>>> from synth.plant.composition import plant, _plants
>>> text = plant_generator(plant(load_rules(_plants("tri_annex.rules"))), "tri")
>>> text.splitlines()[0], "+C+" in text
('<Generator>', True)
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Mapping

from synth.logic.events import Event

import numpy as np

from synth.plant.composition import Plant
from synth.plant.element import ElementAutomaton

if TYPE_CHECKING:
    from synth.sup.supervisor import Supervisor

__all__ = ["faudes_event", "generator_text", "plant_generator", "supervisor_generator", "element_generator"]


def faudes_event(event: Event) -> str:
    """``↑AVANCER1`` → ``AVANCER1_up``; ``↓v10`` → ``v10_down``."""
    return event.name + ("_up" if event.rising else "_down")


def generator_text(
    name: str,
    n_states: int,
    initial: int | None,
    events: Mapping[Event, bool],
    src: np.ndarray,
    ev: np.ndarray,
    dst: np.ndarray,
) -> str:
    """A ``.gen`` System; states are 1..n_states, ``ev`` indexes ``sorted(events)``."""
    names = list(events)
    alphabet = " ".join(f'"{faudes_event(e)}"' + (" +C+" if events[e] else "") for e in names)
    order = np.lexsort((dst, ev, src))
    quoted = [f'"{faudes_event(e)}"' for e in names]
    lines = [f"{s} {quoted[q]} {d}" for s, q, d in zip((src[order] + 1).tolist(), ev[order].tolist(), (dst[order] + 1).tolist())]
    states = "\n".join(str(i) for i in range(1, n_states + 1))
    return (
        f'<Generator>\n"{name}"\n<Alphabet>\n{alphabet}\n</Alphabet>\n<States>\n{states}\n</States>\n'
        f"<TransRel>\n" + "\n".join(lines) + f"\n</TransRel>\n<InitStates>\n{initial + 1 if initial is not None else ''}\n</InitStates>\n"
        f"<MarkedStates>\n{states}\n</MarkedStates>\n</Generator>\n"
    )


def _grid_generator(p: Plant, name: str, keep: np.ndarray, allowed) -> str:
    number = np.cumsum(keep.ravel()) - 1
    events = p.events
    ev_index = {e: i for i, e in enumerate(events)}
    src_all, ev_all, dst_all = [], [], []
    flat = np.arange(p.size, dtype=np.int64).reshape(p.shape)
    for t in p.transitions:
        s, d = p.slices(t)
        ok = allowed(t)
        srcs = flat[s][ok]
        dsts = flat[d][ok]
        src_all.append(number[srcs])
        dst_all.append(number[dsts])
        ev_all.append(np.full(srcs.size, ev_index[t.event], dtype=np.int64))
    cat = lambda xs: np.concatenate(xs) if xs else np.zeros(0, dtype=np.int64)  # noqa: E731
    n = int(np.count_nonzero(keep))
    init = int(number[p.initial_index]) if keep[p.initial] else None
    return generator_text(name, n, init, events, cat(src_all), cat(ev_all), cat(dst_all))


def plant_generator(p: Plant, name: str = "plant") -> str:
    """The whole plant: its reachable states (every grid state unless elements read each
    other) and the transitions enabled there."""
    keep = p.reachable
    return _grid_generator(p, name, keep, lambda t: keep[p.slices(t)[0]] & p.guard_grid(t))


def supervisor_generator(sup: "Supervisor", name: str = "sup") -> str:
    """SUP: its states and the transitions it keeps (no plant-sized array is built)."""
    events = sup.plant.events
    ev_index = {e: i for i, e in enumerate(events)}
    src_all, ev_all, dst_all = [], [], []
    for t, src, dst, ok in sup.moves(sup.states):
        src_all.append(np.searchsorted(sup.states, src[ok]))
        dst_all.append(np.searchsorted(sup.states, dst[ok]))
        ev_all.append(np.full(int(np.count_nonzero(ok)), ev_index[t.event], dtype=np.int64))
    cat = lambda xs: np.concatenate(xs) if xs else np.zeros(0, dtype=np.int64)  # noqa: E731
    init = int(np.searchsorted(sup.states, sup.plant.initial_index)) if sup.size else None
    return generator_text(name, sup.size, init, events, cat(src_all), cat(ev_all), cat(dst_all))


def element_generator(a: ElementAutomaton, name: str | None = None) -> str:
    """One element automaton."""
    evs = a.events()
    events = dict(sorted({e: bool(c) for e, c in zip(evs, a.controllable)}.items()))
    idx = {e: i for i, e in enumerate(events)}
    ev = np.array([idx[e] for e in evs], dtype=np.int64)
    return generator_text(name or a.name, a.size, a.initial, events, a.src, ev, a.dst)
