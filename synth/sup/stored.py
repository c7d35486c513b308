"""The exact reach grids of plants whose elements read each other, kept on disk by content.

Computing them (:func:`synth.plant.closure.backward_closures`, one grid per constraint
term) is the largest part of compiling such a station's constraints: 0.15 CPU s of the
0.6 s that ``validate`` takes on the four-cylinder station. Repeated runs on the same
plant and constraints read them back from ``$XDG_CACHE_HOME/synth/grids`` (by default
``~/.cache/synth/grids``).

The key is a SHA-256 of everything the grids depend on: synth's version, this file
format, the source of the closure computation, each element automaton's arrays (states,
moves, guards) and each term's per-element factors. A file is used only when its header
repeats the key, the grids' number and shape, and the SHA-256 of its payload: a partial or
damaged file is ignored (and written again), never read as grids. Files are written to a
temporary name and renamed into place. ``SYNTH_NO_CACHE=1`` reads and writes nothing.

Example
-------
>>> import os, tempfile
>>> from synth.plant.rules_check import load_rules
>>> from synth.plant.composition import plant, _plants
>>> before = dict(os.environ)
>>> os.environ["XDG_CACHE_HOME"] = tempfile.mkdtemp(); os.environ.pop(OFF, None) and None
>>> p = plant(load_rules(_plants("tri_boxes.rules")))
>>> g = np.zeros(p.shape, dtype=bool)
>>> k = key(p, [((0, np.ones(p.shape[0], dtype=bool)),)])
>>> load(k, 1, p.shape) is None
True
>>> store(k, [g]); [x.shape for x in load(k, 1, p.shape)] == [p.shape]
True
>>> os.environ.clear(); os.environ.update(before)
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import Callable, Sequence

import numpy as np

from synth.plant.composition import Plant

__all__ = ["FORMAT", "OFF", "folder", "key", "load", "store", "kept"]

FORMAT = 1
"""The file format's number (part of the key)."""

OFF = "SYNTH_NO_CACHE"
"""An environment variable: set (to anything but ``0`` or nothing), no grid is read or written."""

_MAGIC = b"synth-grids"


def folder() -> Path | None:
    """``$XDG_CACHE_HOME/synth/grids`` (``~/.cache/synth/grids``); None when the cache is
    off or there is no home to keep it in."""
    if os.environ.get(OFF, "") not in ("", "0"):
        return None
    base = os.environ.get("XDG_CACHE_HOME") or (os.path.join(os.path.expanduser("~"), ".cache")
                                                if os.path.expanduser("~") != "~" else "")
    return Path(base) / "synth" / "grids" if base else None


def key(p: Plant, terms: Sequence[Sequence[tuple[int, np.ndarray]]]) -> str:
    """The SHA-256 naming the reach grids of ``terms`` (per-element factors) in plant ``p``."""
    import hashlib

    from synth.plant import closure
    from synth.version import version

    h = hashlib.sha256()

    def put(*parts: object) -> None:
        for part in parts:
            if isinstance(part, np.ndarray):
                h.update(f"{part.dtype.str}{part.shape}".encode())
                h.update(np.ascontiguousarray(part).tobytes())
            else:
                h.update(repr(part).encode("utf-8"))
            h.update(b"\0")

    put(version(), FORMAT, Path(closure.__file__).read_bytes(), p.shape)
    for e in p.elements:
        guards = e.guards if e.guards is not None else np.zeros(0, dtype=bool)
        put(e.name, e.variables, e.reads, e.initial, e.codes, e.src, e.dst, e.var, e.controllable, guards)
    for factors in terms:
        put(len(factors), *(x for a, vec in factors for x in (a, vec)))
    return h.hexdigest()


def _header(k: str, n: int, shape: tuple[int, ...], digest: str) -> bytes:
    return b" ".join([_MAGIC, str(FORMAT).encode(), k.encode(), str(n).encode(),
                      ",".join(map(str, shape)).encode(), digest.encode()]) + b"\n"


def load(k: str, n: int, shape: tuple[int, ...]) -> list[np.ndarray] | None:
    """The ``n`` grids stored under key ``k``, or None (no cache, no file, or a file that
    is not whole)."""
    import hashlib

    where = folder()
    if where is None:
        return None
    try:
        data = (where / f"{k}.bin").read_bytes()
    except OSError:
        return None
    head, sep, payload = data.partition(b"\n")
    size = int(np.prod(shape, dtype=np.int64))
    if not sep or len(payload) != (n * size + 7) // 8:
        return None
    if head + b"\n" != _header(k, n, shape, hashlib.sha256(payload).hexdigest()):
        return None
    flat = np.unpackbits(np.frombuffer(payload, dtype=np.uint8), count=n * size).astype(bool)
    return [flat[i * size:(i + 1) * size].reshape(shape) for i in range(n)]


def store(k: str, grids: Sequence[np.ndarray]) -> None:
    """Keep ``grids`` under key ``k`` (written whole or not at all; an unwritable cache is skipped)."""
    import hashlib
    import tempfile

    where = folder()
    if where is None or not grids:
        return
    payload = np.packbits(np.concatenate([g.reshape(-1) for g in grids])).tobytes()
    data = _header(k, len(grids), tuple(grids[0].shape), hashlib.sha256(payload).hexdigest()) + payload
    try:
        where.mkdir(parents=True, exist_ok=True)
        fd, tmp = tempfile.mkstemp(prefix=f".{k}.", suffix=".tmp", dir=where)
    except OSError:
        return
    try:
        with os.fdopen(fd, "wb") as fh:
            fh.write(data)
        os.replace(tmp, where / f"{k}.bin")
    except OSError:
        try:
            os.unlink(tmp)
        except OSError:
            pass


def kept(p: Plant, terms: Sequence[Sequence[tuple[int, np.ndarray]]], compute: Callable[[], list[np.ndarray]]) -> list[np.ndarray]:
    """The reach grids of ``terms``: read from the cache, else computed by ``compute`` and stored."""
    if folder() is None:
        return compute()
    k = key(p, terms)
    grids = load(k, len(terms), p.shape)
    if grids is None:
        grids = compute()
        store(k, grids)
    return grids
