"""Shared test helpers: repository paths and a CLI runner."""

from __future__ import annotations

import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
if str(ROOT) not in sys.path:
    sys.path.insert(0, str(ROOT))

from synth.cli.main import main  # noqa: E402


@pytest.fixture
def root() -> Path:
    return ROOT


@pytest.fixture
def cli(capsys):
    """Run ``synth ARGS...`` in-process; returns (exit code, stdout, stderr)."""

    def run(*args: str) -> tuple[int, str, str]:
        code = main([str(a) for a in args])
        out = capsys.readouterr()
        return code, out.out, out.err

    return run


# ---------------------------------------------------------------- the real compiler's tests, counted
# The tests that compile generated ST with MATIEC's iec2c (README, "The real-compiler tests") are
# skipped where it is missing; the session's summary says how many ran, so a CI log shows it.
REAL_COMPILER = "real_compiler"
_counts = {"ran": 0, "skipped": 0}


def pytest_collection_modifyitems(items) -> None:
    for item in items:
        reasons = " ".join(str(m.kwargs.get("reason", "")) for m in item.iter_markers("skipif"))
        if "iec2c" in reasons or "compiled_program" in item.name:
            item.user_properties.append((REAL_COMPILER, "1"))


def pytest_runtest_logreport(report) -> None:
    if (REAL_COMPILER, "1") not in getattr(report, "user_properties", ()):
        return
    if report.skipped and report.when in ("setup", "call"):
        _counts["skipped"] += 1
    elif report.when == "call":
        _counts["ran"] += 1


def pytest_terminal_summary(terminalreporter) -> None:
    if not any(_counts.values()):
        return
    line = f"real-compiler tests (MATIEC's iec2c): {_counts['ran']} ran, {_counts['skipped']} skipped"
    if _counts["skipped"]:
        line += " (iec2c or gcc is missing: see README, \"The real-compiler tests\")"
    terminalreporter.write_line(line)
