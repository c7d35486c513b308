"""``synth filter run``: a trace of cycles read from a CSV file, evaluated cycle by cycle
with :class:`~synth.filter.cycle.FilterCycle` (:mod:`synth.output.filter_text` prints it).

The CSV's header names every input, observer and request ``R_o`` of the filter (and
``Ack`` in blocking mode), in any order; each following line is one PLC cycle, its cells
``0`` or ``1``; an integer observer ``cpt : LOW..HIGH`` has one column ``cpt`` whose cells
are integers in its range (the cycle reads its bits). Blank lines and lines starting with
``#`` are skipped.

Example
-------
>>> from synth.filter.language_check import parse_filter
>>> from synth.filter.cycle import FilterCycle, Algorithm
>>> f = parse_filter("outputs o1, o2\\nsafety K: o1 & o2 keep o1", "a.filter")
>>> rows = read_trace("R_o1,R_o2\\n1,1\\n0,1\\n", "t.csv", FilterCycle(f, Algorithm.LOOP).reads)
>>> [r.outputs for r in run(FilterCycle(f, Algorithm.LOOP), rows)]
[(True, False), (False, True)]
>>> g = parse_filter("observer n : 1..3\\noutputs o\\nsafety S: o & n = 3", "n.filter")
>>> rows = read_trace("n,R_o\\n3,1\\n2,1\\n", "t.csv", FilterCycle(g).reads, g.integer_observers)
>>> rows[0].values, rows[0].numbers, [r.outputs for r in run(FilterCycle(g), rows)]
((('n_b0', False), ('n_b1', True), ('R_o', True)), (('n', 3),), [(False,), (True,)])
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from typing import Sequence

from synth.errors import InputError, Location, close_names
from synth.filter.cycle import Algorithm, CycleResult, FilterCycle, Mode
from synth.filter.language import Filter, IntegerObserver

__all__ = ["Row", "read_trace", "load_trace", "run", "Run", "run_trace"]


@dataclass(frozen=True)
class Row:
    """One cycle of the trace: its line in the file and the values read (the bits of an
    integer observer, whose value is in ``numbers``)."""

    line: int
    values: tuple[tuple[str, bool], ...]
    numbers: tuple[tuple[str, int], ...] = ()

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


def _columns(reads: Sequence[str], integers: Sequence[IntegerObserver]) -> list[str]:
    """``reads`` with the bits of each integer observer replaced by its name."""
    owner = {b: i.name for i in integers for b in i.bits}
    return list(dict.fromkeys(owner.get(n, n) for n in reads))


def read_trace(text: str, file: str, reads: Sequence[str], integers: Sequence[IntegerObserver] = ()) -> list[Row]:
    """The rows of a CSV trace whose header must name exactly ``reads`` (any order), an
    integer observer's bits by its one column."""
    ints = {i.name: i for i in integers}
    reads = _columns(reads, integers)
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
        values: list[tuple[str, bool]] = []
        numbers: list[tuple[str, int]] = []
        for (name, _), (cell, col) in zip(header, cells):
            if name in ints:
                i = ints[name]
                if not re.fullmatch(r"-?[0-9]+", cell) or not i.low <= int(cell) <= i.high:
                    raise InputError(f"an integer in {i.low}..{i.high} expected for {name}, got '{cell}'",
                                     Location(file, no, col, line, max(1, len(cell))))
                numbers.append((name, int(cell)))
                values += zip(i.bits, i.values(int(cell)))
                continue
            if cell not in ("0", "1"):
                raise InputError(f"0/1 expected for {name}, got '{cell}'",
                                 Location(file, no, col, line, max(1, len(cell))))
            values.append((name, cell == "1"))
        rows.append(Row(no, tuple(values), tuple(numbers)))
    return rows


def load_trace(path: str, reads: Sequence[str], integers: Sequence[IntegerObserver] = ()) -> list[Row]:
    """:func:`read_trace` on a file (a missing file is an input error)."""
    from synth.syntax import read_source

    return read_trace(read_source(path), path, reads, integers)


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
    rows = load_trace(path, cycle.reads, f.integer_observers)
    return Run(cycle, path, tuple(rows), tuple(run(cycle, rows)))
