"""The closed loop's parts for ``synth filter verify``: the plant of a rules file as
functions of its state codes (:mod:`~synth.filter.loop.columns`: variables, controllable
and uncontrollable moves, illegal states, states outside SUP, edge events forbidden),
the filter cycle and the controller that makes the requests (a Grafcet, an ST program of
:mod:`~synth.filter.loop.control_st`, or none: any control).

Example
-------
>>> from synth.plant.composition import _plants
>>> from synth.filter.from_rules import skeleton
>>> sk = skeleton(_plants("tri.rules"), _plants("F.filter"))  # the text only: nothing is written
>>> from synth.plant.composition import load_plant
>>> pr = Product(sk.filter, load_plant(_plants("tri.rules")), None, Algorithm.ALGEBRAIC, Mode.SUPERVISOR, False)
>>> pr.size == pr.plant.size, bool(pr.illegal[pr.plant.initial_index])
(True, False)
"""

from __future__ import annotations

from typing import Any, Iterator, Mapping

import numpy as np

from synth.errors import InputError, LimitExceeded
from synth.filter.cycle import Algorithm, FilterCycle, Mode
from synth.filter.language import Filter
from synth.filter.loop.columns import Column, PlantColumns

TYPE_CHECKING = False  # typing.TYPE_CHECKING: the Grafcet modules load only with --grafcet
if TYPE_CHECKING:
    from synth.grafcet.language import Grafcet
    from synth.grafcet.machine import GrafcetMachine
    from synth.filter.loop.control_st import StControl, StSource
    from synth.plant.composition import Plant
    from synth.plant.rules import RuleSet

__all__ = ["Product", "rules_of"]


def rules_of(p: Plant) -> RuleSet:
    """The rule set ``p`` was built from (:func:`~synth.plant.composition.plant`)."""
    if p.rules is None:
        raise AssertionError("the closed loop needs a plant built from a rule set (plant(load_rules(path)))")
    return p.rules


class Product:
    """The filter, the plant ``p`` (built from its rule set ``p.rules``) and the Grafcet
    ``g`` (checked against the plant's inputs and outputs; or none: any control), checked
    against each other; the plant's parts are :class:`~synth.filter.loop.columns.Column`
    objects, indexed by state codes like arrays over the plant's grid."""

    def __init__(self, f: Filter, p: Plant, g: Grafcet | None, algorithm: Algorithm,
                 mode: Mode, atomic: bool, control: StSource | None = None) -> None:
        rs = rules_of(p)
        self.plant, self.rules = p, rs
        self.cycle = FilterCycle(f, algorithm, mode)
        self.filter, self.atomic = f, atomic
        for kind, names, have in (("input", f.inputs, p.inputs), ("output", f.outputs, p.outputs)):
            missing = [n for n in names if n not in have]
            if missing:
                raise InputError(f"{f.file}: the filter's {kind} {', '.join(missing)} is not an "
                                 f"{kind} of the plant {rs.path}", None)
        self.machine: GrafcetMachine | None = None
        self.grafcet: Grafcet | None = g
        if g is not None:
            from synth.grafcet.machine import GrafcetMachine

            self.machine = GrafcetMachine(g)
        self.control: StControl | None = None
        if control is not None:
            from synth.filter.loop.control_st import StControl

            self.control = StControl(control, rs.inputs, p.outputs, f.outputs, f.file)
        # the inputs the controller reads: the Grafcet's, or the program's VAR_INPUTs (plant names)
        self.grafcet_inputs: tuple[str, ...] = () if self.grafcet is None else tuple(self.grafcet.inputs)
        if self.control is not None:
            self.grafcet_inputs = tuple(self.control.inputs)
        self.steps: tuple[str, ...] = () if self.grafcet is None else tuple(s.name for s in self.grafcet.steps)
        observable = {f"X{s}" for s in self.steps}
        self.program_observers = tuple(d.name for d in f.observers if d.definition is None)
        for d in f.observers:
            if self.control is not None and d.definition is None and d.name.upper() not in self.control.observable:
                raise InputError(f"observer {d.name} has no value in verify: define it (`observer {d.name} := "
                                 f"EXPR`) or make it a BOOL variable of PROGRAM {self.control.program}", d.loc)
            if self.control is None and d.name not in observable and d.definition is None:
                raise InputError(f"observer {d.name} has no value in verify: define it (`observer {d.name} := "
                                 "EXPR`) or make it a step variable of the --grafcet Grafcet", d.loc)
        self.size = p.size
        self.columns = cols = PlantColumns(p, rs.constraints)  # functions of state codes: nothing per plant state
        self.val: dict[str, Column] = cols.val
        self.orders = p.outputs
        self.passthrough = tuple(o for o in p.outputs if o not in f.outputs)
        self.held = {v.name: v.initial for v in rs.variables if v.held}  # requested at their held value
        self.ynames = tuple(dict.fromkeys([*f.inputs, *self.grafcet_inputs]))
        if len(self.ynames) > 40:
            raise LimitExceeded(f"{len(self.ynames)} inputs are read; verify codes an input vector in 40 bits")
        self.toggle: dict[str, Column] = cols.toggle
        self.uncontrollable: tuple[str, ...] = tuple(e for e, _ in cols.uncontrollable)  # in first-seen order
        self.illegal: Column = cols.illegal
        self.outside_sup: Column = cols.outside_sup
        self.forbid: dict[str, Column] = cols.forbid
        self.used_index = [self.cycle.remembered.index(n) for n in self.cycle.used]

    @property
    def controlled(self) -> bool:
        """A controller (a Grafcet or an ST program) makes the requests: it has a state."""
        return self.machine is not None or self.control is not None

    def initial_situation(self, inputs: Mapping[str, bool]) -> Any:
        """The controller's state at start (``inputs``: the plant's initial inputs)."""
        if self.control is not None:
            return self.control.initial()
        if self.machine is not None:
            return self.machine.initial({n: inputs[n] for n in self.grafcet_inputs})
        return None

    def timers(self, sit: Any) -> tuple[str, ...]:
        """The controller's timers that may elapse in the cycle (instead of plant events)."""
        if self.control is not None:
            return self.control.timers(sit)
        return self.machine.timers(sit) if self.machine is not None else ()

    def requested(self, sit: Any, values: Mapping[str, bool]) -> tuple[dict[str, bool], dict[str, bool]] | None:
        """The controller's observers (step variables, program variables) and its requests
        for every plant order, in ``sit`` after its reaction to ``values`` (None: any control)."""
        if self.control is not None:
            req = self.control.orders(sit)
            return (self.control.observe(sit, self.program_observers),
                    {o: self.held.get(o, req.get(o, False)) for o in self.orders})
        if self.machine is None:
            return None
        orders = self.machine.orders(sit, {n: values[n] for n in self.grafcet_inputs})
        return {f"X{s}": s in sit.steps for s in self.steps}, {o: self.held.get(o, o in orders) for o in self.orders}

    def moves(self, codes: np.ndarray) -> Iterator[tuple[str, np.ndarray]]:
        """Every uncontrollable event and its successor of each code (-1: it cannot occur)."""
        return self.columns.moves(codes)

    def label(self, code: int) -> str:
        return self.plant.label(self.plant.local(code))

    def violated(self, code: int) -> tuple[str, ...]:
        return self.columns.violated(code)
