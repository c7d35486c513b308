"""``synth filter run``: a trace of cycles read from a CSV file, evaluated cycle by cycle
with :class:`~synth.filter.cycle.FilterCycle` (:mod:`synth.output.filter_text` prints it).

The CSV's header names every input, observer and request ``R_o`` of the filter (and
``Ack`` in blocking mode), in any order; each following line is one PLC cycle, its cells
``0`` or ``1``. Blank lines and lines starting with ``#`` are skipped.

Example
-------
>>> from synth.filter.language_check import parse_filter
>>> from synth.filter.cycle import FilterCycle, Algorithm
>>> f = parse_filter("outputs o1, o2\\nsafety K: o1 & o2 keep o1", "a.filter")
>>> rows = read_trace("R_o1,R_o2\\n1,1\\n0,1\\n", "t.csv", FilterCycle(f, Algorithm.LOOP).reads)
>>> [r.outputs for r in run(FilterCycle(f, Algorithm.LOOP), rows)]
[(True, False), (False, True)]
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Sequence

from synth.errors import InputError, Location, close_names
from synth.filter.cycle import Algorithm, CycleResult, FilterCycle, Mode
from synth.filter.language import Filter

__all__ = ["Row", "read_trace", "load_trace", "run", "Run", "run_trace"]


@dataclass(frozen=True)
class Row:
    """One cycle of the trace: its line in the file and the values read."""

    line: int
    values: tuple[tuple[str, bool], ...]

    def value(self, name: str) -> bool:
        return dict(self.values)[name]


def _cells(text: str) -> list[tuple[str, int]]:
    """The comma-separated cells of a line with their 1-based columns (whitespace trimmed)."""
    out, col = [], 1
    for part in text.split(","):
        stripped = part.strip()
        out.append((stripped, col + (len(part) - len(part.lstrip())) if stripped else col))
        col += len(part) + 1
    return out


def read_trace(text: str, file: str, reads: Sequence[str]) -> list[Row]:
    """The rows of a CSV trace whose header must name exactly ``reads`` (any order)."""
    lines = [(i, line.rstrip("\r")) for i, line in enumerate(text.split("\n"), 1)]
    lines = [(i, line) for i, line in lines if line.strip() and not line.lstrip().startswith("#")]
    if not lines:
        raise InputError("the trace is empty: a header naming " + ", ".join(reads) + " is expected",
                         Location(file, 1, 1, "", 1))
    head_no, head = lines[0]
    header = _cells(head)
    seen: dict[str, int] = {}
    for name, col in header:
        loc = Location(file, head_no, col, head, max(1, len(name)))
        if not name:
            raise InputError("empty column name", loc, expected=reads)
        if name not in reads:
            raise InputError(f"unknown column '{name}'", loc, suggestions=close_names(name, reads),
                             notes=("the columns are the filter's inputs, observers and requests R_o: "
                                    + ", ".join(reads),))
        if name in seen:
            raise InputError(f"column '{name}' appears twice", loc)
        seen[name] = col
    missing = [n for n in reads if n not in seen]
    if missing:
        raise InputError("missing column" + ("s " if len(missing) > 1 else " ") + ", ".join(missing),
                         Location(file, head_no, len(head) + 1, head, 1),
                         notes=("the header names every input, observer and request R_o of the filter",))
    rows = []
    for no, line in lines[1:]:
        cells = _cells(line)
        if len(cells) != len(header):
            raise InputError(f"{len(cells)} cells, the header has {len(header)}",
                             Location(file, no, len(line) + 1 if len(cells) < len(header) else cells[len(header)][1],
                                      line, 1))
        values = []
        for (name, _), (cell, col) in zip(header, cells):
            if cell not in ("0", "1"):
                raise InputError(f"0/1 expected for {name}, got '{cell}'",
                                 Location(file, no, col, line, max(1, len(cell))))
            values.append((name, cell == "1"))
        rows.append(Row(no, tuple(values)))
    return rows


def load_trace(path: str, reads: Sequence[str]) -> list[Row]:
    """:func:`read_trace` on a file (a missing file is an input error)."""
    from synth.syntax import read_source

    return read_trace(read_source(path), path, reads)


def run(cycle: FilterCycle, rows: Sequence[Row]) -> list[CycleResult]:
    """Each row as one cycle, from the initial memory."""
    memory = cycle.initial()
    out = []
    for r in rows:
        result, memory = cycle.step(memory, dict(r.values))
        out.append(result)
    return out


@dataclass(frozen=True)
class Run:
    """``synth filter run``: the cycle evaluated, the trace's rows and each cycle's result."""

    cycle: FilterCycle
    trace: str
    rows: tuple[Row, ...]
    results: tuple[CycleResult, ...]

    @property
    def coherent(self) -> bool:
        """No cycle fell back or met a Y outside the care set."""
        return not any(r.fallback or r.outside_care for r in self.results)


def run_trace(f: Filter, path: str, algorithm: Algorithm = Algorithm.ALGEBRAIC,
              mode: Mode = Mode.SUPERVISOR) -> Run:
    """The filter's cycle on the CSV trace ``path`` (:func:`load_trace`, then :func:`run`)."""
    cycle = FilterCycle(f, Algorithm(algorithm), Mode(mode))
    rows = load_trace(path, cycle.reads)
    return Run(cycle, path, tuple(rows), tuple(run(cycle, rows)))
