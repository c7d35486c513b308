"""``synth completion bash``: a script generated from the parser, sourced in a real bash and
its completion function called as bash calls it on <TAB>."""

from __future__ import annotations

import os
import shutil
import subprocess
import sys

import pytest

from conftest import ROOT

pytestmark = pytest.mark.skipif(shutil.which("bash") is None, reason="bash is not installed")


def _complete(words: list[str]) -> list[str]:
    script = subprocess.run([sys.executable, "-m", "synth", "completion", "bash"], cwd=ROOT, capture_output=True,
                            text=True, env=dict(os.environ, PYTHONPATH=str(ROOT)), check=True).stdout
    line = " ".join(words)
    driver = (f"source /dev/stdin <<'SYNTH_COMPLETION'\n{script}\nSYNTH_COMPLETION\n"
              f"COMP_WORDS=({' '.join(repr(w) for w in words)}); COMP_CWORD={len(words) - 1}\n"
              f"COMP_LINE={line!r}; COMP_POINT=${{#COMP_LINE}}\n"
              "_shtab_synth; printf '%s\\n' \"${COMPREPLY[@]}\"\n")
    done = subprocess.run(["bash", "-c", driver], capture_output=True, text=True, timeout=60)
    assert done.returncode == 0, done.stderr
    return done.stdout.split()


def test_commands_complete():
    assert _complete(["synth", "val"]) == ["validate"]
    assert _complete(["synth", "s"]) == ["sup", "st", "sfc"]


def test_subcommands_and_options_complete():
    assert _complete(["synth", "filter", "ch"]) == ["check"]
    assert _complete(["synth", "filter", "verify", "--ev"]) == ["--events-per-cycle", "--eventually"]
    assert _complete(["synth", "validate", "--js"]) == ["--json"]


def test_choices_complete():
    assert _complete(["synth", "validate", "--engine", "s"]) == ["symbolic"]
