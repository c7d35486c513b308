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
    time): the explicit engine runs, watched (:func:`synth.probe.measure`); at
    :data:`PROBE_NODES` aggregated states met it stops for the symbolic engine when more
    than :data:`PROBE_SHARE` percent of them wait to be explored (SYNC grows steeply;
    :data:`PROBE_MACHINE_SHARE` state by state), else goes on, its result kept
    (the explicit engine pays per SYNC state, the symbolic one per layer: docs/symbolic.md,
    "auto");
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
...        growth=lambda threshold: Growth(1167, 395, Stop.STEEP, "input x is not a plant variable", share=30)).reason
'auto: symbolic (measured: 395 of the 1167 aggregated states met wait to be explored, more than 30 %, state by state (input x is not a plant variable))'
>>> decide(Command.VALIDATE, EngineChoice.AUTO, estimate=10**4).reason
'auto: 10000 plant states × Grafcet steps, not above 100000'
>>> decide(Command.VALIDATE, EngineChoice.AUTO, {Need.LISTING}, estimate=10**8).reason
'auto: the symbolic engine does not serve listing'
"""

from __future__ import annotations

from enum import StrEnum
from pathlib import Path
from typing import TYPE_CHECKING, Callable, Collection, Sequence

from synth.choices import EngineChoice
from synth.errors import InputError, LimitExceeded, Location, SynthError
from synth.frozen import frozen
from synth.probe import Points

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
           "capability", "refuse", "refusal", "decide", "measured", "VALIDATE_THRESHOLD", "PROBE_NODES",
           "PROBE_SHARE", "PROBE_MACHINE_SHARE", "PROBE_SITUATION_SHARE", "SUP_THRESHOLD", "VERIFY_THRESHOLD", "validate",
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


@frozen
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


@frozen
class Threshold:
    """``auto`` runs the symbolic engine when the estimate exceeds ``size``; where
    ``points`` is set (``validate``), only when the explicit engine's own run, watched
    (:func:`synth.probe.measure`), finds SYNC growing steeply at its decision point."""

    size: int
    estimate: str = "plant states"
    points: Points | None = None


VALIDATE_THRESHOLD = 10**5
"""``validate --engine auto``: symbolic only when plant states × Grafcet steps exceed this
(below, the explicit engine without a probe)."""

PROBE_NODES = 400
"""``validate --engine auto``: the decision point, the aggregated states the explicit
engine's watched run has met when it is judged: about 0.03 to 0.1 s of that engine's time
on its frontier path (14 to 27 µs per SYNC state), 0.15 s state by state. A SYNC explored
whole before it (the box sorting: 90 aggregated states; a line of 16 cylinders: 64; par_4:
321) is the explicit engine's result, nothing else runs."""

PROBE_SHARE = 45
"""``validate --engine auto``: symbolic when, at the decision point, more than this percent
of the aggregated states met still wait to be expanded (SYNC grows steeply: each layer
about as large as all before it together). Measured there on the bench families: par_7 53,
steep_6 55, par_8 68, par_9 72, par_5/6 with timers 71/76 (symbolic 1.5 to 8 times faster,
whole commands); steep_5 49, par_6 45 (the engines within 1.2 of each other); branches_5x2
38, branches_4x2 30, three timed branches 30, branches_3x3 20, par_5 22 (explicit up to 3
times faster)."""

PROBE_MACHINE_SHARE = 30
"""``validate --engine auto``: :data:`PROBE_SHARE` where the explicit engine explores state
by state (stored actions, internal variables, plants of 2^40 codes or more), about five
times slower per state: the symbolic engine wins sooner (par_6 with an internal variable:
53; par_5 22; branches_3x2 14)."""

PROBE_SITUATION_SHARE = 50
"""``validate --engine auto``: where the symbolic engine would explore one stable situation
at a time (timers, stored actions, internal variables), it pays per situation and wins only
where SYNC grows more steeply still: more than this percent waiting (par_5 and par_6 with a
1 s wait after each extension: 71 and 76; three timed branches 30)."""

