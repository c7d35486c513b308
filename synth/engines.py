"""The one engine chooser: ``--engine {auto,explicit,symbolic}`` for ``synth validate``,
``synth sup`` and ``synth filter verify``, above the engines (:mod:`synth.validation`,
:mod:`synth.symbolic`, the filter's closed loop), which know nothing of each other.

Everything that decides is here, in three tables and one function:

- :data:`CAPABILITIES`: what each engine declares it serves, per command. A run's
  :class:`Need` (an option such as ``--report``, or a model whose elements read each other)
  that the asked engine does not declare is refused, with the one message of
  :func:`refusal` (exit 2); with ``auto`` it rules that engine out.
- :data:`THRESHOLDS`: ``auto``'s estimate, per command, above which the symbolic engine runs:

  - ``validate``: plant states × Grafcet steps above 10^5, then *measured* (counts, never
    time): the explicit engine within :data:`PROBE_NODES` aggregated states, else the probe
    (:func:`synth.probe.probe`): symbolic when a breadth-first layer of SYNC holds more than
    :data:`PROBE_LAYER` states within :data:`PROBE_BUDGET` (the explicit engine pays per
    SYNC state, the symbolic one per layer: docs/symbolic.md, "auto");
  - ``sup``: plant states above 10^6;
  - ``filter verify``: plant states above 2·10^6 (the explicit closed loop pays per node it
    explores, the symbolic one per level).
- :func:`decide`: the engine that runs and why (:class:`Decision`).

The runners load each input once and hand the loaded models to the engine chosen:
:func:`validate` and :func:`supervisor` here, ``filter verify`` in
:func:`synth.filter.loop.verify.verify` (the filter lies above this module, so the
filter's runner calls the chooser, not the other way round). The engines themselves are
imported only once chosen: a passing box-sorting validation never imports the BDD library.

Example
-------
>>> from synth.probe import Growth, Stop
>>> decide(Command.VALIDATE, EngineChoice.AUTO, estimate=10**8,
...        growth=lambda threshold: Growth((1, 16, 5, 18, 42, 71, 87, 78), Stop.DONE)).reason
'auto: explicit (measured: SYNC has 318 states, its widest breadth-first layer 87, not above 250)'
>>> decide(Command.VALIDATE, EngineChoice.AUTO, estimate=10**4).reason
'auto: 10000 plant states × Grafcet steps, not above 100000'
>>> decide(Command.VALIDATE, EngineChoice.AUTO, {Need.LISTING}, estimate=10**8).reason
'auto: the symbolic engine does not serve listing'
"""

from __future__ import annotations

from dataclasses import dataclass
from enum import StrEnum
from pathlib import Path
from typing import TYPE_CHECKING, Callable, Collection, Sequence

from synth.choices import EngineChoice
from synth.errors import InputError, LimitExceeded, Location, SynthError

if TYPE_CHECKING:  # pragma: no cover - the engines are imported once chosen
    from synth.grafcet.language import Grafcet, Semantics
    from synth.plant.composition import Plant
    from synth.plant.rules import RuleSet
    from synth.probe import Growth
    from synth.sup.explain import Explanation
    from synth.sup.supervisor import Supervisor
    from synth.symbolic.supervisor import SymbolicSupervisor
    from synth.validation.result import Validation

__all__ = ["EngineChoice", "Command", "Need", "Capability", "CAPABILITIES", "Threshold", "THRESHOLDS", "Decision",
           "capability", "refuse", "refusal", "decide", "measured", "VALIDATE_THRESHOLD", "PROBE_LAYER",
           "PROBE_BUDGET", "PROBE_NODES", "PROBE_STEEP", "SUP_THRESHOLD", "VERIFY_THRESHOLD", "validate",
           "validate_models", "SupRun", "supervisor"]


class Command(StrEnum):
    """The commands that have two engines."""

    VALIDATE = "validate"
    SUP = "sup"
    FILTER_VERIFY = "filter verify"


class Need(StrEnum):
    """What one run asks of the engine that serves it."""

    LISTING = "listing"  # validate --report/--cor, sup --export/--why: every state, listed
    READS = "reads"  # the plant's elements read each other's variables (`reads`)
    SFC = "sfc"  # validate --semantics sfc: one evolution per PLC scan
    CONTROLLER = "controller"  # filter verify --grafcet/--control: a controller in the loop
    PROGRESS = "progress"  # filter verify --progress: fair cycles, on the whole product


