"""``synth import`` on every ``*.xml`` under a folder: what real PLCopen files (IDE exports,
example projects) import, what is refused and for which construct, no traceback, and no
silent change.

    python3 bench/import_corpus.py DIR [--json FILE]

For each file (a first-level folder of DIR is counted as one repository): ``imported`` (every SFC POU read, the ``.g7`` parsed back), ``no SFC`` (a
project without an SFC POU: nothing to import), ``refused`` with the first error (a located
message naming the construct), or ``TRACEBACK``. For an imported file, every meaning-carrying
item of its SFC POUs (action qualifiers, assignments of action bodies, selection divergences'
priorities, block calls, timers: :mod:`synth.codegen.plcopen.meaning`) is matched to the
``.g7`` or to a located warning (:mod:`synth.codegen.plcopen.accounting`); an item matched by
neither is a **silent change**, listed as ``file:line: what``. The files are third-party:
fetch them locally (never into this repository) and give their folder.
"""

from __future__ import annotations

import argparse
import json
import re
import sys
import traceback
from collections import Counter
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent.parent))

from synth.codegen.plcopen.accounting import account_import  # noqa: E402
from synth.codegen.plcopen.project import list_pous  # noqa: E402
from synth.errors import SynthError  # noqa: E402

OUTCOMES = ("imported", "refused", "no SFC", "TRACEBACK")


def construct(message: str) -> str:
    """A refusal's message without its location, names and quoted texts: the construct refused."""
    text = message.split(": error: ", 1)[-1]
    text = re.sub(r"^[\w.]+ := [^;]*?;?(?= in )", "an assignment", text)
    text = re.sub(r"'[^']*'|\([^)]*\)|\b\w*[\d_.]\w*\b", "…", text)
    return " ".join(text.split(":")[0].split()[:14])


def one(path: Path) -> dict:
    data = path.read_bytes()
    row: dict = {"file": str(path), "outcome": "", "detail": "", "sfc_pous": 0, "items": 0, "silent": []}
    try:
        row["sfc_pous"] = sum(1 for s in list_pous(data, str(path)) if s.language == "SFC")
        done = account_import(data, str(path))
        row.update(outcome="imported", items=len(done.items), silent=[c.text() for c in done.silent])
    except SynthError as err:
        first = err.render().splitlines()[0] if hasattr(err, "render") else str(err)
        outcome = "no SFC" if "no POU with an SFC body" in first or "not a PLCopen" in first else "refused"
        row.update(outcome=outcome, detail=first)
    except Exception:  # noqa: BLE001 - what this benchmark counts
        row.update(outcome="TRACEBACK", detail=traceback.format_exc().splitlines()[-1])
    return row


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("folder", type=Path)
    ap.add_argument("--json", type=Path)
    args = ap.parse_args()
    paths = sorted(args.folder.rglob("*.xml"))
    rows = [one(p) for p in paths]
    for r in rows:
        print(f"{r['outcome']:<10} {r['file']}  {r['detail']}")
    per_repo: dict[str, Counter] = {}
    for path, r in zip(paths, rows):
        parts = path.relative_to(args.folder).parts
        c = per_repo.setdefault(parts[0] if len(parts) > 1 else ".", Counter())
        c[r["outcome"]] += 1
        c.update({"files": 1, "SFC POUs": r["sfc_pous"], "items": r["items"], "silent changes": len(r["silent"])})
    keys = ("files", "SFC POUs", *OUTCOMES, "items", "silent changes")
    for repo, c in sorted(per_repo.items()):
        print(f"repository {repo}: " + ", ".join(f"{k} {c[k]}" for k in keys))
    total = sum(per_repo.values(), Counter())
    print("total " + ", ".join(f"{k}: {total[k]}" for k in keys))
    refused = Counter(construct(r["detail"]) for r in rows if r["outcome"] == "refused")
    for text, n in refused.most_common():
        print(f"refused {n}: {text}")
    silent = [s for r in rows for s in r["silent"]]
    print(f"silent changes: {len(silent)}")
    for s in silent:
        print("  " + s)
    if args.json:
        args.json.write_text(json.dumps(rows, indent=1) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
