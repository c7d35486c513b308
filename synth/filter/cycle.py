"""One PLC cycle of a safety logic filter: the algorithms and modes a filter runs in.

>>> Algorithm("loop"), Mode("blocking")
(<Algorithm.LOOP: 'loop'>, <Mode.BLOCKING: 'blocking'>)
"""

from __future__ import annotations

from enum import StrEnum

__all__ = ["Algorithm", "Mode"]


class Algorithm(StrEnum):
    """How the outputs are computed: the synthesised equations, or 000's correction loop."""

    ALGEBRAIC = "algebraic"
    LOOP = "loop"


class Mode(StrEnum):
    """What the filter does with the requests (000 §3): pass them on, or latch and fold."""

    SUPERVISOR = "supervisor"
    BLOCKING = "blocking"
