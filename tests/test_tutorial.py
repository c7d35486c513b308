"""docs/tutorial.md, "Your first station", run as written: its files written in a fresh folder
in the page's order (a later version of a file replaces the earlier), each `$ synth …`
command run, its output (standard output, then standard error) equal to the one shown but
for the seconds a run took, and its exit code the `(exit N)` shown (0 when none)."""

from __future__ import annotations

import re
import shlex

from conftest import ROOT
from synth.cli.main import main

DOC = (ROOT / "docs" / "tutorial.md").read_text(encoding="utf-8")
FILE = re.compile(r"^`([\w.]+)`:\n```\w*\n(.*?)^```$", re.M | re.S)
CONSOLE = re.compile(r"^```console\n(.*?)^```$", re.M | re.S)
SECONDS = re.compile(r" in \d+\.\d+ s")


def _steps() -> list[tuple[int, str, str]]:
    """(position, "file" or "console", text) in the page's order."""
    steps = [(m.start(), "file", m.group(1) + "\n" + m.group(2)) for m in FILE.finditer(DOC)]
    steps += [(m.start(), "console", m.group(1)) for m in CONSOLE.finditer(DOC)]
    return sorted(steps)


def _commands(block: str) -> list[tuple[str, list[str], int]]:
    """(command, expected lines, exit code) of one console block."""
    out: list[tuple[str, list[str], int]] = []
    for line in block.rstrip("\n").split("\n"):
        if line.startswith("$ "):
            out.append((line[2:], [], 0))
        else:
            out[-1][1].append(line)
    fixed = []
    for cmd, lines, _ in out:
        code = 0
        if lines and re.fullmatch(r"\(exit \d+\)", lines[-1]):
            code = int(lines.pop()[6:-1])
        fixed.append((cmd, lines, code))
    return fixed


def test_the_page_has_its_steps():
    kinds = [k for _, k, _ in _steps()]
    assert kinds.count("file") == 3 and kinds.count("console") == 8
    assert sum(len(_commands(t)) for _, k, t in _steps() if k == "console") == 11


def test_the_tutorial_runs_as_written(tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    ran = []
    for _, kind, text in _steps():
        if kind == "file":
            name, body = text.split("\n", 1)
            (tmp_path / name).write_text(body, encoding="utf-8")
            continue
        for cmd, lines, code in _commands(text):
            argv = shlex.split(cmd)
            assert argv[0] == "synth"
            got = main(argv[1:])
            captured = capsys.readouterr()
            shown = SECONDS.sub(" in N s", "\n".join(lines) + ("\n" if lines else ""))
            assert (got, SECONDS.sub(" in N s", captured.out + captured.err)) == (code, shown), cmd
            ran.append(cmd)
    assert len(ran) == 11
    assert (tmp_path / "station.st").read_text().count("FUNCTION_BLOCK FB_station_Filter") == 1
