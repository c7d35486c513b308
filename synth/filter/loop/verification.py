"""What ``synth filter verify`` finds: the kinds of finding, a trace row, a finding and
the verification's outcome (:func:`~synth.filter.loop.verify.verify` computes them).

Example
-------
>>> row = TraceRow("initial", "A", "", (), ())
>>> v = Verification("F.filter", "p.rules", ANY_CONTROL, Algorithm.LOOP, Mode.SUPERVISOR, False, False,
...                  1, 1, 0, True, 0.0, 0, {FindingKind.FALLBACK: Finding(FindingKind.FALLBACK, (), (row,), 1)})
>>> v.safe, v.coherent, [str(k) for k in v.findings]
(True, False, ['fallback'])
"""

from __future__ import annotations

from dataclasses import dataclass, field
from enum import StrEnum

from synth.choices import EngineChoice
from synth.filter.cycle import Algorithm, Mode

__all__ = ["ANY_CONTROL", "ControlKind", "Control", "FindingKind", "UNSAFE", "INCOHERENT", "TraceRow", "Finding", "ProgressFailure",
           "Progress", "Verification"]

ANY_CONTROL = "any control"
"""The request source of ``--any-control`` (otherwise the Grafcet's file, or ``PROGRAM P of F.st``)."""


class ControlKind(StrEnum):
    """What makes the requests of each scan."""

    ANY = "any"  # --any-control: every request vector
    GRAFCET = "grafcet"  # --grafcet G.g7: the Grafcet's orders
    ST = "st"  # --control PROG.st: a cyclic IEC 61131-3 PROGRAM run by the ST interpreter


@dataclass(frozen=True)
class Control:
    """The request source of a verification (the ``control`` key of the JSON)."""

    kind: ControlKind
    file: str | None = None
    program: str | None = None

    def json(self) -> dict[str, str]:
        out = {"kind": str(self.kind)}
        if self.file is not None:
            out["file"] = self.file
        if self.program is not None:
            out["program"] = self.program
        return out


class FindingKind(StrEnum):
    """The kinds of finding, in the order they are reported."""

    VIOLATION = "violation"  # a plant state violates a constraint once the outputs are written
    EDGE = "edge"  # an output event breaks an edge constraint
    REFUSED = "refused"  # the plant has no controllable event for an output change
    FALLBACK = "fallback"  # the loop falls back
    OUTSIDE_CARE = "outside_care"  # Y is outside the care set of the algebraic filter
    TRANSIENT = "transient"  # a plant state violates a constraint before the PLC writes its outputs
    OUTSIDE_SUP = "outside_sup"  # uncontrollable events alone lead from a state to a violation


UNSAFE = (FindingKind.VIOLATION, FindingKind.EDGE, FindingKind.REFUSED, FindingKind.OUTSIDE_SUP)
"""The kinds that make the loop unsafe (and ``transient`` with ``strict``)."""

INCOHERENT = (FindingKind.FALLBACK, FindingKind.OUTSIDE_CARE)
"""The kinds that make the loop incoherent."""


@dataclass(frozen=True)
class TraceRow:
    """One cycle of a trace, as ``synth run`` prints a step: the plant's event, the
    plant state (its true variables), the situation, the requests and the orders."""

    event: str
    state: str
    situation: str
    requests: tuple[str, ...]
    orders: tuple[str, ...]
    note: str = ""
    ran: bool = True  # False: the plant's event only, the PLC has not run yet


@dataclass(frozen=True)
class Finding:
    """The first (shortest) occurrence of one kind of finding, and how many distinct
    plant states show it."""

    kind: FindingKind
    constraints: tuple[str, ...]
    trace: tuple[TraceRow, ...]
    count: int


class ProgressFailure(StrEnum):
    """How ``--progress GOAL`` fails."""

    UNREACHABLE = "unreachable"  # a reachable state from which no path reaches GOAL
    AVOIDED = "avoided"  # a fair cycle of the closed loop that never meets GOAL


@dataclass(frozen=True)
class Progress:
    """The outcome of ``--progress GOAL``: the states from which GOAL cannot be reached,
    the states on a fair cycle avoiding it, and the shortest trace of the first failure
    (to the first such state; for a cycle, then once around it)."""

    goal: str
    unreachable: int
    avoiding: int
    failure: ProgressFailure | None = None
    trace: tuple[TraceRow, ...] = ()

    @property
    def holds(self) -> bool:
        return self.failure is None


@dataclass(frozen=True)
class Verification:
    """The outcome of :func:`~synth.filter.loop.verify.verify`."""

    filter: str
    plant: str
    source: str  # ANY_CONTROL or the Grafcet's file
    algorithm: Algorithm
    mode: Mode
    atomic: bool
    strict: bool
    states: int  # nodes of the product
    plant_states: int  # distinct plant states among them
    cycles: int  # transitions explored
    complete: bool
    seconds: float
    outside_sup: int
    findings: dict[FindingKind, Finding] = field(default_factory=dict)
    corrected: int = 0  # cycles where O != R (with a Grafcet: the transparency)
    max_distance: int = 0
    events_per_cycle: int = 1  # the plant makes 0..K events between two scans
    progress: Progress | None = None  # with --progress (None: not asked, or the exploration stopped)
    control: Control = Control(ControlKind.ANY)
    engine: EngineChoice = EngineChoice.EXPLICIT  # the engine that explored (--engine)

    @property
    def safe(self) -> bool:
        bad = set(UNSAFE) | ({FindingKind.TRANSIENT} if self.strict else set())
        return not any(k in self.findings for k in bad)

    @property
    def coherent(self) -> bool:
        return not any(k in self.findings for k in INCOHERENT)
