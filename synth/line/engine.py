"""The line's one call into :mod:`synth.engines`: validate a Grafcet already loaded against
a plant already compiled (a worker compiles each plant once and validates many Grafcets and
mutants against it).

The engine is chosen as ``synth validate`` chooses it (:func:`synth.engines.validate_models`);
this is the only place in :mod:`synth.line` that calls the engines.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Sequence

if TYPE_CHECKING:  # pragma: no cover
    from synth.grafcet.language import Grafcet
    from synth.plant.composition import Plant
    from synth.plant.rules import RuleSet
    from synth.validation.result import Validation

__all__ = ["validate_model"]


def validate_model(rs: RuleSet, p: Plant, g: Grafcet, *, engine: str = "auto", expert: bool = False,
                   homes: Sequence[str] = (), max_states: int | None = None, needs_listing: bool = False) -> Validation:
    """``synth validate`` on a loaded model: the engine chosen by :mod:`synth.engines`
    (``needs_listing``: a full report will list every aggregated state, explicit engine only)."""
    from synth.engines import validate_models

    return validate_models(rs, p, g, engine=engine, needs_listing=needs_listing, expert=expert, homes=homes,
                           max_states=max_states)
