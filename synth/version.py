"""synth's version, read from the installed distribution only when asked (``--help`` stays fast).

>>> version().count(".") >= 1
True
"""

from __future__ import annotations

__all__ = ["version"]


def version() -> str:
    """The installed distribution's version (the source tree's pyproject when not installed)."""
    from importlib import metadata

    try:
        return metadata.version("synth")
    except metadata.PackageNotFoundError:  # pragma: no cover - a bare source tree
        import re
        from pathlib import Path

        text = (Path(__file__).resolve().parents[2] / "pyproject.toml").read_text(encoding="utf-8")
        found = re.search(r'^version = "([^"]+)"', text, re.M)
        return found.group(1) if found else "unknown"
