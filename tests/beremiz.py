"""Beremiz's own PLCopen loader for the tests: its ``PLCControler`` opens an XML project and
generates the IEC 61131-3 program (SFC as textual ``STEP``/``TRANSITION``/``ACTION``) that
Beremiz hands to MATIEC (issue 22).

Beremiz is third-party (GPL, wxPython GUI): it is never committed nor installed by synth.
Name a checkout in ``SYNTH_BEREMIZ`` and a Python that can import it headless (its
``fake_wx``; lxml, numpy, matplotlib, zeroconf, click) in ``SYNTH_BEREMIZ_PYTHON`` to run the
tests that need it; they are skipped otherwise.
"""

from __future__ import annotations

import os
import subprocess
from pathlib import Path

__all__ = ["find_beremiz", "beremiz_program"]

_SCRIPT = """
import sys
sys.path.insert(0, sys.argv[1])
import fake_wx  # noqa: F401  (Beremiz's stand-in for wxPython, as its CLI uses)
import ProjectController  # noqa: F401  (imported first, as Beremiz_cli does)
from PLCControler import PLCControler
c = PLCControler()
error = c.OpenXMLFile(sys.argv[2])
if error:
    print("OPEN ERROR", error, file=sys.stderr)
    sys.exit(3)
program, errors, warnings = c.GenerateProgram(sys.argv[3])
if errors or program is None:
    print("GENERATE ERROR", errors, file=sys.stderr)
    sys.exit(4)
for w in warnings:
    print("WARNING", w, file=sys.stderr)
"""


def find_beremiz() -> tuple[str, Path] | None:
    """(python, checkout) when Beremiz is available here, else None."""
    home, python = os.environ.get("SYNTH_BEREMIZ"), os.environ.get("SYNTH_BEREMIZ_PYTHON")
    if not home or not python or not (Path(home) / "PLCControler.py").exists():
        return None
    return python, Path(home)


def beremiz_program(xml: Path, out: Path) -> subprocess.CompletedProcess[str]:
    """Open ``xml`` with Beremiz's loader and write the program it generates to ``out``."""
    found = find_beremiz()
    assert found is not None, "Beremiz is not available"
    python, home = found
    return subprocess.run([python, "-c", _SCRIPT, str(home), str(xml), str(out)], capture_output=True, text=True,
                          timeout=300, cwd=home)
