"""``synth import`` on every ``*.xml`` under a folder: what real PLCopen files (IDE exports,
example projects) import, what is refused and for which construct, and no traceback.

    python3 bench/import_corpus.py DIR [--json FILE]

For each file (a first-level folder of DIR is counted as one repository): ``imported`` (every SFC POU read, the ``.g7`` parsed back), ``no SFC`` (a
project without an SFC POU: nothing to import), ``refused`` with the first error (a located
message naming the construct), or ``TRACEBACK``. The files are third-party: fetch them
locally (never into this repository) and give their folder.
"""

from __future__ import annotations

import argparse
import json
import sys
import traceback
from collections import Counter
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

from synth.codegen.plcopen.importer import import_sfc  # noqa: E402
from synth.errors import SynthError  # noqa: E402
from synth.grafcet.language_check import parse_grafcet  # noqa: E402


def one(path: Path) -> dict:
    data = path.read_bytes()
    try:
        text = import_sfc(data, str(path))
        parse_grafcet(text, str(path.with_suffix(".g7")))
        return {"file": str(path), "outcome": "imported", "detail": ""}
    except SynthError as err:
        first = err.render().splitlines()[0] if hasattr(err, "render") else str(err)
        outcome = "no SFC" if "no POU with an SFC body" in first or "not a PLCopen" in first else "refused"
        return {"file": str(path), "outcome": outcome, "detail": first}
    except Exception:  # noqa: BLE001 - what this benchmark counts
        return {"file": str(path), "outcome": "TRACEBACK", "detail": traceback.format_exc().splitlines()[-1]}


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("folder", type=Path)
    ap.add_argument("--json", type=Path)
    args = ap.parse_args()
    rows = [one(p) for p in sorted(args.folder.rglob("*.xml"))]
    for r in rows:
        print(f"{r['outcome']:<10} {r['file']}  {r['detail']}")
    per_repo: dict[str, Counter] = {}
    for path, r in zip(sorted(args.folder.rglob("*.xml")), rows):
        repo = path.relative_to(args.folder).parts[0] if len(path.relative_to(args.folder).parts) > 1 else "."
        per_repo.setdefault(repo, Counter())[r["outcome"]] += 1
    for repo, c in sorted(per_repo.items()):
        print(f"repository {repo}: " + ", ".join(f"{k} {c[k]}" for k in ("imported", "refused", "no SFC", "TRACEBACK")))
    counts = Counter(r["outcome"] for r in rows)
    print("total " + ", ".join(f"{k}: {counts[k]}" for k in ("imported", "refused", "no SFC", "TRACEBACK")))
    if args.json:
        args.json.write_text(json.dumps(rows, indent=1) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
