"""Writing output files atomically: a report is complete or absent, never partial."""

from __future__ import annotations

import os
import tempfile
from pathlib import Path

__all__ = ["write_atomic", "write_or_print", "write_files"]


def write_atomic(path: str | Path, data: str | bytes) -> Path:
    """Write ``data`` to a temporary file beside ``path``, then rename it into place.

    >>> import tempfile, pathlib
    >>> with tempfile.TemporaryDirectory() as d:
    ...     write_atomic(pathlib.Path(d) / "a.txt", "hello").read_text()
    'hello'
    """
    target = Path(path)
    raw = data.encode("utf-8") if isinstance(data, str) else data
    try:
        blocker = next((d for d in target.parents if d.exists()), None)
        if blocker is not None and not blocker.is_dir():
            raise NotADirectoryError(20, f"'{blocker}' is a file, not a folder")
        target.parent.mkdir(parents=True, exist_ok=True)
        fd, tmp = tempfile.mkstemp(prefix=f".{target.name}.", suffix=".tmp", dir=target.parent)
    except (OSError, ValueError) as exc:
        raise _cannot_write(target, exc) from None
    try:
        with os.fdopen(fd, "wb") as fh:
            fh.write(raw)
        umask = os.umask(0)
        os.umask(umask)
        os.chmod(tmp, 0o666 & ~umask)
        os.replace(tmp, target)
    except BaseException as exc:
        try:
            os.unlink(tmp)
        except OSError:
            pass
        if isinstance(exc, OSError):
            raise _cannot_write(target, exc) from None
        raise
    return target


def _cannot_write(target: Path, exc: Exception) -> Exception:
    """``cannot write 'path': reason``, an input error (exit 2) without a location."""
    from synth.errors import InputError

    shown = str(target) if len(str(target)) <= 200 else str(target)[:200] + "…"
    reason = exc.strerror if isinstance(exc, OSError) and exc.strerror else str(exc)
    return InputError(f"cannot write '{shown}': {reason}", None)


def write_or_print(path: str | Path | None, data: str | bytes) -> None:
    """``data`` to ``path`` atomically, or to standard output when no path is given."""
    import sys

    if path:
        write_atomic(path, data)
    elif isinstance(data, bytes):
        sys.stdout.buffer.write(data)
    else:
        sys.stdout.write(data)


def write_files(folder: str | Path | None, files: list[tuple[str, bytes]]) -> None:
    """Several files (already rendered, so an error leaves none behind) into ``folder``, each
    written atomically; ``folder`` is required (a located error on the command line otherwise)."""
    from synth.errors import InputError

    if not folder:
        raise InputError(f"{len(files)} files to write ({', '.join(n for n, _ in files)}): give -o DIR", None)
    if Path(folder).exists() and not Path(folder).is_dir():
        raise InputError(f"{folder} is a file; {len(files)} files need a folder: give -o DIR", None)
    for name, data in files:
        write_atomic(Path(folder) / name, data)