@dataclass(frozen=True)
class Capability:
    """One engine's declaration for one command: the needs it serves."""

    command: Command
    engine: EngineChoice
    serves: frozenset[Need]


_EVERY_NEED = frozenset(Need)

CAPABILITIES: tuple[Capability, ...] = (
    Capability(Command.VALIDATE, EngineChoice.EXPLICIT, _EVERY_NEED),
    Capability(Command.VALIDATE, EngineChoice.SYMBOLIC, frozenset()),
    Capability(Command.SUP, EngineChoice.EXPLICIT, _EVERY_NEED),
    Capability(Command.SUP, EngineChoice.SYMBOLIC, frozenset()),
    Capability(Command.FILTER_VERIFY, EngineChoice.EXPLICIT, _EVERY_NEED),
    Capability(Command.FILTER_VERIFY, EngineChoice.SYMBOLIC, frozenset({Need.READS})),
)
"""Every engine of every command, and the needs it serves: the explicit engines every one;
the symbolic ones the plain run, and the closed loop's a plant whose elements read each
other (its cycle encodes their guards)."""


@dataclass(frozen=True)
class Threshold:
    """``auto`` runs the symbolic engine when the estimate exceeds ``size``; where ``layer``
    is set (``validate``), only when the explicit engine does not end within ``nodes``
    aggregated states and the probe, given ``budget`` SYNC states, meets a breadth-first
    layer of more than ``layer`` SYNC states (within ``steep`` of them when the symbolic
    engine would explore one stable situation at a time)."""

    size: int
    estimate: str = "plant states"
    layer: int = 0
    budget: int = 0
    nodes: int = 0
    steep: int = 0


VALIDATE_THRESHOLD = 10**5
"""``validate --engine auto``: symbolic only when plant states × Grafcet steps exceed this
(below, the explicit engine without a probe)."""

PROBE_LAYER = 250
"""``validate --engine auto``: symbolic when a breadth-first layer of SYNC holds more than
this many SYNC states. Where the explicit engine pays about as much for a layer as the
symbolic one: measured with this explicit engine's cost per SYNC state (about 100 µs); an
explicit engine k times faster per state moves it about k times up."""

PROBE_NODES = 100
"""``validate --engine auto``: the explicit engine runs first within this many aggregated
states (the box-sorting Grafcets' SYNC: 30 to 90; the lines of bench/gen_line.py: 32 at 8
cylinders, 48 at 12); when it ends there its result is the one kept and nothing else runs.
It scales with :data:`PROBE_LAYER` (about 15 to 40 ms of this explicit engine's time)."""

PROBE_STEEP = 800
"""``validate --engine auto``: where the symbolic engine would explore one stable situation
at a time (timers, stored actions, …), it pays per situation and wins only where SYNC grows
steeply: the first layer above :data:`PROBE_LAYER` within this many SYNC states."""

PROBE_BUDGET = 1300
"""``validate --engine auto``: the SYNC states the probe explores at most, about 0.1 s of
the explicit engine's time. Large enough to meet the first layer above :data:`PROBE_LAYER`
on every bench family that has one (branches × sequence: after 1 006 to 1 253 states), small
enough that a probe that ends in the explicit engine costs it little; it scales with
:data:`PROBE_LAYER`."""

SUP_THRESHOLD = 10**6
"""``sup --engine auto``: symbolic when the plant has more states than this."""

VERIFY_THRESHOLD = 2_000_000
"""``filter verify --engine auto``: symbolic when the plant has more states than this."""

THRESHOLDS: dict[Command, Threshold] = {
    Command.VALIDATE: Threshold(VALIDATE_THRESHOLD, "plant states × Grafcet steps", PROBE_LAYER, PROBE_BUDGET,
                                PROBE_NODES, PROBE_STEEP),
    Command.SUP: Threshold(SUP_THRESHOLD),
    Command.FILTER_VERIFY: Threshold(VERIFY_THRESHOLD),
}


@dataclass(frozen=True)
class Decision:
    """The engine that runs, and why."""

    engine: EngineChoice
    reason: str
    measured: bool = False  # ``auto`` ran the probe (:mod:`synth.probe`): the reason gives its counts


def capability(command: Command, engine: EngineChoice) -> Capability:
    """The declaration of ``engine`` for ``command`` in :data:`CAPABILITIES`."""
    return next(c for c in CAPABILITIES if c.command is command and c.engine is engine)


_LISTING_OPTIONS = {Command.VALIDATE: "--report/--cor", Command.SUP: "--export/--why"}


