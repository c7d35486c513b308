"""The standard IEC 61131-3 function blocks the ST interpreter runs: TON, TOF, TP, R_TRIG, F_TRIG, SR, RS.

Each is its variables with their initial values and a step that updates them from the
inputs, the block's hidden state (a timer's start, an edge detector's memory) and the
clock in milliseconds; ``TIME`` values are integers of milliseconds.

Example
-------
>>> ton = STANDARD_FBS["TON"]
>>> values, state = ton.fresh(), {}
>>> values.update(IN=True, PT=100)
>>> ton.step(values, state, 0)
>>> values["Q"]
False
>>> ton.step(values, state, 100)
>>> (values["Q"], values["ET"])
(True, 100)
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any, Callable, Mapping

__all__ = ["StandardFb", "STANDARD_FBS"]

Values = dict[str, Any]  # the block's variables: BOOL and TIME (ms) values by name
State = dict[str, Any]  # the block's hidden memory


@dataclass(frozen=True)
class StandardFb:
    """One standard function block: its variables (initial values) and its step ``(values, state, now)``."""

    name: str
    variables: Mapping[str, bool | int]
    step: Callable[[Values, State, int], None]

    def fresh(self) -> Values:
        """The variables of a new instance."""
        return dict(self.variables)


def _ton(v: Values, st: State, now: int) -> None:
    if v["IN"]:
        start = st.setdefault("start", now)
        v["ET"] = min(now - start, v["PT"])
        v["Q"] = now - start >= v["PT"]
    else:
        st.pop("start", None)
        v["ET"], v["Q"] = 0, False


def _tof(v: Values, st: State, now: int) -> None:
    if v["IN"]:
        st.pop("fall", None)
        v["ET"], v["Q"] = 0, True
    elif v["Q"]:
        fall = st.setdefault("fall", now)
        v["ET"] = min(now - fall, v["PT"])
        v["Q"] = now - fall < v["PT"]


def _tp(v: Values, st: State, now: int) -> None:
    if "start" not in st and v["IN"] and not st.get("in", False):
        st["start"] = now
    if "start" in st:
        v["ET"] = min(now - st["start"], v["PT"])
        v["Q"] = now - st["start"] < v["PT"]
        if not v["Q"] and not v["IN"]:
            del st["start"]
    else:
        v["ET"], v["Q"] = 0, False
    st["in"] = v["IN"]


def _r_trig(v: Values, st: State, now: int) -> None:
    m = st.get("M", False)
    v["Q"] = v["CLK"] and not m
    st["M"] = v["CLK"]


def _f_trig(v: Values, st: State, now: int) -> None:
    # IEC 61131-3: Q := NOT CLK AND NOT M; M := NOT CLK (M starts FALSE)
    m = st.get("M", False)
    v["Q"] = not v["CLK"] and not m
    st["M"] = not v["CLK"]


def _sr(v: Values, st: State, now: int) -> None:
    v["Q1"] = v["S1"] or (v["Q1"] and not v["R"])


def _rs(v: Values, st: State, now: int) -> None:
    v["Q1"] = not v["R1"] and (v["S"] or v["Q1"])


_TIMER = {"IN": False, "PT": 0, "Q": False, "ET": 0}
_EDGE = {"CLK": False, "Q": False}

STANDARD_FBS: Mapping[str, StandardFb] = {fb.name: fb for fb in (
    StandardFb("TON", _TIMER, _ton),
    StandardFb("TOF", _TIMER, _tof),
    StandardFb("TP", _TIMER, _tp),
    StandardFb("R_TRIG", _EDGE, _r_trig),
    StandardFb("F_TRIG", _EDGE, _f_trig),
    StandardFb("SR", {"S1": False, "R": False, "Q1": False}, _sr),
    StandardFb("RS", {"S": False, "R1": False, "Q1": False}, _rs),
)}
