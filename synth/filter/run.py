"""``synth filter run``: a trace of cycles read from a CSV file, evaluated cycle by cycle
with :class:`~synth.filter.cycle.FilterCycle`, printed as text or JSON.

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
from typing import Any, Sequence

from synth.errors import InputError, Location, close_names
from synth.filter.cycle import Algorithm, CycleResult, FilterCycle

__all__ = ["Row", "read_trace", "load_trace", "run", "run_text", "run_json"]


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


def _bits(v: Sequence[bool]) -> str:
    return "".join("1" if b else "0" for b in v)


def run_text(cycle: FilterCycle, rows: Sequence[Row], results: Sequence[CycleResult]) -> str:
    """One line per cycle: the true read-only values, R -> O as bit strings in output
    order, then what happened; the loop's iterations on a second line."""
    f = cycle.filter
    ys = [n for n in cycle.reads if n not in cycle.requests]
    lines = [f"outputs: {', '.join(f.outputs)}   ({cycle.algorithm.value}, {cycle.mode.value})"]
    width = len(str(len(rows)))
    for k, (row, r) in enumerate(zip(rows, results), 1):
        vals = dict(row.values)
        y = ", ".join(n for n in ys if vals[n])
        line = f"{k:>{width}}  Y: {{{y}}}  R: {_bits(r.requests)} -> O: {_bits(r.outputs)}"
        if r.violated:
            line += "  violated: " + ", ".join(r.violated)
        if r.corrections:
            line += "  corrected: " + ", ".join(r.corrections)
        for flag, word in ((r.fallback, "FALLBACK"), (r.outside_care, "OUTSIDE CARE SET"), (r.blocked, "blocked")):
            if flag:
                line += f"  {word}"
        if r.unsafe:
            line += "  UNSAFE: " + ", ".join(r.unsafe)
        lines.append(line)
        if cycle.algorithm is Algorithm.LOOP:
            lines.append(" " * width + "  iterations: " + " ".join(_bits(si) for si in r.iterations))
    bad = sum(1 for r in results if r.fallback or r.outside_care)
    lines.append(f"{len(results)} cycles, {sum(1 for r in results if r.corrections)} corrected, "
                 f"{sum(1 for r in results if r.fallback)} fallback, "
                 f"{sum(1 for r in results if r.outside_care)} outside the care set"
                 + ("" if bad else ": coherent"))
    return "\n".join(lines) + "\n"


def run_json(cycle: FilterCycle, rows: Sequence[Row], results: Sequence[CycleResult]) -> dict[str, Any]:
    outs = cycle.outputs

    def named(v: Sequence[bool]) -> dict[str, int]:
        return {o: int(b) for o, b in zip(outs, v)}

    return {
        "algorithm": cycle.algorithm.value,
        "mode": cycle.mode.value,
        "outputs": list(outs),
        "cycles": [{
            "cycle": k, "line": row.line,
            "read": {n: int(v) for n, v in row.values},
            "requests": named(r.requests), "outputs": named(r.outputs),
            "iterations": [named(si) for si in r.iterations],
            "fallback": r.fallback, "violated": list(r.violated), "corrections": list(r.corrections),
            "outside_care": r.outside_care, "unsafe": list(r.unsafe), "blocked": r.blocked,
        } for k, (row, r) in enumerate(zip(rows, results), 1)],
        "fallbacks": sum(1 for r in results if r.fallback),
        "outside_care": sum(1 for r in results if r.outside_care),
        "coherent": not any(r.fallback or r.outside_care for r in results),
    }
