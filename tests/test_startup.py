"""Start-up: each command imports only what it uses (docs/performance.md, "Start-up").

Every check runs in a fresh interpreter (a subprocess), since this test process has
long imported everything; what a command imported is read from ``sys.modules``. No
timing here: ``python3 bench/startup.py`` measures.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys

import pytest

from conftest import ROOT

# Third-party packages no command needs for argument parsing, nor a passing validation.
HEAVY = ("numpy", "lark", "regex", "graphviz", "networkx", "dd", "jinja2", "lxml", "blark")


def modules_after(code: str) -> dict:
    """Run ``code`` in a fresh ``python`` with this tree first on the path; it fills
    ``NEW``, the modules it imported (those the interpreter's start-up, site hooks
    included, had already imported are left out), and the JSON of ``OUT`` is returned."""
    script = f"import sys\nBEFORE = set(sys.modules)\nOUT = {{}}\n{code}\nprint('\\n' + __import__('json').dumps(OUT))\n"
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([str(ROOT), os.environ.get("PYTHONPATH", "")]))
    done = subprocess.run([sys.executable, "-c", script], cwd=ROOT, env=env, capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    return json.loads(done.stdout.splitlines()[-1])


HELP = """
import synth.cli.main as m
m.build_parser()
OUT["parser"] = sorted(set(sys.modules) - BEFORE)
for argv in (["--help"], ["validate", "--help"], ["sup", "--help"], ["filter", "st", "--help"], ["st", "--help"]):
    try:
        m.main(argv)
    except SystemExit as e:
        assert e.code == 0, (argv, e.code)
OUT["help"] = sorted(set(sys.modules) - BEFORE)
"""


def test_help_imports_only_argparse_and_the_cli() -> None:
    out = modules_after(HELP)
    for key in ("parser", "help"):
        loaded = set(out[key])
        assert "synth.cli.validate" in loaded  # the check is not vacuous
        assert sorted(loaded & set(HEAVY)) == [], key
        # nor the standard library's slower modules, nor synth's library
        slow = {"typing", "dataclasses", "inspect", "json", "pathlib", "difflib", "fractions"}
        assert sorted(loaded & slow) == [], key
        # the glossary the validate --help epilog shows is text with no import behind it
        text_only = {"synth.version", "synth.output", "synth.output.glossary"}
        assert [m for m in loaded if m.startswith("synth.") and not m.startswith("synth.cli") and m not in text_only] == [], key


VALIDATE = """
import contextlib, io
import synth.cli.main as m
with contextlib.redirect_stdout(io.StringIO()):
    OUT["code"] = [m.main(ARGV)]
OUT["modules"] = sorted(set(sys.modules) - BEFORE)
"""


@pytest.mark.parametrize("grafcet, passed", [("tri.g7", True), ("tri_missing_order.g7", False)])
def test_validate_imports_no_graph_nor_bdd_library(grafcet: str, passed: bool) -> None:
    argv = ["validate", str(ROOT / "grafcets" / grafcet), "--plant", str(ROOT / "plants" / "tri.rules"), "--quiet"]
    out = modules_after(f"ARGV = {argv!r}\n{VALIDATE}")
    assert out["code"] == [0 if passed else 1]
    loaded = set(out["modules"])
    assert {"numpy", "lark"} <= loaded  # the explicit engine and the parsers: the check above is not vacuous
    assert sorted(loaded & {"graphviz", "networkx", "dd", "jinja2", "synth.symbolic.validate"}) == []
    assert "regex" not in loaded  # lark imported without it (synth.syntax)
    assert sorted(loaded & {"json", "difflib"}) == []  # only for --json / --cor, and for a misspelt name
    # the diagnosis is imported only when there is something to diagnose
    assert ("synth.validation.diagnosis" in loaded) is not passed


def test_lark_keeps_regex_after_synth_imported_it_without() -> None:
    """synth imports lark without the ``regex`` module; lark's ``regex=True`` (and any
    other ``import regex``) still get the real module."""
    pytest.importorskip("regex")
    out = modules_after(
        "import synth.syntax\n"
        "OUT['regex_loaded'] = 'regex' in sys.modules\n"
        "from lark import Lark\n"
        "p = Lark('start: WORD\\nWORD: /\\\\p{L}+/', parser='lalr', regex=True)\n"
        "OUT['parsed'] = str(p.parse('\\u00e9t\\u00e9').children[0])\n"
        "import regex\n"
        "OUT['real'] = [regex.__name__, type(regex).__name__, hasattr(regex, '__file__')]\n"
    )
    assert out["regex_loaded"] is False
    assert out["parsed"] == "\u00e9t\u00e9"
    assert out["real"] == ["regex", "module", True]
