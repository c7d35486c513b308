"""Whether two or more synth trees print the same filter reports, byte for byte: the CLI's
``filter check --json``, ``check``, ``solve --json``, ``solve``, ``st`` and
``st --algorithm loop``, each ``st`` also with ``--xml`` (its file), on the bundled filters and
on bench families.

    python3 bench/filter_same.py --tree BEFORE --tree AFTER [--cases ring:4,8 chain:16 ...]
                                 [--bundled/--no-bundled] [--timeout 600] [--json FILE]

``BEFORE`` is typically ``git archive main | tar -x -C /tmp/before``. Every filter is
written once into one temporary folder and each tree runs there on the same relative
file names (so paths and provenance headers agree), the trees one after the other for
each command (interleaved: the load hits them alike). Each run's exit code, stdout,
stderr and written file are compared with the first tree's; the differing ones are
listed, the exit status is 1 if any differs. The CPU seconds of each tree (children's
user + system) are printed per case, for the record, not as a benchmark.
"""

from __future__ import annotations

import argparse
import hashlib
import json
import os
import resource
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(Path(__file__).resolve().parent))

from filter_scale import FAMILIES  # noqa: E402  (a sibling script, not a package)

DEFAULT_CASES = ("ring:4,8", "chain:16,64", "grid:16,32", "grid_edges:8,16,24")
"""The bench families compared by default (family:sizes)."""

COMMANDS: tuple[tuple[str, ...], ...] = (
    ("check", "--json"), ("check",), ("solve", "--json"), ("solve",),
    ("st", "-o", "out.st"), ("st", "--algorithm", "loop", "-o", "out.st"),
    ("st", "--xml", "-o", "out.st"), ("st", "--algorithm", "loop", "--xml", "-o", "out.st"))
"""The ``synth filter`` commands run on every filter (``out.st``: the file compared, PLCopen XML
with ``--xml``)."""


def bundled() -> list[Path]:
    """The ``.filter`` files the repository tracks."""
    listed = subprocess.run(["git", "-C", str(ROOT), "ls-files", "*.filter"], capture_output=True, text=True,
                            check=True).stdout.split()
    return [ROOT / p for p in listed]


def cases(specs: list[str], with_bundled: bool, folder: Path) -> list[str]:
    """Write every filter into ``folder``: their names relative to it."""
    names: list[str] = []
    if with_bundled:
        for path in bundled():
            name = path.relative_to(ROOT).as_posix().replace("/", "__")
            shutil.copyfile(path, folder / name)
            names.append(name)
    for spec in specs:
        family, _, sizes = spec.partition(":")
        for n in (int(x) for x in sizes.split(",")):
            name = f"{family}_{n}.filter"
            (folder / name).write_text(FAMILIES[family](n), encoding="utf-8")
            names.append(name)
    return names


def run(tree: Path, argv: list[str], folder: Path, timeout: float) -> tuple[str, float]:
    """A digest of one command's exit code, stdout, stderr and ``out.st``, and its CPU s."""
    out = folder / "out.st"
    out.unlink(missing_ok=True)
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    try:
        done = subprocess.run([sys.executable, "-m", "synth", "filter", *argv], capture_output=True, cwd=folder,
                              env=dict(os.environ, PYTHONPATH=str(tree)), timeout=timeout, check=False)
        parts = [str(done.returncode).encode(), done.stdout, done.stderr,
                 out.read_bytes() if out.exists() else b"(no file)"]
    except subprocess.TimeoutExpired:
        parts = [b"timeout"]
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    return hashlib.sha256(b"\0".join(hashlib.sha256(p).digest() for p in parts)).hexdigest(), cpu


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--tree", action="append", required=True, type=Path, help="a synth source tree (twice or more)")
    ap.add_argument("--cases", nargs="*", default=list(DEFAULT_CASES), help="family:sizes (default: %(default)s)")
    ap.add_argument("--no-bundled", dest="bundled", action="store_false", help="leave out the tracked .filter files")
    ap.add_argument("--timeout", type=float, default=600.0, help="seconds per command (default 600)")
    ap.add_argument("--json", metavar="FILE", help="also write every digest and CPU time as JSON")
    args = ap.parse_args()
    if len(args.tree) < 2:
        ap.error("give at least two --tree")
    trees = [t.resolve() for t in args.tree]
    rows, differing = [], 0
    with tempfile.TemporaryDirectory() as d:
        folder = Path(d)
        for name in cases(args.cases, args.bundled, folder):
            cpu = [0.0] * len(trees)
            for command in COMMANDS:
                argv = [command[0], name, *command[1:]]
                digests = []
                for i, tree in enumerate(trees):
                    digest, seconds = run(tree, argv, folder, args.timeout)
                    digests.append(digest)
                    cpu[i] += seconds
                same = len(set(digests)) == 1
                differing += not same
                rows.append({"filter": name, "command": " ".join(argv), "same": same, "digests": digests})
                if not same:
                    print(f"DIFFERENT  filter {' '.join(argv)}", flush=True)
            print(f"{name:<48} " + "  ".join(f"{c:7.2f} s" for c in cpu), flush=True)
    print(f"{len(rows)} runs per tree, {differing} differing")
    if args.json:
        Path(args.json).write_text(json.dumps({"trees": [str(t) for t in trees], "runs": rows}, indent=2) + "\n",
                                   encoding="utf-8")
    return 1 if differing else 0


if __name__ == "__main__":
    sys.exit(main())
