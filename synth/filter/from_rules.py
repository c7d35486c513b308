"""``synth filter from-rules``: a ``.filter`` skeleton from a rules file's constraints.

The skeleton ``use``-s the rules file (its inputs and orders become the filter's inputs
and outputs; they are listed in comments) and has one ``safety`` per constraint that
involves an order: ``constraint C: X = 0`` gives ``safety C: X`` and ``X = 1`` gives
``safety C: !(X)``. An edge constraint such as ``↓AVANCER1 & !v11`` stays as written (an
edge of an output is a literal of that output at t: a simple constraint). The filter's
checker classifies each one (one output at t: CSs, more: CSc); combined constraints get
no priority, only a comment saying to add ``keep``/``force``. A constraint on inputs only
is no filter constraint: it is kept as a comment. The text is checked by parsing it back
(``synth filter from-rules`` then writes it).

Example
-------
>>> import tempfile, pathlib
>>> with tempfile.TemporaryDirectory() as tmp:
...     d = pathlib.Path(tmp)
...     _ = (d / "p.rules").write_text('''element E { order A = 0, B = 0  sensor s = 0  ↑A -> ↑s  ↓A -> ↓s }
... constraint K "not both": A & B = 0
... constraint S: B & s = 0''')
...     sk = skeleton(d / "p.rules", d / "p.filter")
>>> [(c.id, str(c.kind)) for c in sk.constraints]
[('K', 'combined'), ('S', 'simple')]
>>> print(sk.text.splitlines()[5])
safety K "not both": A & B
"""

from __future__ import annotations

import os
from dataclasses import dataclass
from enum import StrEnum
from pathlib import Path

from synth.filter.language import Filter
from synth.filter.language_check import output_polarities, parse_filter
from synth.plant.rules import RuleSet
from synth.plant.rules_check import load_rules

__all__ = ["Classification", "Classified", "Skeleton", "skeleton"]


class Classification(StrEnum):
    """How a rules constraint enters the skeleton: a simple or combined filter constraint,
    or skipped (no order in it)."""

    SIMPLE = "simple"
    COMBINED = "combined"
    SKIPPED = "skipped"


@dataclass(frozen=True)
class Classified:
    """A rules constraint as the filter sees it, and the outputs at t it involves."""

    id: str
    kind: Classification
    outputs: tuple[str, ...]
    expression: str


@dataclass(frozen=True)
class Skeleton:
    """The skeleton's text, the constraints classified, and the filter it parses to."""

    text: str
    constraints: tuple[Classified, ...]
    filter: Filter


def _use_path(rules: Path, output: Path) -> str:
    """The rules file relative to the output's folder (absolute if that folder does not exist yet)."""
    if not output.resolve().parent.is_dir():
        return rules.resolve().as_posix()
    try:
        return Path(os.path.relpath(rules.resolve(), output.resolve().parent)).as_posix()
    except ValueError:  # another drive
        return rules.resolve().as_posix()


def _vector(word: str, names: tuple[str, ...]) -> list[str]:
    lines, line = [], f"# {word}"
    for i, n in enumerate(names):
        piece = (" " if i == 0 else ", ") + n
        if len(line) + len(piece) > 88:
            lines.append(line + ",")
            line = "#" + " " * len(word) + " " + n
        else:
            line += piece
    return lines + [line]


def skeleton(rules_path: str | Path, output: str | Path) -> Skeleton:
    """The skeleton for ``rules_path`` as it will read when written to ``output``."""
    rules_path, output = Path(rules_path), Path(output)
    rs: RuleSet = load_rules(rules_path)
    outs = set(rs.outputs)
    use = _use_path(rules_path, output)
    lines = [f"# Filter skeleton written by `synth filter from-rules {rules_path.as_posix()}`.",
             f'use "{use}"',
             *_vector("inputs (from the plant):", rs.inputs),
             *_vector("outputs (from the plant):", rs.outputs),
             ""]
    kinds: list[Classified] = []
    for c in rs.constraints:
        forbidden = c.forbidden
        text = forbidden.text()
        involved = tuple(output_polarities(forbidden, outs))
        label = f' "{c.label.replace(chr(34), chr(39))}"' if c.label else ""
        if not involved:
            lines.append(f"# {c.id}{label}: {text}  -- involves no order: not a filter constraint")
            kinds.append(Classified(c.id, Classification.SKIPPED, (), text))
            continue
        lines.append(f"safety {c.id}{label}: {text}")
        if len(involved) > 1:
            lines.append("    # combined: add `keep L` or `force o=v, ...` (needed by --algorithm loop)")
        kind = Classification.SIMPLE if len(involved) == 1 else Classification.COMBINED
        kinds.append(Classified(c.id, kind, involved, text))
    text = "\n".join(lines) + "\n"
    f = parse_filter(text, str(output), output.resolve().parent)  # errors are synth's: never written
    for k in kinds:  # the filter checker agrees with the classification above
        if k.kind is not Classification.SKIPPED:
            assert f.safety(k.id).kind.value == k.kind and f.safety(k.id).outputs == k.outputs, k
    return Skeleton(text, tuple(kinds), f)
