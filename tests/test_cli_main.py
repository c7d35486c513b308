"""``synth`` with no arguments prints the command list (on stderr) and exits 2;
``synth --help`` prints it on stdout and exits 0."""

from __future__ import annotations

import subprocess
import sys

import pytest

from conftest import ROOT

COMMANDS = ("plant", "sup", "validate", "filter", "lib")


def test_synth_alone_lists_the_commands(cli):
    code, out, err = cli()
    assert code == 2 and out == ""
    assert err.startswith("usage: synth")
    assert all(c in err for c in COMMANDS), err


def test_synth_alone_as_a_program():
    run = subprocess.run([sys.executable, "-m", "synth"], cwd=ROOT, capture_output=True, text=True)
    assert run.returncode == 2
    assert "validate" in run.stderr and "usage: synth" in run.stderr


def test_help_still_exits_0(capsys):
    from synth.cli.main import main

    with pytest.raises(SystemExit) as e:
        main(["--help"])
    assert e.value.code == 0
    out = capsys.readouterr().out
    assert all(c in out for c in COMMANDS), out


def test_validate_help_explains_the_words_of_a_state(capsys):
    """Sit, E, Z, ORD and PROH are explained in ``validate --help`` as in the report's legend."""
    from synth.cli.main import main

    with pytest.raises(SystemExit) as done:
        main(["validate", "--help"])
    assert done.value.code == 0
    out = capsys.readouterr().out
    for term in ("Sit ", "E ", "Z ", "ORD ", "PROH "):
        assert f"\n  {term}" in out
    assert "SUP forbids" in out and "SUP authorises" in out


def test_the_command_table_names_what_each_module_registers() -> None:
    """``main.COMMANDS`` (which module to load for a command line's first word) matches
    what the modules register, in the order of ``synth --help``."""
    import argparse
    from importlib import import_module

    from synth.cli.main import COMMANDS, build_parser

    for module, names in COMMANDS.items():
        sub = argparse.ArgumentParser().add_subparsers()
        import_module(f"synth.cli.{module}").register(sub)
        assert tuple(sub.choices) == names, module
    assert tuple(build_parser().commands.choices) == tuple(n for names in COMMANDS.values() for n in names)


@pytest.mark.parametrize("argv", [
    ["validate", "--help"], ["filter", "verify", "--help"], ["check", "--help"], ["st", "--help"],
    ["validate", "--engin", "x"], ["filter", "chek"], ["validate"], ["sup", "--max-states", "x", "a.rules"],
])
def test_a_command_parsed_alone_as_among_all(argv, capsys) -> None:
    """The parser of the command a line names (its arguments alone declared) prints the same
    help and the same errors as the parser of every command."""
    from synth.cli.main import build_parser, parse

    def outcome(parser) -> tuple[object, str, str]:
        try:
            args = parse(parser, argv)
            code: object = sorted((k, str(v)) for k, v in vars(args).items() if k != "root_parser")
        except SystemExit as e:
            code = e.code
        out, err = capsys.readouterr()
        return code, out, err

    alone, among = outcome(build_parser(argv[0])), outcome(build_parser())
    assert alone == among
    assert alone[0] in (0, 2)  # each line above asks for help or is wrong


BLAS = """
import atexit, os, sys
sys.argv = ["synth", "validate", "grafcets/tri.g7", "--plant", "plants/tri.rules"]
def report():
    threads = [line.split()[1] for line in open("/proc/self/status") if line.startswith("Threads:")]
    print("BLAS", os.environ.get("OPENBLAS_NUM_THREADS"), "numpy" in sys.modules, threads)
atexit.register(report)
from synth.cli.main import entry
entry()
"""


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="reads /proc/self/status")
@pytest.mark.parametrize("chosen, expected", [(None, "1"), ("3", "3")])
def test_the_console_script_runs_numpy_on_one_blas_thread_unless_told(chosen, expected):
    """numpy's OpenBLAS would start a spinning thread per core at import (``one_blas_thread``):
    the command runs on its one thread; a value the user set is kept."""
    env = {k: v for k, v in __import__("os").environ.items() if k != "OPENBLAS_NUM_THREADS"}
    if chosen is not None:
        env["OPENBLAS_NUM_THREADS"] = chosen
    run = subprocess.run([sys.executable, "-c", BLAS], cwd=ROOT, capture_output=True, text=True,
                         env=env)
    assert run.returncode == 0, run.stderr
    last = run.stdout.strip().splitlines()[-1]
    assert last.startswith(f"BLAS {expected} True ["), last
    if chosen is None:
        assert last == "BLAS 1 True ['1']"
