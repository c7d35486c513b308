"""Which engine runs, and running it: ``--engine {auto,explicit,symbolic}`` for
``synth validate`` and ``synth sup``, above both engines (:mod:`synth.validation`,
:mod:`synth.symbolic`), which know nothing of each other.

``auto`` estimates both engines' work before running anything:

- ``validate``: symbolic when the model is large (the product of the element state
  counts times the number of Grafcet steps above :data:`VALIDATE_THRESHOLD`, 10^5) *and*
  the Grafcet moves many actuators at once (:func:`concurrency`, the widest AND
  divergence, at least :data:`CONCURRENCY_THRESHOLD`, 4). Both engines pay per stable
  situation; per situation the explicit engine lists every interleaving of the moving
  elements (about r^D SYNC states for D branches at once, r ≈ 3 for a cylinder), the
  symbolic one builds BDDs whose size grows polynomially in D. Measured
  (docs/performance.md, bench/symbolic.py): at D = 3 the explicit engine is as fast or
  faster on every family (branches × sequence: 2.7× faster), from D = 4 on the symbolic
  one wins (par, steep). ``--report`` and ``--cor`` need every aggregated state, so
  ``auto`` keeps them explicit.
- ``sup``: symbolic above :data:`SUP_THRESHOLD` (10^6) plant states, unless ``--export``
  or ``--why`` ask for the explicit listing.
- a plant whose elements read each other's variables (``reads``) is always explicit:
  the symbolic engine refuses it.

The engines themselves are imported only once chosen: a passing box-sorting
validation never imports the BDD library.

Example
-------
>>> choose(EngineChoice.AUTO, 10**8)
<EngineChoice.SYMBOLIC: 'symbolic'>
>>> choose(EngineChoice.AUTO, 10**8, width=3)
<EngineChoice.EXPLICIT: 'explicit'>
>>> choose(EngineChoice.AUTO, 10**8, needs_listing=True)
<EngineChoice.EXPLICIT: 'explicit'>
"""

from __future__ import annotations

from dataclasses import dataclass
from enum import StrEnum
from pathlib import Path
from typing import TYPE_CHECKING, Any, Callable, Sequence

from synth.errors import LimitExceeded, SynthError

if TYPE_CHECKING:  # pragma: no cover - the engines are imported once chosen
    from synth.grafcet.language import Grafcet, Semantics
    from synth.plant.composition import Plant
    from synth.plant.rules import RuleSet
    from synth.sup.explain import Explanation
    from synth.sup.supervisor import Supervisor
    from synth.symbolic.supervisor import SymbolicSupervisor
    from synth.validation.result import Validation

__all__ = ["EngineChoice", "choose", "concurrency", "VALIDATE_THRESHOLD", "CONCURRENCY_THRESHOLD", "SUP_THRESHOLD",
           "validate", "SupRun", "supervisor"]

VALIDATE_THRESHOLD = 10**5
"""``validate --engine auto``: symbolic only when plant states × Grafcet steps exceed this."""

CONCURRENCY_THRESHOLD = 4
"""``validate --engine auto``: symbolic only when the Grafcet starts this many branches at once."""

SUP_THRESHOLD = 10**6
"""``sup --engine auto``: symbolic when the plant has more states than this."""


class EngineChoice(StrEnum):
    AUTO = "auto"
    EXPLICIT = "explicit"
    SYMBOLIC = "symbolic"


def concurrency(g: Grafcet) -> int:
    """The widest AND divergence of ``g``: the most steps one transition activates (1
    for a sequence), the number of branches that can move actuators at once.

    >>> from synth.grafcet.language_check import load_grafcet
    >>> from synth.plant.composition import _plants
    >>> concurrency(load_grafcet(_plants("../grafcets/tri.g7")))
    1
    """
    return max((len(t.targets) for t in g.transitions), default=1)


def choose(asked: EngineChoice | str, estimate: int, *, threshold: int = VALIDATE_THRESHOLD,
           width: int = CONCURRENCY_THRESHOLD, needs_listing: bool = False,
           listing_option: str = "--report/--cor") -> EngineChoice:
    """The engine to run for an estimated size and concurrency ``width`` (see module
    docstring; ``sup`` passes no width); ``needs_listing``: an option needs every state
    explicitly (the symbolic engine cannot serve it)."""
    asked = EngineChoice(asked)
    if asked == EngineChoice.AUTO:
        small = estimate <= threshold or width < CONCURRENCY_THRESHOLD
        return EngineChoice.EXPLICIT if needs_listing or small else EngineChoice.SYMBOLIC
    if asked == EngineChoice.SYMBOLIC and needs_listing:
        raise SynthError(f"{listing_option} lists every state: use --engine explicit (or auto)")
    return asked