def refusal(command: Command, need: Need, readers: Sequence[str] = (), reads_at: Location | None = None) -> SynthError:
    """The error of an engine asked for a run it does not serve (``readers``: the elements
    that read others, for :attr:`Need.READS`, located at ``reads_at``, their first ``reads``)."""
    if need is Need.LISTING:
        return SynthError(f"{_LISTING_OPTIONS[command]} lists every state: use --engine explicit (or auto)")
    if need is Need.READS:
        what = f"the symbolic engine does not support elements that read other elements' variables (`reads` in {', '.join(readers)})"
        if reads_at is not None:
            return InputError(what, reads_at, notes=("use --engine explicit",))
        return SynthError(f"{what}; use --engine explicit")
    if need is Need.SFC:
        return SynthError("--semantics sfc runs on the explicit engine: use --engine explicit (or auto)")
    what = "--progress" if need is Need.PROGRESS else "--grafcet and --control"
    return InputError(f"the symbolic engine of filter verify supports --any-control only, without --progress "
                      f"({what} need --engine explicit)", None)


def refuse(command: Command, asked: EngineChoice | str, needs: Collection[Need], readers: Sequence[str] = (),
           reads_at: Location | None = None) -> None:
    """Raise :func:`refusal` when the engine asked (not ``auto``) does not serve one of
    ``needs`` (the first in :class:`Need`'s order). The runners call it with the options
    before any input is read, :func:`decide` with the model's needs too."""
    asked = EngineChoice(asked)
    if asked is EngineChoice.AUTO:
        return
    missing = [n for n in Need if n in needs and n not in capability(command, asked).serves]
    if missing:
        raise refusal(command, missing[0], readers, reads_at)


def decide(command: Command, asked: EngineChoice | str, needs: Collection[Need] = (), *, estimate: int = 0,
           growth: Callable[[Threshold], Growth] | None = None, readers: Sequence[str] = (),
           reads_at: Location | None = None) -> Decision:
    """The engine that runs ``command`` asked with ``--engine asked`` for a run with
    ``needs`` (:attr:`Need.READS` added when ``readers`` is not empty), ``auto``'s
    ``estimate`` and, where the threshold has a ``layer``, ``growth(threshold)``: what the
    bounded explicit run or the probe measured, asked for only when the estimate is above
    the threshold's size (see the module docstring; without ``growth``, the estimate alone)."""
    asked = EngineChoice(asked)
    needs = set(needs) | ({Need.READS} if readers else set())
    refuse(command, asked, needs, readers, reads_at)
    if asked is not EngineChoice.AUTO:
        return Decision(asked, f"--engine {asked}")
    unserved = sorted(n for n in needs if n not in capability(command, EngineChoice.SYMBOLIC).serves)
    if unserved:
        return Decision(EngineChoice.EXPLICIT, f"auto: the symbolic engine does not serve {', '.join(unserved)}")
    t = THRESHOLDS[command]
    if estimate <= t.size:
        return Decision(EngineChoice.EXPLICIT, f"auto: {estimate} {t.estimate}, not above {t.size}")
    if t.layer and growth is not None:
        return measured(growth(t), t)
    return Decision(EngineChoice.SYMBOLIC, f"auto: {estimate} {t.estimate}, above {t.size}")


