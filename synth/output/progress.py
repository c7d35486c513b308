"""Progress lines for long runs, on a terminal only (never in pipes, files or CI logs).

Example
-------
>>> tty_progress(False) is None
True
"""

from __future__ import annotations

import sys
import time
from typing import Callable

__all__ = ["tty_progress", "clear_progress"]


def tty_progress(enabled: bool) -> Callable[[str], None] | None:
    """A function that overwrites one stderr line with ``[seconds] text``, or None when disabled."""
    if not enabled:
        return None
    start = time.monotonic()

    def show(text: str) -> None:
        sys.stderr.write(f"\r\033[K[{time.monotonic() - start:6.1f}s] {text}")
        sys.stderr.flush()

    return show


def clear_progress(show: Callable[[str], None] | None) -> None:
    """Erase the progress line, if one was shown."""
    if show is not None:
        sys.stderr.write("\r\033[K")
        sys.stderr.flush()
