"""The only layer that calls Graphviz: DOT text → SVG, and atomic file output."""

from __future__ import annotations

import shutil
from pathlib import Path

from .errors import SynthError
from .files import write_atomic

__all__ = ["svg", "write_svg", "dot_available"]


def dot_available() -> bool:
    """Whether Graphviz's ``dot`` program is on the PATH."""
    return shutil.which("dot") is not None


def svg(dot_text: str) -> str:
    """Render DOT text to SVG text with Graphviz's ``dot``."""
    import graphviz

    if not dot_available():
        raise SynthError("Graphviz's 'dot' program is not installed (Debian: apt-get install graphviz)")
    try:
        out = graphviz.Source(dot_text).pipe(format="svg", encoding="utf-8")
    except graphviz.backend.ExecutableNotFound as exc:  # pragma: no cover - checked above
        raise SynthError(str(exc)) from None
    except graphviz.backend.CalledProcessError as exc:
        raise SynthError(f"Graphviz failed: {exc.stderr.decode('utf-8', 'replace') if exc.stderr else exc}") from None
    return out


def write_svg(path: str | Path, dot_text: str) -> Path:
    """Render and write an SVG file atomically."""
    return write_atomic(path, svg(dot_text))