SUP_THRESHOLD = 10**6
"""``sup --engine auto``: symbolic when the plant has more states than this."""

VERIFY_THRESHOLD = 2_000_000
"""``filter verify --engine auto``: symbolic when the plant has more states than this."""

THRESHOLDS: dict[Command, Threshold] = {
    Command.VALIDATE: Threshold(VALIDATE_THRESHOLD, "plant states × Grafcet steps",
                                Points(PROBE_NODES, PROBE_SHARE, PROBE_MACHINE_SHARE, PROBE_SITUATION_SHARE)),
    Command.SUP: Threshold(SUP_THRESHOLD),
    Command.FILTER_VERIFY: Threshold(VERIFY_THRESHOLD),
}


@frozen
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
    ``estimate`` and, where the threshold has ``points``, ``growth(threshold)``: what the
    explicit engine's watched run measured, asked for only when the estimate is above
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
    if t.points is not None and growth is not None:
        return measured(growth(t), t)
    return Decision(EngineChoice.SYMBOLIC, f"auto: {estimate} {t.estimate}, above {t.size}")


def measured(g: Growth, t: Threshold) -> Decision:
    """``validate``'s engine from the counts measured (:class:`~synth.probe.Growth`) and the
    threshold ``t``.

    >>> from synth.probe import Growth, Stop
    >>> t = THRESHOLDS[Command.VALIDATE]
    >>> measured(Growth(815, 432, Stop.STEEP, share=45), t).reason
    'auto: symbolic (measured: 432 of the 815 aggregated states met wait to be explored, more than 45 %)'
    >>> measured(Growth(628, 172, Stop.NARROW, share=45), t).reason
    'auto: explicit (measured: 172 of the 628 aggregated states met wait to be explored, not more than 45 %)'
    >>> measured(Growth(90, 0, Stop.RAN, sync_states=150), t).reason
    'auto: explicit (measured: SYNC explored whole before the decision point, 90 aggregated states, 150 SYNC states)'
    """
    from synth.probe import Stop

    pt = t.points
    assert pt is not None
    if g.stop is Stop.RAN:
        return Decision(EngineChoice.EXPLICIT, f"auto: explicit (measured: SYNC explored whole before the decision "
                                               f"point, {g.met} aggregated states, {g.sync_states} SYNC states)", True)
    if g.stop is Stop.ERROR:
        return Decision(EngineChoice.EXPLICIT, f"auto: explicit (measured: an internal variable out of range after "
                                               f"{g.met} aggregated states)", True)
    share = g.share
    counts = f"{g.waiting} of the {g.met} aggregated states met wait to be explored"
    path = "" if g.machine is None else f", state by state ({g.machine})"
    if g.stop is Stop.STEEP:
        return Decision(EngineChoice.SYMBOLIC, f"auto: symbolic (measured: {counts}, more than {share} %{path})", True)
    if g.per_situation:
        return Decision(EngineChoice.EXPLICIT, f"auto: explicit (measured: {counts}, more than {share} % but not more "
                                               f"than {pt.situation_share} % as exploring per stable situation needs"
                                               f"{path})", True)
    return Decision(EngineChoice.EXPLICIT, f"auto: explicit (measured: {counts}, not more than {share} %{path})", True)


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

    from synth.validation.sync import Exploration
    from synth.validation.validate import validate_loaded

    explored = None
    if progress is not None:
        def explored(n: int, pending: int, show: Callable[[str], None] = progress) -> None:
            show(f"exploring SYNC: {n} aggregated states, {pending} to visit")
    how = Exploration(max_states, explored)  # the explicit engine's run, watched or not

    ran: list[Validation] = []

    def growth(t: Threshold) -> Growth:
        from synth.probe import measure

        assert t.points is not None
        counts, done = measure(rs, p, g, t.points, expert=expert, homes=homes, how=how)
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
            validate_loaded(rs, p, g, expert=expert, homes=homes, how=Exploration(max_states))
            raise
    return validate_loaded(rs, p, g, expert=expert, homes=homes, how=how)


@frozen
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
