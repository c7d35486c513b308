"""Progress of long runs: one live line on a terminal (never in pipes, files or CI logs), and
what the run has reached, which a Ctrl-C prints.

A run calls :func:`start_run` once; its stages report with the function :func:`tty_progress`
returns (always a function: off a terminal it only records). :func:`reached` says how far it
went.

Example
-------
>>> start_run()
>>> show = tty_progress(False)
>>> show("exploring: 12 states")
>>> reached().split(": ", 1)[1]
'exploring: 12 states'
>>> clear_progress(show)
"""

from __future__ import annotations

import sys
import threading
import time
from typing import Callable

__all__ = ["start_run", "reached", "tty_progress", "clear_progress", "stop_progress", "live_line"]

_state: dict[str, float | str] = {"start": time.monotonic(), "last": "", "shown": 0.0}


def start_run() -> None:
    """Start the clock of a command; nothing reached yet."""
    _state.update(start=time.monotonic(), last="", shown=0.0)


def _elapsed() -> float:
    return time.monotonic() - float(_state["start"])


def reached() -> str:
    """`` after 3.2 s: <the last progress text>`` (the text only if a stage reported one)."""
    last = str(_state["last"])
    return f" after {_elapsed():.1f} s" + (f": {last}" if last else "")


def live_line(enabled: bool) -> bool:
    """Whether to draw a live line: asked for (not ``--quiet``) and standard error a terminal."""
    return enabled and sys.stderr.isatty()


_lock = threading.Lock()
_ticker: dict[str, threading.Event | None] = {"stop": None}


def _draw(text: str, stop: threading.Event | None = None) -> None:
    with _lock:
        if stop is not None and stop.is_set():  # erased meanwhile: draw nothing more
            return
        _state["shown"] = time.monotonic()
        sys.stderr.write(f"\r\033[K[{_elapsed():6.1f}s] {text}")
        sys.stderr.flush()


def _tick(stop: threading.Event) -> None:
    """Redraw the line every half second, so the seconds run on during a long stage."""
    while not stop.wait(0.5):
        if _state["last"]:
            _draw(str(_state["last"]), stop)


def tty_progress(enabled: bool) -> Callable[[str], None]:
    """A function recording a stage's progress text; when ``enabled`` (the caller checks
    the terminal: :func:`live_line`) it also overwrites one stderr line with
    ``[seconds] text``, at most ten times a second, and a thread keeps the seconds running."""
    if enabled and _ticker["stop"] is None:
        stop = _ticker["stop"] = threading.Event()
        threading.Thread(target=_tick, args=(stop,), daemon=True, name="synth-progress").start()

    def show(text: str) -> None:
        _state["last"] = text
        if enabled and time.monotonic() - float(_state["shown"]) >= 0.1:
            _draw(text)

    show.enabled = enabled  # type: ignore[attr-defined]
    return show


def clear_progress(show: Callable[[str], None] | None) -> None:
    """Stop the redrawing and erase the line, if one was drawn."""
    if show is None or not getattr(show, "enabled", False):
        return
    stop_progress()


def stop_progress() -> None:
    """Stop the redrawing and erase the line if one is drawn (the end of any run, an error or
    a Ctrl-C included)."""
    stop = _ticker["stop"]
    if stop is not None:
        stop.set()
        _ticker["stop"] = None
    with _lock:
        if float(_state["shown"]):
            sys.stderr.write("\r\033[K")
            sys.stderr.flush()
            _state["shown"] = 0.0
