"""Results cached by what produced them: the content hash of every file a job reads (the
files it names and those they ``use``), synth's version, the job's kind, name, options and
mutant. A changed byte in any of them is another key, so the cache never returns a result
for changed inputs; an unchanged job is not recomputed.

The cache lives in ``$XDG_CACHE_HOME/synth/line`` (``~/.cache/synth/line``) or in
``--cache DIR``; each result is one JSON file, written atomically.

Example
-------
>>> import tempfile, pathlib
>>> from synth.line.jobs import Job, JobKind
>>> d = pathlib.Path(tempfile.mkdtemp())
>>> _ = (d / "g.g7").write_text("grafcet G { initial step 0 }")
>>> j = with_digests(Job("s", JobKind.ST_CHECK, "st", grafcet=str(d / "g.g7")))
>>> c = Cache(d / "cache")
>>> c.get(j) is None
True
>>> c.put(j, {"verdict": "pass"}); c.get(j)
{'verdict': 'pass'}
>>> _ = (d / "g.g7").write_text("grafcet G { initial step 1 }")
>>> c.get(with_digests(j)) is None
True
"""

from __future__ import annotations

import dataclasses
import hashlib
import json
import os
from pathlib import Path
from typing import Any

from synth.line.jobs import Job, files_read

__all__ = ["Cache", "default_cache_dir", "digest", "with_digests", "job_key"]


def default_cache_dir() -> Path:
    """``$XDG_CACHE_HOME/synth/line``, or ``~/.cache/synth/line``."""
    base = os.environ.get("XDG_CACHE_HOME") or str(Path.home() / ".cache")
    return Path(base) / "synth" / "line"


def digest(path: str) -> str:
    """SHA-256 of ``path``'s contents and of every file it uses (names and contents);
    a missing file hashes as missing."""
    h = hashlib.sha256()
    for f in files_read(path):
        h.update(f.encode("utf-8") + b"\0")
        try:
            h.update(Path(f).read_bytes())
        except OSError:
            h.update(b"\0missing\0")
        h.update(b"\0")
    return h.hexdigest()


def with_digests(job: Job) -> Job:
    """``job`` with the digests of the files it reads, as they are now."""
    return dataclasses.replace(job, digests=tuple((f, digest(f)) for f in job.files))


def job_key(job: Job) -> str:
    """The cache key: synth's version, what the job is, and the digests of what it reads."""
    from synth.version import version

    fields = {"synth": version(), "kind": str(job.kind), "station": job.station, "name": job.name,
              "files": [job.plant, job.grafcet, job.filter], "options": list(job.options),
              "expect": None if job.expect is None else str(job.expect), "mutant": job.mutant,
              "digests": list(job.digests)}
    return hashlib.sha256(json.dumps(fields, sort_keys=True).encode("utf-8")).hexdigest()


class Cache:
    """A folder of results, one JSON file per key; ``hits`` and ``misses`` count the lookups."""

    def __init__(self, folder: str | Path | None) -> None:
        self.folder = Path(folder) if folder is not None else default_cache_dir()
        self.hits = self.misses = 0

    def _path(self, job: Job) -> Path:
        key = job_key(job)
        return self.folder / key[:2] / f"{key}.json"

    def get(self, job: Job) -> dict[str, Any] | None:
        try:
            data = json.loads(self._path(job).read_text(encoding="utf-8"))
        except (OSError, ValueError):
            self.misses += 1
            return None
        self.hits += 1
        return data if isinstance(data, dict) else None

    def put(self, job: Job, result: dict[str, Any]) -> None:
        from synth.output.files import write_atomic

        write_atomic(self._path(job), json.dumps(result, sort_keys=True, ensure_ascii=False))