def measured(g: Growth, t: Threshold) -> Decision:
    """``validate``'s engine from the counts measured (:class:`~synth.probe.Growth`) and the
    threshold ``t``.

    >>> from synth.probe import Growth, Stop
    >>> t = THRESHOLDS[Command.VALIDATE]
    >>> measured(Growth((1, 64, 7, 33, 107, 261), Stop.WIDE), t).reason
    'auto: symbolic (measured: breadth-first layer 5 of SYNC holds more than 250 states, after 473 states)'
    >>> measured(Growth((1, 5, 5, 13, 19, 40, 50, 52, 77, 118, 166, 209, 198, 170), Stop.BUDGET), t).reason
    'auto: explicit (measured: 1123 SYNC states in 14 breadth-first layers, none above 250)'
    >>> measured(Growth((150,), Stop.RAN), t).reason
    'auto: explicit (measured: SYNC explored whole within 100 aggregated states, 150 SYNC states)'
    """
    from synth.probe import Stop

    layer = t.layer
    if g.stop is Stop.RAN:
        return Decision(EngineChoice.EXPLICIT, f"auto: explicit (measured: SYNC explored whole within {t.nodes} "
                                               f"aggregated states, {g.states} SYNC states)", True)

    if g.stop is Stop.WIDE and g.per_situation:
        return Decision(EngineChoice.EXPLICIT, f"auto: explicit (measured: breadth-first layer {len(g.layers) - 1} "
                                               f"of SYNC holds more than {layer} states after {g.states} states, not "
                                               f"within {t.steep} as exploring per stable situation needs)", True)
    if g.stop is Stop.WIDE:
        return Decision(EngineChoice.SYMBOLIC, f"auto: symbolic (measured: breadth-first layer {len(g.layers) - 1} of "
                                               f"SYNC holds more than {layer} states, after {g.states} states)", True)
    if g.stop is Stop.DONE:
        return Decision(EngineChoice.EXPLICIT, f"auto: explicit (measured: SYNC has {g.states} states, its widest "
                                               f"breadth-first layer {g.widest}, not above {layer})", True)
    if g.stop is Stop.ERROR:
        return Decision(EngineChoice.EXPLICIT, f"auto: explicit (measured: an internal variable out of range after "
                                               f"{g.states} SYNC states)", True)
    return Decision(EngineChoice.EXPLICIT, f"auto: explicit (measured: {g.states} SYNC states in {len(g.layers)} "
                                           f"breadth-first layers, none above {layer})", True)


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
    decided: Callable[[Decision], None] | None = None,
) -> Validation:
    """``synth validate``: load, choose the engine, run it. ``needs_listing``: ``--report``
    or ``--cor`` will list every aggregated state (explicit engine only; with ``--engine
    symbolic`` an error before any input is read); ``max_states`` bounds the explicit
    engine, ``max_nodes`` the symbolic one; ``progress`` receives progress lines;
    ``semantics`` ``sfc`` (one evolution per PLC scan) runs on the explicit engine;
    ``decided`` receives the engine chosen and why."""
    from synth.grafcet.language import Semantics
    from synth.validation.result import load_model

    options = {Need.LISTING} if needs_listing else set()
    if Semantics(semantics) is not Semantics.GRAFCET:
        options.add(Need.SFC)
    refuse(Command.VALIDATE, engine, options)
    rs, p, g = load_model(grafcet_path, rules_path, semantics)
    return validate_models(rs, p, g, engine=engine, needs_listing=needs_listing, expert=expert, homes=homes,
                           max_states=max_states, max_nodes=max_nodes, progress=progress, decided=decided)


def validate_models(
    rs: RuleSet,
    p: Plant,
    g: Grafcet,
    *,
    engine: EngineChoice | str = EngineChoice.AUTO,
    needs_listing: bool = False,
    expert: bool = False,
    homes: Sequence[str] = (),
    max_states: int | None = None,
    max_nodes: int | None = None,
    progress: Callable[[str], None] | None = None,
    decided: Callable[[Decision], None] | None = None,
) -> Validation:
    """:func:`validate` on models already loaded (a line's worker compiles each plant once and
    validates many Grafcets against it): the same choice, the same engines."""
    from synth.grafcet.language import Semantics

    options = {Need.LISTING} if needs_listing else set()
    if g.semantics is not Semantics.GRAFCET:
        options.add(Need.SFC)

    from synth.validation.validate import validate_loaded

    ran: list[Validation] = []

    def growth(t: Threshold) -> Growth:
        from synth.probe import measure

        counts, done = measure(rs, p, g, (t.nodes, t.budget, t.layer, t.steep), expert=expert, homes=homes,
                               max_states=max_states)
        ran.extend([done] if done is not None else [])
        return counts

    chosen = decide(Command.VALIDATE, engine, options, estimate=p.size * max(1, len(g.steps)), growth=growth,
                    readers=p.readers, reads_at=p.reads_at)
    if decided is not None:
        decided(chosen)
    if ran and chosen.engine is EngineChoice.EXPLICIT:
        return ran[0]
    if chosen.engine is EngineChoice.SYMBOLIC:
        from synth.grafcet.situation import OutOfRange
        from synth.symbolic.validate import validate_loaded as symbolic

        try:
            return symbolic(rs, p, g, expert=expert, homes=homes, max_nodes=max_nodes, progress=progress)
        except OutOfRange:  # the explicit engine says it with the shortest trace
            validate_loaded(rs, p, g, expert=expert, homes=homes, max_states=max_states)
            raise
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
    chosen = decide(Command.SUP, engine, {Need.LISTING} if needs_listing else (), estimate=p.size, readers=p.readers,
                    reads_at=p.reads_at)
    if chosen.engine is EngineChoice.SYMBOLIC:
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
