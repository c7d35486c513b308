"""Which engine runs: ``--engine {auto,explicit,symbolic}`` and the ``auto`` rule.

``auto`` estimates the explicit engine's work before running anything:

- ``validate``: the product of the element state counts (the plant's size) times the
  number of Grafcet steps (a stand-in for the situations); symbolic above
  :data:`VALIDATE_THRESHOLD` (10^7). The explicit engine's cost follows the reachable
  SYNC, which this bounds from above; at 10^7 the explicit engine still answers in well
  under a second on sequential machines, and the symbolic engine costs a few tenths of a
  second more at most (see docs/symbolic.md for the measurements behind the choice);
  ``--report`` and ``--cor`` need every aggregated state, so ``auto`` keeps them explicit.
- ``sup``: symbolic above :data:`SUP_THRESHOLD` (10^6) plant states, unless ``--export``
  or ``--why`` ask for the explicit listing.

Example
-------
>>> choose(EngineChoice.AUTO, 10**8)
<EngineChoice.SYMBOLIC: 'symbolic'>
>>> choose(EngineChoice.AUTO, 10**8, needs_listing=True)
<EngineChoice.EXPLICIT: 'explicit'>
"""

from __future__ import annotations

from enum import StrEnum

from synth.errors import SynthError

__all__ = ["EngineChoice", "choose", "VALIDATE_THRESHOLD", "SUP_THRESHOLD"]

VALIDATE_THRESHOLD = 10**7
"""``validate --engine auto``: symbolic when plant states × Grafcet steps exceed this."""

SUP_THRESHOLD = 10**6
"""``sup --engine auto``: symbolic when the plant has more states than this."""


class EngineChoice(StrEnum):
    AUTO = "auto"
    EXPLICIT = "explicit"
    SYMBOLIC = "symbolic"


def choose(asked: EngineChoice | str, estimate: int, *, threshold: int = VALIDATE_THRESHOLD,
           needs_listing: bool = False, listing_option: str = "--report/--cor") -> EngineChoice:
    """The engine to run for an estimated size; ``needs_listing``: an option needs every
    state explicitly (the symbolic engine cannot serve it)."""
    asked = EngineChoice(asked)
    if asked == EngineChoice.AUTO:
        return EngineChoice.EXPLICIT if needs_listing or estimate <= threshold else EngineChoice.SYMBOLIC
    if asked == EngineChoice.SYMBOLIC and needs_listing:
        raise SynthError(f"{listing_option} lists every state: use --engine explicit (or auto)")
    return asked
