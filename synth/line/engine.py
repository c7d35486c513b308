"""The line's one call into :mod:`synth.engines`: validate a Grafcet already loaded against
a plant already compiled (a worker compiles each plant once and validates many Grafcets and
mutants against it).

The engine is chosen as ``synth validate`` chooses it (:func:`synth.engines.choose` on the
same estimate); this is the only place in :mod:`synth.line` that knows how.
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
    from synth.engines import EngineChoice, choose, concurrency
    from synth.grafcet.language import Semantics

    asked = choose(engine, 0, needs_listing=True, listing_option="--validation-reports") if needs_listing \
        else EngineChoice(engine)
    if (p.reads or g.semantics is not Semantics.GRAFCET) and asked == EngineChoice.AUTO:
        asked = EngineChoice.EXPLICIT
    estimate = p.size * max(1, len(g.steps))
    if asked != EngineChoice.EXPLICIT and choose(asked, estimate, width=concurrency(g)) == EngineChoice.SYMBOLIC:
        from synth.symbolic.validate import validate_loaded as symbolic

        return symbolic(rs, p, g, expert=expert, homes=homes)
    from synth.validation.validate import validate_loaded

    return validate_loaded(rs, p, g, expert=expert, homes=homes, max_states=max_states)
