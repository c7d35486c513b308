"""Long runs draw one live line on a terminal (a pseudo-terminal here) and nothing when their
standard error is a pipe or with --quiet: ``st --check`` and ``filter verify``."""

from __future__ import annotations

import os
import subprocess
import sys

import pytest

from conftest import ROOT

pytestmark = pytest.mark.skipif(not hasattr(os, "openpty"), reason="no pseudo-terminals here")

CYLINDER = """use "lib/single_acting.rules"
element V1 = single_acting(AVANCER=Q1, v0=v10, v1=v11)
constraint REST "push only from rest": ↑Q1 & !v10 = 0
"""
FILTER = 'inputs v10, v11\noutputs Q1\nsafety FROM_REST "push only from rest": ↑Q1 & !v10\n'


def _run(argv: list[str], tty: bool) -> tuple[int, str, str]:
    """``synth ARGV`` with standard error on a pseudo-terminal (``tty``) or a pipe:
    (exit code, standard output, what standard error received)."""
    env = dict(os.environ, PYTHONPATH=str(ROOT))
    cmd = [sys.executable, "-m", "synth", *argv]
    if not tty:
        done = subprocess.run(cmd, cwd=ROOT, env=env, capture_output=True, text=True, timeout=300)
        return done.returncode, done.stdout, done.stderr
    master, slave = os.openpty()
    proc = subprocess.Popen(cmd, cwd=ROOT, env=env, stdout=subprocess.PIPE, stderr=slave, text=True)
    os.close(slave)
    chunks = []
    while True:
        try:
            data = os.read(master, 4096)
        except OSError:  # the other side closed (Linux: EIO)
            break
        if not data:
            break
        chunks.append(data)
    out = proc.stdout.read() if proc.stdout else ""
    code = proc.wait(timeout=300)
    os.close(master)
    return code, out, b"".join(chunks).decode("utf-8", errors="replace")


@pytest.fixture()
def loop(tmp_path):
    (tmp_path / "c.rules").write_text(CYLINDER)
    (tmp_path / "c.filter").write_text(FILTER)
    return ["filter", "verify", str(tmp_path / "c.filter"), "--plant", str(tmp_path / "c.rules"), "--any-control",
            "--engine", "explicit"]


def test_filter_verify_live_line_on_a_terminal(loop):
    code, out, err = _run(loop, tty=True)
    assert code == 0 and "safe:" in out
    assert "\r\x1b[K[" in err and "s] closed loop: " in err and " cycles/s), level 1" in err
    assert err.endswith("\r\x1b[K")  # the line is erased at the end: nothing left on the terminal


def test_symbolic_filter_verify_live_line(loop):
    argv = [*loop[:-1], "symbolic"]
    code, out, err = _run(argv, tty=True)
    assert code == 0 and "safe:" in out
    assert "s] closed loop (symbolic): level 1, " in err and " BDD nodes" in err
    assert _run(argv, tty=False)[2] == ""


def test_filter_verify_silent_when_piped_or_quiet(loop):
    assert _run(loop, tty=False)[2] == ""
    code, out, err = _run([*loop, "--quiet"], tty=True)
    assert code == 0 and "safe:" in out and err == ""


def test_st_check_live_line_on_a_terminal():
    argv = ["st", "--check", str(ROOT / "grafcets/timers.g7"), "--depth", "3"]
    code, out, err = _run(argv, tty=True)
    assert code == 0 and "0 mismatches" in out
    assert "s] ST against synth run: " in err and "cycles/s), 0 mismatches" in err
    assert err.endswith("\r\x1b[K")
    piped = _run(argv, tty=False)
    assert piped[0] == 0 and piped[1] == out and piped[2] == ""


@pytest.mark.parametrize("argv", [["filter", "check", "plants/tri.filter"], ["filter", "solve", "plants/loop_a.filter"],
                                  ["import", "tests/data/plcopen/beremiz_counter.xml"]])
def test_stage_lines_of_check_solve_import(argv):
    """Shorter runs name their stage on the line (and erase it); piped, nothing."""
    code, out, err = _run(argv, tty=True)
    piped = _run(argv, tty=False)
    assert (piped[0], piped[1]) == (code, out)
    assert "\r\x1b[K[" in err
    # the live line drawn and erased, and else exactly what a pipe receives (the terminal
    # turns \n into \r\n)
    import re

    assert re.sub(r"\r\x1b\[K(\[ *\d+\.\ds\] [^\r\n]*)?", "", err) == piped[2].replace("\n", "\r\n")
    assert "\x1b" not in piped[2] and "\r" not in piped[2]


def test_ctrl_c_during_a_long_run_says_how_far_it_went():
    """SIGINT once the live line shows the closed loop's first levels: the line is erased,
    then one line says how far the run went, exit 130, no traceback."""
    import re
    import signal

    env = dict(os.environ, PYTHONPATH=str(ROOT))
    master, slave = os.openpty()
    # three events per cycle: 767 224 cycles (about 5 s), seconds of work left when the first level shows
    # (at one event the loop ends within a second, and a loaded machine may deliver the signal after it)
    proc = subprocess.Popen([sys.executable, "-m", "synth", "filter", "verify", "plants/four_cylinders.filter",
                             "--plant", "plants/four_cylinders.rules", "--any-control", "--engine", "explicit",
                             "--events-per-cycle", "3"],
                            cwd=ROOT, env=env, stdout=subprocess.PIPE, stderr=slave)
    os.close(slave)
    seen = b""
    while b"closed loop: " not in seen:
        seen += os.read(master, 4096)
    proc.send_signal(signal.SIGINT)
    while True:
        try:
            data = os.read(master, 4096)
        except OSError:
            break
        if not data:
            break
        seen += data
    assert proc.wait(timeout=60) == 130
    os.close(master)
    tail = seen.decode().rsplit("\r\x1b[K", 1)[1]
    assert re.fullmatch(r"interrupted after \d+\.\d s: closed loop: \d+ states, \d+ cycles \(\d+ cycles/s\), "
                        r"level \d+\r\n", tail), tail
