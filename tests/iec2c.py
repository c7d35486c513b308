"""MATIEC's ``iec2c`` for the tests: find it, compile generated ST with it, and run the C it
emits as a :class:`synth.codegen.check.ProgramRunner` (issue 22).

MATIEC is the IEC 61131-3 compiler of Beremiz and OpenPLC. It is built locally from its public
sources (OpenPLC_v3's ``utils/matiec_src``) and never committed; put ``iec2c`` on PATH (or name
it in ``SYNTH_IEC2C``, with its ``lib`` folder beside it or in ``SYNTH_IEC2C_LIB``) to run the
tests that need it; they are skipped otherwise.

The harness is a small C program around the compiled ``PROGRAM``: it includes ``POUS.c``,
holds one instance and reads commands on standard input, one per line:

* ``c I V I V ...``: set input ``I`` (an index) to ``V`` (0/1), run one cycle (the program's
  ``_body__``), print the watched variables as one line of 0/1;
* ``a MS``: move ``__CURRENT_TIME`` (what MATIEC's TON reads) on by ``MS`` milliseconds;
* ``s`` / ``r``: push a copy of the instance and the clock / pop and restore it.
"""

from __future__ import annotations

import os
import re
import shutil
import subprocess
from pathlib import Path
from typing import Mapping

from synth.codegen.program import StProgram
from synth.codegen.st import PouKind, SectionKind

__all__ = ["find_iec2c", "compile_st", "CompiledProgram"]

_HARNESS = r"""#include "POUS.h"
#include "POUS.c"
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
TIME __CURRENT_TIME;
BOOL __DEBUG;
typedef struct { %(type)s inst; TIME now; } snapshot_t;
static snapshot_t stack[64];
static int top = 0;
int main(void) {
    %(type)s inst;
    char line[65536];
    memset(&inst, 0, sizeof inst);
    %(type)s_init__(&inst, 0);
    BOOL *inputs[] = {%(inputs)s};
    BOOL *watched[] = {%(watched)s};
    int n_watched = %(n_watched)d;
    INT *numbers[] = {%(numbers)s};
    int n_numbers = %(n_numbers)d;
    while (fgets(line, sizeof line, stdin)) {
        if (line[0] == 'c') {
            char *p = line + 1;
            long i, v;
            int used;
            while (sscanf(p, "%%ld %%ld%%n", &i, &v, &used) == 2) { *inputs[i] = (BOOL)v; p += used; }
            %(type)s_body__(&inst);
            for (int k = 0; k < n_watched; k++) putchar(*watched[k] ? '1' : '0');
            for (int k = 0; k < n_numbers; k++) printf(" %%d", (int)*numbers[k]);
            putchar('\n');
            fflush(stdout);
        } else if (line[0] == 'a') {
            long long ns = (long long)__CURRENT_TIME.tv_nsec + atoll(line + 1) * 1000000LL;
            __CURRENT_TIME.tv_sec += ns / 1000000000LL;
            __CURRENT_TIME.tv_nsec = ns %% 1000000000LL;
        } else if (line[0] == 's') {
            stack[top].inst = inst; stack[top].now = __CURRENT_TIME; top++;
        } else if (line[0] == 'r') {
            top--; inst = stack[top].inst; __CURRENT_TIME = stack[top].now;
        }
    }
    return 0;
}
"""


def find_iec2c() -> tuple[str, Path] | None:
    """``iec2c`` and its ``lib`` folder, or None when MATIEC is not installed here."""
    exe = os.environ.get("SYNTH_IEC2C") or shutil.which("iec2c")
    if not exe:
        return None
    lib = Path(os.environ.get("SYNTH_IEC2C_LIB") or Path(exe).resolve().parent / "lib")
    return (exe, lib) if lib.is_dir() else None


def compile_st(text: str, folder: Path) -> subprocess.CompletedProcess[str]:
    """Run ``iec2c`` on ``text`` (written to ``folder/program.st``); the C goes to ``folder``."""
    found = find_iec2c()
    assert found is not None, "iec2c is not installed"
    exe, lib = found
    folder.mkdir(parents=True, exist_ok=True)
    (folder / "program.st").write_text(text, encoding="utf-8")
    return subprocess.run([exe, "-I", str(lib), "-T", str(folder), str(folder / "program.st")],
                          capture_output=True, text=True, timeout=120)


