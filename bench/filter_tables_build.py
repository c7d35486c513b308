"""The tables-form filter block on the real compiler chain: ``synth filter st`` of
``grid_edges`` 8 × N/8 (past the chain's work limit from 8 × 5 on), then MATIEC's ``iec2c``,
gcc at each optimisation level, and the compiled block run on random cycles.

    python3 bench/filter_tables_build.py --tree BEFORE --tree AFTER [--sizes 40,64] [--cycles 2000]
                                         [--opt O0,O1] [--gcc-timeout 300] [--beremiz] [--json FILE]

Needs ``iec2c`` (``SYNTH_IEC2C`` or on PATH, its ``lib`` beside it or in ``SYNTH_IEC2C_LIB``)
and gcc. ``BEFORE`` is typically ``git archive main | tar -x -C /tmp/before``. Per size the
trees run one after the other (interleaved: the load hits them alike). Per tree: the ST's
lines and bytes and the CPU seconds of ``filter st`` (a fresh process, start included), of
``iec2c`` and of gcc (each level: a small driver that includes MATIEC's C, sets every input
from a fixed pseudo-random sequence, calls the block once per cycle); then the CPU µs per
cycle of the program (``clock()`` around the cycles) and a checksum of the outputs, which
must agree between the trees (the same block behaviour on the same inputs). ``--beremiz``
(``SYNTH_BEREMIZ``, ``SYNTH_BEREMIZ_PYTHON`` as for the tests): also ``filter st --xml``, the
program Beremiz's generator writes from it, and that program through iec2c, gcc at the first
level and the same cycles (its checksum must be the ST's). CPU seconds of children
(``resource.getrusage``), not wall time: the machine is shared.
"""

from __future__ import annotations

import argparse
import json
import os
import re
import resource
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

from filter_scale import grid_edges_filter  # noqa: E402  (a sibling script, not a package)

DRIVER = r"""#include "POUS.h"
#include "POUS.c"
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
TIME __CURRENT_TIME;
BOOL __DEBUG;
int main(int argc, char **argv) {
    static %(type)s inst;
    long cycles = atol(argv[1]);
    unsigned long long state = 88172645463325252ULL, sum = 0;
    memset(&inst, 0, sizeof inst);
    %(type)s_init__(&inst, 0);
    BOOL *inputs[] = {%(inputs)s};
    BOOL *outputs[] = {%(outputs)s};
    int n_in = sizeof inputs / sizeof inputs[0], n_out = sizeof outputs / sizeof outputs[0];
    clock_t spent = 0;
    for (long c = 0; c < cycles; c++) {
        for (int i = 0; i < n_in; i++) {
            state ^= state << 13; state ^= state >> 7; state ^= state << 17;
            *inputs[i] = (BOOL)(state & 1);
        }
        clock_t t = clock();
        %(type)s_body__(&inst);
        spent += clock() - t;
        for (int k = 0; k < n_out; k++) sum = sum * 31 + (*outputs[k] ? 1 : 0) + (unsigned long long)k;
    }
    printf("%%.3f %%llu\n", 1e6 * (double)spent / CLOCKS_PER_SEC / (double)cycles, sum);
    return 0;
}
"""


BEREMIZ = """
import sys
sys.path.insert(0, sys.argv[1])
import fake_wx  # noqa: F401  (Beremiz's stand-in for wxPython, as its CLI uses)
import ProjectController  # noqa: F401
from PLCControler import PLCControler
c = PLCControler()
error = c.OpenXMLFile(sys.argv[2])
if error:
    sys.exit("OPEN ERROR " + str(error))
program, errors, warnings = c.GenerateProgram(sys.argv[3])
if errors or program is None:
    sys.exit("GENERATE ERROR " + str(errors))
"""
"""Beremiz's loader and generator (as ``tests/beremiz.py`` drives them): the ST it hands to MATIEC."""


def children_cpu() -> float:
    r = resource.getrusage(resource.RUSAGE_CHILDREN)
    return r.ru_utime + r.ru_stime


def timed(cmd: list[str], timeout: float, **kw: object) -> tuple[subprocess.CompletedProcess[str] | None, float]:
    """``cmd`` and its CPU seconds (None when it passed ``timeout`` wall seconds and was stopped)."""
    t = children_cpu()
    try:
        done = subprocess.run(cmd, capture_output=True, text=True, timeout=timeout, **kw)  # type: ignore[call-overload]
    except subprocess.TimeoutExpired:
        return None, children_cpu() - t
    return done, children_cpu() - t


def section(text: str, kind: str) -> list[str]:
    return [n for block in re.findall(rf"^[ \t]*{kind}[ \t]*\n(.*?)^[ \t]*END_VAR", text, re.S | re.M)
            for n in re.findall(r"^\s*(\w+)\s*:\s*BOOL;", block, re.M)]


