"""Every bundled Grafcet on the PLC against ``synth run --semantics sfc``, with more sequences
than the test (``tests/test_sfc_beremiz.py``, whose harness this runs): exported by ``synth
sfc``, built by Beremiz's generator, compiled by MATIEC's ``iec2c`` and gcc, run on seeded
random input sequences. One line per Grafcet (scans played, transitions fired, sequences that
differ) and every first difference.

    SYNTH_BEREMIZ=... SYNTH_BEREMIZ_PYTHON=... SYNTH_IEC2C=... python bench/sfc_on_plc.py [--seeds 100]
"""

from __future__ import annotations

import argparse
import sys
import tempfile
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
for _p in (str(ROOT), str(ROOT / "tests")):
    if _p not in sys.path:
        sys.path.insert(0, _p)


def main(argv: list[str] | None = None) -> int:
    from beremiz import find_beremiz
    from iec2c import find_iec2c
    from test_sfc_beremiz import run_on_plc, scans_for
    from test_sfc_meaning import GRAFCETS

    from synth.grafcet.language_check import load_grafcet

    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--seeds", type=int, default=100, help="random sequences per Grafcet (default 100)")
    args = ap.parse_args(argv)
    if find_beremiz() is None or find_iec2c() is None:
        print("needs Beremiz (SYNTH_BEREMIZ, SYNTH_BEREMIZ_PYTHON) and iec2c (SYNTH_IEC2C or PATH)", file=sys.stderr)
        return 2
    agree = scans = 0
    with tempfile.TemporaryDirectory() as tmp:
        for path in GRAFCETS:
            g = load_grafcet(path)
            out = run_on_plc(g, Path(tmp) / path.stem, range(args.seeds), scans_for(g))
            scans += out.scans
            agree += not out.differences
            print(f"{path.name}: {out.scans} scans, {len(out.fired)}/{len(g.transitions)} transitions fired, "
                  f"{len(out.differences)}/{args.seeds} sequences differ")
            for d in out.differences:
                print("  " + d.text())
    print(f"{agree} of {len(GRAFCETS)} Grafcets agree over {scans} scans")
    return 0 if agree == len(GRAFCETS) else 1


if __name__ == "__main__":
    sys.exit(main())