def validate(
    grafcet_path: str | Path,
    rules_path: str | Path,
    *,
    engine: EngineChoice | str = EngineChoice.AUTO,
    needs_listing: bool = False,
    expert: bool = False,
    homes: Sequence[str] = (),
    max_states: int | None = None,
    max_nodes: int | None = None,
    progress: Callable[[str], None] | None = None,
    semantics: "Semantics | str" = "grafcet",
) -> Validation:
    """``synth validate``: load, choose the engine, run it. ``needs_listing``: ``--report``
    or ``--cor`` will list every aggregated state (explicit engine only; with ``--engine
    symbolic`` an error before any input is read); ``max_states`` bounds the explicit
    engine, ``max_nodes`` the symbolic one; ``progress`` receives progress lines;
    ``semantics`` ``sfc`` (one evolution per PLC scan) runs on the explicit engine."""
    from synth.grafcet.language import Semantics
    from synth.validation.result import load_model

    asked = choose(engine, 0, needs_listing=True) if needs_listing else EngineChoice(engine)
    rs, p, g = load_model(grafcet_path, rules_path, semantics)
    estimate = p.size * max(1, len(g.steps))
    if (p.reads or g.semantics is not Semantics.GRAFCET) and asked == EngineChoice.AUTO:  # explicit engine only
        asked = EngineChoice.EXPLICIT
    if asked != EngineChoice.EXPLICIT and choose(asked, estimate, width=concurrency(g)) == EngineChoice.SYMBOLIC:
        from synth.grafcet.situation import OutOfRange
        from synth.symbolic.validate import validate_loaded as symbolic

        try:
            return symbolic(rs, p, g, expert=expert, homes=homes, max_nodes=max_nodes, progress=progress)
        except OutOfRange:  # the explicit engine says it with the shortest trace
            from synth.validation.validate import validate_loaded as explicit

            explicit(rs, p, g, expert=expert, homes=homes, max_states=max_states)
            raise
    from synth.validation.validate import validate_loaded

    explored = None
    if progress is not None:
        def explored(n: int, pending: int, show: Callable[[str], None] = progress) -> None:
            show(f"exploring SYNC: {n} aggregated states, {pending} to visit")

    return validate_loaded(rs, p, g, expert=expert, homes=homes, max_states=max_states, progress=explored)


@dataclass(frozen=True)
class SupRun:
    """One run of ``synth sup``: the rule set, its plant, and SUP from the engine chosen
    (a :class:`~synth.sup.supervisor.Supervisor` listing its states, or a
    :class:`~synth.symbolic.supervisor.SymbolicSupervisor` with counts only)."""

    path: str
    rules: RuleSet
    plant: Plant
    sup: Supervisor | SymbolicSupervisor

    @property
    def bdd_nodes(self) -> int | None:
        """The symbolic engine's BDD node count; None when the explicit engine ran."""
        from synth.sup.supervisor import Supervisor

        return None if isinstance(self.sup, Supervisor) else self.sup.nodes

    def listed(self) -> Supervisor:
        """SUP with its states listed, for ``--export``: the explicit engine's
        (``needs_listing`` chose it)."""
        from synth.sup.supervisor import Supervisor

        if not isinstance(self.sup, Supervisor):
            raise SynthError("the symbolic engine lists no state: use --engine explicit")
        return self.sup

    @property
    def labels(self) -> dict[str, str]:
        return {c.id: c.label for c in self.rules.constraints}

    def why(self, state: str | None = None) -> Explanation:
        """Why ``state`` (its true variables; default the initial state) is in SUP or not."""
        from synth.sup.explain import explain
        from synth.sup.supervisor import Supervisor

        sup = self.sup if isinstance(self.sup, Supervisor) else Supervisor(self.plant, self.rules.constraints)
        return explain(sup, self.plant.initial if state is None else self.plant.parse_state(state))


def supervisor(
    rules_path: str | Path,
    *,
    engine: EngineChoice | str = EngineChoice.AUTO,
    needs_listing: bool = False,
    max_states: int | None = None,
    max_nodes: int | None = None,
    progress: Callable[[str], None] | None = None,
    loaded: Callable[[Plant], None] | None = None,
) -> SupRun:
    """``synth sup``: load, choose the engine, run it. ``needs_listing``: ``--export`` or
    ``--why`` will list states (explicit engine only); ``max_states`` refuses larger
    plants in the explicit engine; ``loaded(plant)`` is called once the plant is built,
    before anything can fail on its size (the CLI prints the plant's warnings)."""
    from synth.plant.composition import plant
    from synth.plant.rules_check import load_rules

    rs = load_rules(rules_path)
    p = plant(rs)
    if loaded is not None:
        loaded(p)
    chosen = choose(engine, p.size, threshold=SUP_THRESHOLD, needs_listing=needs_listing, listing_option="--export/--why")
    if p.reads and EngineChoice(engine) == EngineChoice.AUTO:  # elements read each other: explicit engine only
        chosen = EngineChoice.EXPLICIT
    if chosen == EngineChoice.SYMBOLIC:
        from synth.symbolic.encoding import NodeBudget
        from synth.symbolic.supervisor import symbolic_supervisor

        return SupRun(str(rules_path), rs, p, symbolic_supervisor(p, rs.constraints, budget=NodeBudget(max_nodes),
                                                                  progress=progress))
    if max_states is not None and p.size > max_states:
        raise LimitExceeded(
            f"the plant of {rules_path} has {p.size} states, more than --max-states {max_states}; "
            "the explicit exploration lists every SUP state. Raise --max-states, use --engine symbolic "
            "(counts on BDDs, any size), or validate a Grafcet with `synth validate`"
        )
    from synth.sup.supervisor import supremal_controllable

    return SupRun(str(rules_path), rs, p, supremal_controllable(p, rs.constraints, progress=progress))