def build(st: Path, c_dir: Path, iec2c: str, lib: Path, opts: list[str], cycles: int, gcc_timeout: float,
          out: dict[str, object], prefix: str = "") -> None:
    """``st`` through iec2c and gcc at each level, run on ``cycles`` cycles: into ``out``."""
    text = st.read_text(encoding="utf-8")
    shutil.rmtree(c_dir, ignore_errors=True)
    c_dir.mkdir()
    done, cpu = timed([iec2c, "-I", str(lib), "-T", str(c_dir), str(st)], 1200)
    assert done is not None and done.returncode == 0, done.stdout + done.stderr if done else "iec2c timed out"
    out[prefix + "iec2c_cpu"] = round(cpu, 2)
    out[prefix + "c_bytes"] = (c_dir / "POUS.c").stat().st_size
    block = re.search(r"^\s*FUNCTION_BLOCK (\w+)", text, re.M)[1].upper()  # type: ignore[index]
    inputs, outputs = section(text, "VAR_INPUT"), section(text, "VAR_OUTPUT")
    assert inputs and outputs, f"no inputs or outputs read in {st}"
    (c_dir / "driver.c").write_text(DRIVER % {
        "type": block,
        "inputs": ", ".join(f"&inst.{n.upper()}.value" for n in inputs),
        "outputs": ", ".join(f"&inst.{n.upper()}.value" for n in outputs)}, encoding="utf-8")
    for opt in opts:
        exe = c_dir / f"driver_{opt}"
        done, cpu = timed(["gcc", f"-{opt}", "-w", "-I", str(lib / "C"), "-I", str(c_dir), str(c_dir / "driver.c"),
                           "-o", str(exe)], gcc_timeout)
        key = f"{prefix}gcc_{opt}_cpu"
        out[key] = round(cpu, 2) if done is not None else f"stopped after {gcc_timeout:.0f} s ({cpu:.1f} CPU s)"
        if done is None:
            continue
        assert done.returncode == 0, done.stderr
        run = subprocess.run([str(exe), str(cycles)], capture_output=True, text=True, check=True, timeout=3600)
        us, checksum = run.stdout.split()
        out[f"{prefix}us_per_cycle_{opt}"], out[f"{prefix}checksum_{opt}"] = float(us), checksum


def one(tree: Path, size: int, folder: Path, iec2c: str, lib: Path, opts: list[str], cycles: int,
        gcc_timeout: float, beremiz: tuple[str, str] | None) -> dict[str, object]:
    name = f"grid_edges_{size}"
    (folder / f"{name}.filter").write_text(grid_edges_filter(size), encoding="utf-8")
    env = {**os.environ, "PYTHONPATH": str(tree)}
    done, cpu = timed([sys.executable, "-m", "synth", "filter", "st", f"{name}.filter", "-o", f"{name}.st"],
                      1200, cwd=folder, env=env)
    assert done is not None and done.returncode == 0, done.stderr if done else "filter st timed out"
    text = (folder / f"{name}.st").read_text(encoding="utf-8")
    out: dict[str, object] = {"st_lines": text.count("\n"), "st_bytes": len(text.encode()), "st_cpu": round(cpu, 2)}
    build(folder / f"{name}.st", folder / "c", iec2c, lib, opts, cycles, gcc_timeout, out)
    if beremiz is None:
        return out
    done, cpu = timed([sys.executable, "-m", "synth", "filter", "st", f"{name}.filter", "--xml", "-o", f"{name}.xml"],
                      1200, cwd=folder, env=env)
    assert done is not None and done.returncode == 0, done.stderr if done else "filter st --xml timed out"
    out["xml_bytes"] = (folder / f"{name}.xml").stat().st_size
    python, home = beremiz
    done, cpu = timed([python, "-c", BEREMIZ, home, str(folder / f"{name}.xml"), str(folder / "beremiz.st")], 1200,
                      cwd=home)
    if done is None or done.returncode != 0:
        out["beremiz"] = "failed: " + (done.stderr[-300:] if done else "timed out")
        return out
    out["beremiz_cpu"] = round(cpu, 2)
    build(folder / "beremiz.st", folder / "bc", iec2c, lib, opts[:1], cycles, gcc_timeout, out, "beremiz_")
    return out


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--tree", action="append", required=True, type=Path)
    ap.add_argument("--sizes", default="40,64")
    ap.add_argument("--cycles", type=int, default=2000)
    ap.add_argument("--opt", default="O0,O1")
    ap.add_argument("--gcc-timeout", type=float, default=300.0)
    ap.add_argument("--beremiz", action="store_true", help="also filter st --xml, built by Beremiz's generator")
    ap.add_argument("--json", type=Path)
    a = ap.parse_args()
    exe = os.environ.get("SYNTH_IEC2C") or shutil.which("iec2c")
    if exe is None:
        print("iec2c not found: set SYNTH_IEC2C", file=sys.stderr)
        return 2
    lib = Path(os.environ.get("SYNTH_IEC2C_LIB") or Path(exe).resolve().parent / "lib")
    home, python = os.environ.get("SYNTH_BEREMIZ"), os.environ.get("SYNTH_BEREMIZ_PYTHON")
    beremiz = (python, home) if a.beremiz and home and python else None
    if a.beremiz and beremiz is None:
        print("--beremiz: set SYNTH_BEREMIZ and SYNTH_BEREMIZ_PYTHON", file=sys.stderr)
        return 2
    results: dict[str, dict[str, object]] = {}
    with tempfile.TemporaryDirectory(prefix="tables_build_") as tmp:
        for size in (int(s) for s in a.sizes.split(",")):
            for i, tree in enumerate(a.tree):
                folder = Path(tmp) / f"{size}_{i}"
                folder.mkdir()
                r = one(tree.resolve(), size, folder, exe, lib, a.opt.split(","), a.cycles, a.gcc_timeout, beremiz)
                results[f"{size} {tree}"] = r
                print(f"grid_edges {size} ({tree}): {json.dumps(r)}", flush=True)
    if a.json:
        a.json.write_text(json.dumps(results, indent=2) + "\n", encoding="utf-8")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
