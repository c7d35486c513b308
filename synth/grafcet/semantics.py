"""Where IEC 60848 (search for stability) and IEC 61131-3 SFC (one evolution per scan) read one
Grafcet differently: the steps a PLC keeps active for a scan that IEC 60848 only passes through.

``synth import`` says so after reading a PLC program, so that it is validated with the meaning
it has on the PLC (``--semantics sfc``).

Example
-------
>>> from synth.grafcet.language_check import parse_grafcet
>>> g = parse_grafcet("grafcet G { initial step 1 step 2: A step 3: B "
...                   "transition 1 -> 2 when ↑go transition 2 -> 3 when 1 transition 3 -> 1 when !go }")
>>> scan_only_steps(g)
('2',)
"""

from __future__ import annotations

from dataclasses import replace

from synth.errors import InputError
from synth.grafcet.ass import stable_situations
from synth.grafcet.language import Grafcet, Semantics, step_key
from synth.grafcet.machine import GrafcetMachine

__all__ = ["IMPORT_BUDGET", "IMPORT_REACTIONS", "scan_only_steps"]


IMPORT_BUDGET = 2_000
"""Situations each reading may explore for ``synth import``'s note: a note, not a verdict, so
it stays well under a second on a chart of 200 steps and says so when it is not computed."""


IMPORT_REACTIONS = 8_000
"""Runs of the machine each reading may make for that note (about a CPU second): many inputs
and partial grafcets (the blocks of a Beremiz chart) make each situation costly."""


def scan_only_steps(g: Grafcet, max_states: int = IMPORT_BUDGET,
                    max_reactions: int = IMPORT_REACTIONS) -> tuple[str, ...] | None:
    """The steps active in some situation of the SFC reading and in no stable situation of the
    IEC 60848 one (inputs free); None when the Grafcet never stabilises in IEC 60848.
    :class:`~synth.errors.LimitExceeded` when either reading has more than ``max_states``
    situations or needs more than ``max_reactions`` runs of the machine."""
    try:
        stable = stable_situations(GrafcetMachine(replace(g, semantics=Semantics.GRAFCET)), max_states=max_states,
                                   max_reactions=max_reactions)
        scans = stable_situations(GrafcetMachine(replace(g, semantics=Semantics.SFC)), max_states=max_states,
                                  max_reactions=max_reactions)
    except InputError:
        return None
    seen = {s for sit in stable for s in sit.steps}
    return tuple(sorted({s for sit in scans for s in sit.steps} - seen, key=step_key))
