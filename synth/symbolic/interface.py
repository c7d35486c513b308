"""What both symbolic SYNC representations offer the searches and the report: one interface.

The symbolic engine explores SYNC in one of two representations (the choice:
:func:`synth.symbolic.validate.choose_path`):

- *per situation* (:class:`~synth.symbolic.situations.reach.SituationReach` over
  :class:`~synth.symbolic.situations.sync.SymbolicSync`): a set of nodes is a BDD of plant
  states per stable situation (``dict[int, Function]``), a move a *bundle* of edges
  between two situations;
- *steps in the BDD* (:class:`~synth.symbolic.steps.reach.StepReach` over
  :class:`~synth.symbolic.steps.sync.StepSync`): a set of nodes is one BDD over (active
  steps, plant state), a move a plant move with its edge relation.

:class:`SymbolicGraph` names what both offer: node-set algebra, the onion rings,
pre- and post-images per move in the explicit exploration's order, forward and
backward fixpoints, held nodes, one node picked from a set and made a set again, and
the situations' numbering. The searches (:mod:`synth.symbolic.searches`) and the
recipe "explored SYNC → :class:`~synth.validation.result.Validation`"
(:mod:`synth.symbolic.verdicts`) are written once above it.

Example
-------
>>> from synth.logic.events import Event
>>> path = Path(((0, (0, 4)), (1, (1, 4))), (Event.rise("dcy"),))  # node (situation 0, state (0, 4)) --↑dcy--> …
>>> len(path.nodes) == len(path.events) + 1
True
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Collection, Iterable, Protocol, Sequence, TypeVar

from synth.grafcet.machine import GrafcetMachine, Situation
from synth.logic.events import Event
from synth.logic.expr import Expr
from synth.plant.composition import Plant
from synth.symbolic.relation import Move

__all__ = ["Key", "PathKey", "Local", "Path", "Numbered", "SymbolicGraph", "Finder", "Steps", "S", "M"]

Local = tuple[int, ...]  # a plant state: element-local codes
Key = tuple[int, Local]  # a node: situation index, plant state
PathKey = tuple[tuple[int, ...], ...]  # a shortest path, in the explicit exploration's order (with ranks: synth.symbolic.ties)
Steps = tuple[str, ...]  # a situation's active steps

S = TypeVar("S")  # a set of nodes
M = TypeVar("M")  # a move: edges of one event
S_contra = TypeVar("S_contra", contravariant=True)


@dataclass(frozen=True)
class Path:
    """A path of the aggregated automaton: nodes as (situation, plant state) and events."""

    nodes: tuple[Key, ...]
    events: tuple[Event, ...]


class Numbered(Protocol):
    """The stable situations met, numbered as the nodes ``(situation, plant state)`` name them."""

    @property
    def plant(self) -> Plant:
        """The plant whose states the nodes hold."""
        ...

    @property
    def machine(self) -> GrafcetMachine:
        """The Grafcet's machine (the situations' reading of IEC 60848)."""
        ...

    @property
    def situations(self) -> list[Situation]:
        """The situations by index."""
        ...

    def situation(self, sit: Situation) -> int:
        """The index of ``sit`` (numbered when first asked for, where the representation allows it)."""
        ...


class SymbolicGraph(Protocol[S, M]):
    """An explored symbolic SYNC: sets ``S`` of aggregated nodes and moves ``M`` (see the module docstring)."""

    @property
    def numbering(self) -> Numbered:
        """The situations' numbering the nodes' keys use."""
        ...

    # ---- node-set algebra
    @property
    def empty(self) -> S:
        """The empty set."""
        ...

    def union(self, a: S, b: S) -> S: ...

    def join(self, sets: Iterable[S]) -> S:
        """The union of ``sets`` (in one pass: a search joins many)."""
        ...

    def meet(self, a: S, b: S) -> S: ...

    def minus(self, a: S, b: S) -> S: ...

    def is_empty(self, a: S) -> bool: ...

    def count(self, a: S) -> int:
        """The number of nodes of ``a``, exactly."""
        ...

    # ---- the explored graph
    @property
    def initial(self) -> S:
        """The initial nodes."""
        ...

    @property
    def reached(self) -> S:
        """Every aggregated node."""
        ...

    def rings(self) -> Sequence[S]:
        """The nodes by distance from the initial nodes (the onion rings)."""
        ...

    def moves_from(self, u: S) -> Iterable[M]:
        """The moves that may leave ``u``, in the explicit exploration's order."""
        ...

    def order(self, m: M) -> tuple[int, int, int]:
        """The explicit exploration's order of ``m`` from a node: plant moves by element and variable, then timers."""
        ...

    def event(self, m: M) -> Event: ...

    def plant_move(self, m: M) -> Move | None:
        """The plant move of ``m`` (None: a timer)."""
        ...

    def post_by(self, u: S, m: M, within: S | None = None) -> S:
        """The nodes (of ``within``) the edges of ``m`` lead to from ``u``."""
        ...

    def pre_by(self, u: S, m: M) -> S:
        """The nodes with an edge of ``m`` into ``u``."""
        ...

    def pre(self, u: S, within: S) -> S:
        """The nodes of ``within`` with an edge into ``u``."""
        ...

    def forward(self, u: S) -> S:
        """Nodes reachable from ``u`` (included)."""
        ...

    def backward(self, u: S, within: S | None = None) -> S:
        """Nodes from which ``u`` can be reached (included; only through ``within`` when given)."""
        ...

    def held(self) -> S:
        """Nodes from which no node with other active steps is reachable."""
        ...

    def is_held(self, key: Key) -> bool:
        """:meth:`held` for one node."""
        ...

    # ---- one node
    def pick(self, u: S) -> Key:
        """One node of ``u`` (not empty): the smallest situation, then the smallest state."""
        ...

    def cube(self, key: Key) -> S:
        """The node ``key`` as a set."""
        ...

    def contains(self, u: S, key: Key) -> bool: ...

    def listed(self, u: S, limit: int) -> list[Key]:
        """The nodes of ``u``, situation by situation (at most ``limit``)."""
        ...

    # ---- what the report asks
    def waited(self) -> S:
        """The initial nodes, and the initial situation's nodes once its timers elapsed."""
        ...

    def where(self, condition: Expr) -> S:
        """The nodes where ``condition`` (over plant and step variables) holds."""
        ...

    def prohibited(self) -> dict[tuple[Steps, Event], S]:
        """Per (active steps, refused order event), the nodes where SUP refuses it."""
        ...

    def only_steps(self, u: S, steps: Collection[Steps]) -> bool:
        """Whether every situation of ``u`` has its active steps among ``steps``."""
        ...

    def conflicts(self) -> list[tuple[S, Event, str, tuple[str, ...]]]:
        """The OR-divergence conflicts met: (source nodes, event, step, transitions fired)."""
        ...

    def never_leaves(self) -> bool:
        """Whether every situation met has the initial situation's active steps."""
        ...

    def one_per_situation(self) -> list[Key]:
        """One node of every situation with nodes."""
        ...

    def reached_steps(self) -> frozenset[str]:
        """The steps active in some situation met."""
        ...

    def stats(self) -> dict[str, int]:
        """The counts of the report: SYNC states, aggregated states and transitions."""
        ...

    def situation_count(self) -> int:
        """The number of stable situations met."""
        ...


class Finder(Protocol[S_contra]):
    """A report's searches: the first node of each finding, then the traces to nodes
    (one target at a time: :class:`~synth.symbolic.searches.OneByOne`; batched:
    :class:`~synth.symbolic.steps.batch.Batched`)."""

    def firsts(self, sets: Sequence[S_contra]) -> list[tuple[Key, int, PathKey]]:
        """Per set, (its first node, distance, path key) as :func:`~synth.symbolic.searches.first_node`."""
        ...

    def traces(self, keys: Sequence[Key]) -> list[Path]:
        """Per node, its trace as :func:`~synth.symbolic.searches.shortest_trace` (after :meth:`firsts`)."""
        ...
