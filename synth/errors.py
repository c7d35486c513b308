"""One exception hierarchy for synth, and friendly source-located messages.

Every mistake in a user file (``.rules``, ``.g7``) becomes an :class:`InputError`
carrying a :class:`Location`. Its :meth:`InputError.render` gives the format the
CLI prints::

    plants/tri.rules:12:21: error: unknown variable 'AVANCR1'
      12 | constraint C1 "V1": AVANCR1 & RECULER1 = 0
         |                     ^~~~~~~
      = did you mean AVANCER1?

Example
-------
>>> loc = Location("a.rules", 1, 5, "foo bar baz", 3)
>>> print(InputError("unknown variable 'bar'", loc, suggestions=("baz",)).render())
a.rules:1:5: error: unknown variable 'bar'
  1 | foo bar baz
    |     ^~~
  = did you mean baz?
"""

from __future__ import annotations

from enum import StrEnum
from functools import lru_cache

from synth.frozen import frozen

TYPE_CHECKING = False  # typing.TYPE_CHECKING, without importing typing
if TYPE_CHECKING:
    from collections.abc import Iterable, Sequence

__all__ = [
    "Location",
    "Severity",
    "SynthError",
    "InputError",
    "InputErrors",
    "ModelError",
    "ModelFailure",
    "LimitExceeded",
    "close_names",
    "location_in",
    "source_lines",
]


@frozen
class Location:
    """A position in a user file (1-based line and column) and the text of that line."""

    file: str
    line: int
    column: int
    text: str = ""
    width: int = 1

    def __str__(self) -> str:
        return f"{self.file}:{self.line}:{self.column}"


class Severity(StrEnum):
    """How bad a reported input mistake is: an error stops the command, a warning does not."""

    ERROR = "error"
    WARNING = "warning"


class SynthError(Exception):
    """Base of every error synth raises on purpose."""


class InputError(SynthError):
    """A mistake in a user's input file: reported with file, line, column and a caret."""

    def __init__(
        self,
        message: str,
        location: Location | None,
        *,
        expected: Sequence[str] = (),
        suggestions: Sequence[str] = (),
        notes: Sequence[str] = (),
        severity: Severity = Severity.ERROR,
    ) -> None:
        super().__init__(message)
        self.severity = Severity(severity)
        self.message = message
        self.location = location
        self.expected = tuple(expected)
        self.suggestions = tuple(suggestions)
        self.notes = tuple(notes)

    def render(self) -> str:
        """The message, the line quoted with a caret under the column, then what was expected,
        the close names and the notes. Every part is bounded: a huge line is quoted in a
        window of :data:`WINDOW` characters around the column, a huge message or name cut."""
        loc = self.location
        message = _bounded(self.message, 20 * WINDOW)
        head = f"{_bounded(str(loc), 2 * WINDOW)}: {self.severity}: {message}" if loc else f"{self.severity}: {message}"
        lines = [head]
        if loc is not None and loc.text:
            number = str(loc.line)
            pad = " " * len(number)
            raw = loc.text.rstrip("\n")
            column, width = max(1, loc.column), max(1, loc.width)
            start = 0
            if len(raw) > WINDOW:  # the window around the column, "…" where the line goes on
                start = max(0, min(column - 1 - WINDOW // 3, len(raw) - WINDOW))
                raw = ("…" if start else "") + raw[start:start + WINDOW] + ("…" if start + WINDOW < len(raw) else "")
                column = column - start + (1 if start else 0)
                width = max(1, min(width, len(raw) - column + 1))
            # one visible character per control character, so the caret stays aligned
            text = "".join(c if c >= " " or c == "\t" else chr(0x2400 + ord(c)) for c in raw)
            text = text.expandtabs(1)
            lines.append(f"  {number} | {text}")
            lines.append(f"  {pad} | " + " " * (column - 1) + "^" + "~" * (width - 1))
        if self.expected:
            lines.append("  = expected " + ", ".join(_bounded(e, WINDOW) for e in self.expected[:20]))
        if self.suggestions:
            lines.append("  = did you mean " + " or ".join(_bounded(s, WINDOW) for s in self.suggestions) + "?")
        for note in self.notes:
            lines.append("  = note: " + _bounded(note, 20 * WINDOW))
        return "\n".join(lines)

    def __str__(self) -> str:
        return self.render()


WINDOW = 120
"""How many characters of a line an error quotes (around the column), and the unit of the
other bounds of :meth:`InputError.render`."""


def _bounded(text: str, limit: int) -> str:
    """``text``, cut to ``limit`` characters with "… (N characters)" when longer.

    >>> _bounded("abcdef", 4)
    'abcd… (6 characters)'
    """
    return text if len(text) <= limit else f"{text[:limit]}… ({len(text)} characters)"


class ModelFailure(InputError):
    """A well-formed input whose model fails in a way located in it (an assignment that leaves
    its variable's range): reported like an input error, with exit code 1, a failing model."""


MAX_SHOWN = 20
"""How many errors of one pass are shown; a line "… and N more errors" says the rest."""


class InputErrors(SynthError):
    """Several input errors found in one pass, reported together (the first :data:`MAX_SHOWN`)."""

    def __init__(self, errors: Sequence[InputError]) -> None:
        self.errors = tuple(errors)
        super().__init__(self.render())

    def render(self) -> str:
        shown = "\n\n".join(e.render() for e in self.errors[:MAX_SHOWN])
        rest = len(self.errors) - MAX_SHOWN
        return shown + (f"\n\n… and {rest} more error{'s' if rest > 1 else ''}" if rest > 0 else "")


class ModelError(SynthError):
    """A model is well-formed but cannot be processed (e.g. a Grafcet that never stabilises)."""


class LimitExceeded(SynthError):
    """An exploration stopped at the user's ``--max-states`` limit."""


def close_names(name: str, candidates: Iterable[str], n: int = 3) -> tuple[str, ...]:
    """The valid names closest to ``name`` (case-insensitive), best first.

    >>> close_names("AVANCR1", ["AVANCER1", "RECULER1", "v10"])
    ('AVANCER1',)
    """
    import difflib  # only when a name is wrong

    pool = sorted(set(candidates))
    lowered = {c.lower(): c for c in pool}
    hits = difflib.get_close_matches(name.lower(), list(lowered), n=n, cutoff=0.5)
    return tuple(lowered[h] for h in hits)


def source_lines(source: str) -> list[str]:
    """The lines of ``source`` as the parsers number them: split at ``\\n`` only (a
    ``\\r`` before it is dropped); ``\\r``, ``\\f`` and other control characters
    inside a line stay in it.

    >>> source_lines("a\\r\\nb\\fc\\n")
    ['a', 'b\\x0cc', '']
    """
    return [line[:-1] if line.endswith("\r") else line for line in source.split("\n")]


@lru_cache(maxsize=8)
def _lines(source: str) -> tuple[str, ...]:
    """:func:`source_lines`, split once per source however many tokens are located in it."""
    return tuple(source_lines(source))


def location_in(file: str, source: str, line: int, column: int, width: int = 1) -> Location:
    """A :class:`Location` whose ``text`` is taken from ``source``."""
    lines = _lines(source)
    text = lines[line - 1] if 0 < line <= len(lines) else ""
    return Location(file, line, column, text, width)
