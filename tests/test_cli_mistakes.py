"""The command line names the mistake: an unknown option or command with the closest valid
ones, a file that cannot be read or written said as such, a crash as a bug in synth (exit 3,
never 1), Ctrl-C as exit 130 with what was reached; ``--eventually`` and its alias."""

from __future__ import annotations

import os
import re
import subprocess
import sys

import pytest

from conftest import ROOT
from synth.cli.main import main


def _argparse_error(capsys, *argv: str) -> tuple[int, str]:
    with pytest.raises(SystemExit) as e:
        main(list(argv))
    return int(e.value.code), capsys.readouterr().err.splitlines()[-1]


def test_unknown_option_is_named_with_the_closest(capsys):
    code, last = _argparse_error(capsys, "validate", "grafcets/tri.g7", "--plant", "plants/tri.rules", "--jsn")
    assert code == 2
    assert last == "synth validate: error: unknown option '--jsn'; did you mean '--json' or '--junit'?"


def test_unknown_option_of_a_filter_subcommand(capsys):
    code, last = _argparse_error(capsys, "filter", "check", "plants/tri.filter", "--plnt", "plants/tri.rules")
    assert code == 2
    assert last == "synth filter check: error: unknown option '--plnt'; did you mean '--plant' or '--junit'?"


def test_unknown_option_far_from_any(capsys):
    code, last = _argparse_error(capsys, "lib", "--zzzzzz")
    assert (code, last) == (2, "synth lib: error: unknown option '--zzzzzz'")
    code, last = _argparse_error(capsys, "lib", "extra")
    assert (code, last) == (2, "synth lib: error: unexpected argument 'extra'")


def test_command_typo(capsys):
    code, last = _argparse_error(capsys, "validat", "x.g7")
    assert code == 2
    assert last == ("synth: error: unknown command 'validat'; did you mean 'validate'? (commands: plant, sup, ass, "
                    "run, validate, filter, st, sfc, import, commission, check, mutate, lib, completion)")


def test_subcommand_typo(capsys):
    code, last = _argparse_error(capsys, "filter", "chek", "x.filter")
    assert code == 2
    assert last == ("synth filter: error: unknown subcommand 'chek'; did you mean 'check'? "
                    "(subcommands: check, solve, st, run, verify, from-rules)")


def test_choice_typo(capsys):
    code, last = _argparse_error(capsys, "validate", "g.g7", "--plant", "p.rules", "--engine", "symbolc")
    assert code == 2
    assert last == ("synth validate: error: argument --engine: invalid choice 'symbolc'; did you mean 'symbolic'? "
                    "(choose from auto, explicit, symbolic)")


def test_missing_input_is_cannot_read(cli):
    assert cli("import", "project.xml") == (2, "", "error: cannot read 'project.xml': No such file or directory\n")
    assert cli("import", "--list", "project.xml")[2] == "error: cannot read 'project.xml': No such file or directory\n"
    assert cli("validate", "nope.g7", "--plant", "plants/tri.rules")[2] == \
        "error: cannot read 'nope.g7': No such file or directory\n"


def test_wrong_file_kind_is_cannot_read(cli):
    assert cli("import", str(ROOT / "plants")) == (2, "", f"error: cannot read '{ROOT / 'plants'}': Is a directory\n")


def test_unwritable_output_is_cannot_write(cli, tmp_path):
    blocker = tmp_path / "file"
    blocker.write_text("")
    code, out, err = cli("sfc", str(ROOT / "grafcets/tri.g7"), "-o", str(blocker / "tri.xml"))
    assert (code, out) == (2, "")
    assert err == f"error: cannot write '{blocker / 'tri.xml'}': '{blocker}' is a file, not a folder\n"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["file"]


def test_a_crash_is_a_bug_exit_3(cli, monkeypatch):
    import synth.plant.library

    def boom() -> None:
        raise RuntimeError("boom\nsecond line")

    monkeypatch.setattr(synth.plant.library, "library_models", boom)
    monkeypatch.delenv("SYNTH_TRACEBACK", raising=False)
    assert cli("lib") == (3, "", "synth: internal error: RuntimeError: boom second line\n"
                                 "this is a bug in synth: please report it with the command and its input files "
                                 "(SYNTH_TRACEBACK=1 prints the traceback)\n")
    monkeypatch.setenv("SYNTH_TRACEBACK", "1")
    code, _, err = cli("lib")
    assert code == 3 and err.startswith("Traceback (most recent call last):") and "RuntimeError: boom" in err


def test_ctrl_c_exits_130_and_says_how_far(cli, monkeypatch):
    import synth.plant.library
    from synth.output.progress import tty_progress

    def interrupted() -> None:
        tty_progress(False)("reading the library: 3 models")
        raise KeyboardInterrupt

    monkeypatch.setattr(synth.plant.library, "library_models", interrupted)
    code, out, err = cli("lib")
    assert (code, out) == (130, "")
    assert re.fullmatch(r"interrupted after \d+\.\d s: reading the library: 3 models\n", err), err


def test_sigint_in_a_real_process_exits_130(tmp_path):
    """A SIGINT during a run (here: while synth waits on its input) exits 130, no traceback."""
    import signal
    import time

    env = dict(os.environ, PYTHONPATH=str(ROOT))
    proc = subprocess.Popen([sys.executable, "-c", "import time, synth.cli.main as m\n"
                             "import synth.plant.library as l\n"
                             "l.library_models = lambda: time.sleep(30)\n"
                             "import sys; sys.exit(m.main(['lib']))"],
                            cwd=ROOT, env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    time.sleep(2)
    proc.send_signal(signal.SIGINT)
    out, err = proc.communicate(timeout=30)
    assert proc.returncode == 130
    assert re.fullmatch(r"interrupted after \d+\.\d s\n", err), err


def test_eventually_and_its_alias_progress(cli):
    from synth.cli.main import build_parser

    verify = build_parser().commands.choices["filter"].commands.choices["verify"]
    assert "--eventually GOAL, --progress GOAL" in verify.format_help()
    ns1 = verify.parse_args(["F.filter", "--plant", "P.rules", "--any-control", "--eventually", "↑x"])
    ns2 = verify.parse_args(["F.filter", "--plant", "P.rules", "--any-control", "--progress", "↑x"])
    assert ns1.progress == ns2.progress == "↑x"


def test_help_documents_the_exit_codes(capsys):
    with pytest.raises(SystemExit):
        main(["--help"])
    out = " ".join(capsys.readouterr().out.split())
    assert ("exit codes: 0 pass, 1 the model fails (problems found), 2 bad input or a limit reached, "
            "3 a bug in synth (SYNTH_TRACEBACK=1 shows its traceback), 130 interrupted") in out


def test_wrong_file_kind_is_named(cli):
    code, out, err = cli("import", "grafcets/tri.g7")
    assert (code, out) == (2, "")
    assert err.splitlines()[0] == "grafcets/tri.g7:1:1: error: not well-formed XML: Start tag expected, '<' not found"
    assert err.splitlines()[-1] == ("  = note: grafcets/tri.g7 is a Grafcet file (.g7), not a PLCopen XML file (.xml): "
                                    "check the order of the arguments")
    code, _, err = cli("validate", "plants/tri.rules", "--plant", "grafcets/tri.g7")
    assert code == 2
    assert err.splitlines()[-1] == ("  = note: grafcets/tri.g7 is a Grafcet file (.g7), not a plant's rules file "
                                    "(.rules): check the order of the arguments")