class CompiledProgram:
    """The generated program compiled by ``iec2c`` and gcc, driven through the harness;
    ``pou``: the POU to run (default: the ``PROGRAM``; a ``FUNCTION_BLOCK`` runs the same way,
    one call per cycle). A declaration ``S12.X`` of an SFC program watches step ``S12``'s flag."""

    def __init__(self, program: StProgram, folder: Path, pou: str | None = None) -> None:
        found = find_iec2c()
        assert found is not None, "iec2c is not installed"
        done = compile_st(program.text, folder)
        assert done.returncode == 0, done.stdout + done.stderr
        main = next(p for p in program.pous if (p.name == pou if pou else p.kind is PouKind.PROGRAM))
        inputs = [d.name for s in main.sections if s.kind is SectionKind.INPUT for d in s.declarations]
        watched = [d.name for s in main.sections for d in s.declarations if d.type == "BOOL"]
        numbers = [d.name for s in main.sections for d in s.declarations
                   if d.type == "INT" and s.kind is not SectionKind.CONSTANT]
        self.number_index = {n.upper(): i for i, n in enumerate(numbers)}
        self.input_index = {n.upper(): i for i, n in enumerate(inputs)}
        self.watched_index = {n.upper(): i for i, n in enumerate(watched)}
        c_type = main.name.upper()
        # an SFC's step S12 is MATIEC's __step_list[k] (a macro of POUS.c): watch S12.X through it
        steps = dict(re.findall(r"^#define (\w+) (__step_list\[\d+\])$", (folder / "POUS.c").read_text(), re.M))

        def field(n: str) -> str:
            head, _, tail = n.upper().partition(".")
            return f"{steps.get(head, head)}{_ + tail}.value"

        (folder / "harness.c").write_text(_HARNESS % {
            "type": c_type,
            "inputs": ", ".join(f"&inst.{n.upper()}.value" for n in inputs) or "0",
            "watched": ", ".join(f"&inst.{field(n)}" for n in watched),
            "n_watched": len(watched),
            "numbers": ", ".join(f"&inst.{n.upper()}.value" for n in numbers) or "0",
            "n_numbers": len(numbers),
        }, encoding="utf-8")
        cc = subprocess.run(["gcc", "-O1", "-w", "-I", str(found[1] / "C"), "-I", str(folder),
                             str(folder / "harness.c"), "-o", str(folder / "harness")],
                            capture_output=True, text=True, timeout=120)
        assert cc.returncode == 0, cc.stderr
        self.process = subprocess.Popen([str(folder / "harness")], stdin=subprocess.PIPE, stdout=subprocess.PIPE,
                                        text=True, bufsize=1)
        self.last = ""
        self.cycles = 0

    def _send(self, line: str) -> None:
        assert self.process.stdin is not None
        self.process.stdin.write(line + "\n")

    def cycle(self, inputs: Mapping[str, bool]) -> None:
        cells = " ".join(f"{self.input_index[n.upper()]} {int(v)}" for n, v in inputs.items())
        self._send("c " + cells)
        self.process.stdin.flush()  # type: ignore[union-attr]
        assert self.process.stdout is not None
        self.last = self.process.stdout.readline().strip()
        self.cycles += 1

    def value(self, name: str) -> bool:
        return self.last.split(" ")[0][self.watched_index[name.upper()]] == "1"

    def number(self, name: str) -> int:
        return int(self.last.split(" ")[1 + self.number_index[name.upper()]])

    def __getitem__(self, name: str) -> bool:
        return self.value(name)

    def advance(self, ms: int) -> None:
        self._send(f"a {int(ms)}")

    def save(self) -> object:
        self._send("s")
        return self.last

    def restore(self, saved: object) -> None:
        self._send("r")
        self.last = str(saved)

    def close(self) -> None:
        if self.process.stdin:
            self.process.stdin.close()
        self.process.wait(timeout=30)
