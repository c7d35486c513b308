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
