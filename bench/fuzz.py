"""A mutation fuzzer over synth's input languages: it mutates the bundled inputs and runs the
command that reads each, in this process, counting what must never happen.

    python3 bench/fuzz.py --runs 20000 --seed 1 [--out fuzz_out] [--json]

The languages: the rules (``.rules``), Grafcets (``.g7``), filters (``.filter``), PLCopen XML,
Structured Text given to ``filter verify --control``, CSV traces of ``filter run``, and the
command-line expressions ``--events`` (``run``), ``--home`` (``validate``) and ``--why``
(``sup``). Each run takes one bundled input, applies 1 to 4 mutations (a span deleted,
duplicated or moved, a token of the language or a nasty string inserted, a character
changed, the text cut, line ends changed), runs the command and classifies the outcome:

- **crash**: exit 3, an unexpected exception (a bug in synth), or any other exception that
  escaped ``main``;
- **unlocated**: exit 2 whose first line is neither ``file:line:col: …`` nor one of the
  messages that have no place in a file (``error: cannot read 'x'``, a limit reached, a usage
  error of the command line);
- **slow**: a run longer than ``--timeout`` seconds (stopped by an alarm);
- **huge**: more than 64 KiB on standard error.

Every finding keeps its input in ``--out`` (``<language>_<run>.<ext>`` and the command). The
counts are deterministic for a seed, but for the slow ones (they depend on the machine).
``tests/test_fuzz.py`` runs a small slice in CI.
"""

from __future__ import annotations

import argparse
import contextlib
import io
import json
import os
import random
import re
import signal
import sys
import tempfile
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable

ROOT = Path(__file__).resolve().parent.parent
if str(ROOT) not in sys.path:
    sys.path.insert(0, str(ROOT))

LOCATED = re.compile(r"^.+:\d+:\d+: (error|warning): ")
# first lines that rightly have no file position: files that cannot be read or written, limits,
# argparse's usage errors, the whole command's verdicts on stderr
UNPLACED = re.compile(r"^(error: cannot (read|write) |stopped: |usage: |synth( \S+)*: error: |error: )")
NASTY = ("", "\r\n", "\r", "\t", "\x00", "\ufeff", "é", "↑", "↓", "⁻¹", "*)", "(*", "//", '"', "'", "\\", "#",
         "{", "}", "(", ")", "[", "]", ";", ":", ",", "=", ":=", "->", "<", ">", "&", "|", "!", "~", "^", "_",
         "9" * 40, "9" * 4400, "-1", "0", "1", "1e400", "nan", " " * 3000, "x" * 3000, "\n" * 50, "X0", "2s/X1",
         "0ms/", "T#1h", "/", ".", "..", "lib/", "/dev/zero", "<!--", "-->", "<![CDATA[", "]]>", "&amp;", "&#0;",
         "<a>", "</a>")
TOKENS = {
    "rules": ("element", "model", "use", "sensor", "sensors", "order", "orders", "free", "reads", "incoherent",
              "constraint", "inputs", "outputs", "= 0", "= 1", "<", "[", "]", "->", "{", "}", "v10", "AVANCER1"),
    "g7": ("grafcet", "initial", "step", "transition", "when", "if", "->", "internal", ":=", "0..3", "X1", "2s/X101",
           "↑dcy", "inputs", "outputs", "stored", "set", "reset", "{", "}"),
    "filter": ("inputs", "outputs", "observer", "assume", "safety", "keep", "force", "minimize", "maximize", "sim",
               "equation", "use", "pre(", "^-1", "grafcet", "integer", ":=", "=", "R_"),
    "xml": ("<step", "<transition", "localId=", "refLocalId=", "<connection", "<pou", "<body>", "<SFC>", "<ST>",
            "<xhtml:p>", "<inVariable", "<expression>", "</", "/>", 'name="', 'pouType="program"', "<jumpStep"),
    "st": ("PROGRAM", "END_PROGRAM", "VAR", "VAR_INPUT", "VAR_OUTPUT", "END_VAR", "BOOL", "INT", "TIME", "TON",
           "IF", "THEN", "ELSE", "END_IF", ":=", "AND", "OR", "NOT", "T#5s", "CASE", "WHILE", "FUNCTION_BLOCK"),
    "csv": (",", "\n", "0", "1", "2", "R_o1", "o1", "#", '"', "x", ";"),
    "events": (",", "↑", "↓", "^", "_", "dcy", "cp12", "2s/X101", "v10", "X101", "s/", "0s/X0", " "),
    "home": ("X0", "X1", "&", "|", "!", "(", ")", "1", "0", "v0", "Q", "↑", "dcy"),
    "why": (",", "TAPIS", "v10", "v20", "AVANCER1", "AVANCER3", "RECULER1", "=1", "x"),
}


@dataclass(frozen=True)
class Language:
    """One input language: its seeds (files, or texts for command-line expressions) and how a
    mutant is run (the argument vector, given the mutant's path or text)."""

    name: str
    ext: str
    seeds: tuple[str, ...]  # paths relative to ROOT, or the expression texts
    argv: Callable[[str], list[str]]
    is_file: bool = True


def _languages(work: Path) -> list[Language]:
    """The nine languages and what runs them. ``work`` holds the fixed files some commands need."""
    plants = tuple(f"plants/{p.name}" for p in sorted((ROOT / "plants").glob("*.rules")))
    lib = tuple(f"plants/lib/{p.name}" for p in sorted((ROOT / "plants/lib").glob("*.rules")))
    g7 = tuple(f"grafcets/{p.name}" for p in sorted((ROOT / "grafcets").glob("*.g7")))
    filters = tuple(f"plants/{p.name}" for p in sorted((ROOT / "plants").glob("*.filter"))) + \
        tuple(f"tests/data/filter/{p.name}" for p in sorted((ROOT / "tests/data/filter").glob("*.filter")))
    xml = tuple(f"tests/data/plcopen/{p.name}" for p in sorted((ROOT / "tests/data/plcopen").glob("*.xml")))
    st = ("tests/data/filter/toggle.st",)
    (work / "c.rules").write_text('use "lib/single_acting.rules"\nelement V1 = single_acting(AVANCER=Q1, v0=v10, v1=v11)\n'
                                  'constraint REST "push only from rest": ↑Q1 & !v10 = 0\n')
    (work / "c.filter").write_text('inputs v10, v11\noutputs Q1\nsafety FROM_REST "push only from rest": ↑Q1 & !v10\n')
    tri, home_g7, home_rules = str(ROOT / "plants/tri.rules"), str(ROOT / "tests/data/home/production_loop.g7"), \
        str(ROOT / "tests/data/home/cylinder.rules")
    return [
        Language("rules", "rules", plants + lib, lambda f: ["plant", f]),
        Language("g7", "g7", g7, lambda f: ["run", f, "--plant", tri] if "tri" in f else ["run", f]),
        Language("filter", "filter", filters, lambda f: ["filter", "check", f]),
        Language("xml", "xml", xml, lambda f: ["import", f]),
        Language("st", "st", st, lambda f: ["filter", "verify", str(work / "c.filter"), "--plant", str(work / "c.rules"),
                                            "--control", f, "--max-states", "2000"]),
        Language("csv", "csv", ("tests/data/filter/loop_a.csv",),
                 lambda f: ["filter", "run", str(ROOT / "plants/loop_a.filter"), "--trace", f]),
        Language("events", "txt", ("↑dcy,↑cp12,2s/X101,↓v10,↑v11", "↑dcy,↑cp11,2s/X111"),
                 lambda t: ["run", str(ROOT / "grafcets/tri.g7"), "--plant", tri, "--events", t], is_file=False),
        Language("home", "txt", ("X0", "X0 & !dcy", "X0 | X1", "!(X1 | X2) & v0"),
                 lambda t: ["validate", home_g7, "--plant", home_rules, "--home", t], is_file=False),
        Language("why", "txt", ("TAPIS,v10,v20,v30,v40,AVANCER1,AVANCER3", "TAPIS,v10,v20,v30,v40"),
                 lambda t: ["sup", str(ROOT / "plants/tri_annex.rules"), "--why", t], is_file=False),
    ]


def mutate(text: str, rng: random.Random, tokens: tuple[str, ...]) -> str:
    """``text`` after 1 to 4 random edits."""
    for _ in range(rng.randint(1, 4)):
        n = len(text)
        i = rng.randint(0, n)
        j = min(n, i + rng.choice((1, 2, 5, 20, 200)))
        kind = rng.randrange(8)
        if kind == 0 and n:
            text = text[:i] + text[j:]  # delete a span
        elif kind == 1:
            text = text[:i] + text[i:j] * rng.choice((2, 3, 50)) + text[j:]  # repeat a span
        elif kind == 2:
            text = text[:i] + rng.choice(tokens) + text[i:]  # a token of the language
        elif kind == 3:
            text = text[:i] + rng.choice(NASTY) + text[i:]  # a nasty string
        elif kind == 4 and n:
            text = text[:i] + chr(rng.choice((rng.randint(32, 126), rng.randint(0, 31), rng.randint(128, 0x2FFF)))) \
                + text[i + 1:]  # one character changed
        elif kind == 5:
            text = text[:i]  # cut
        elif kind == 6:
            text = text.replace("\n", rng.choice(("\r\n", "\r", "\n\n", " ")))
        elif n:
            k = rng.randint(0, n)
            piece = text[i:j]
            rest = text[:i] + text[j:]
            text = rest[:k] + piece + rest[k:]  # move a span
    return text


class _Timeout(BaseException):
    """Raised by the alarm: not an Exception, so synth's own handlers cannot swallow it."""


@dataclass
class Tally:
    runs: int = 0
    codes: dict[int, int] = field(default_factory=dict)
    crash: int = 0
    unlocated: int = 0
    slow: int = 0
    huge: int = 0
    seconds: float = 0.0
    longest: float = 0.0
    findings: list[dict[str, object]] = field(default_factory=list)


def run_one(argv: list[str], timeout: float) -> tuple[int | None, str, float, str]:
    """``synth ARGV`` in this process: (exit code or None, stderr, seconds, the escaped exception)."""
    from synth.cli.main import main

    out, err = io.StringIO(), io.StringIO()
    escaped = ""
    start = time.monotonic()

    def alarm(*_: object) -> None:
        raise _Timeout()

    old = signal.signal(signal.SIGALRM, alarm)
    signal.setitimer(signal.ITIMER_REAL, timeout)
    code: int | None
    try:
        with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
            try:
                code = main(argv)
            except SystemExit as e:  # argparse
                code = e.code if isinstance(e.code, int) else 2
    except _Timeout:
        code = None
    except Exception as e:  # noqa: BLE001 - escaped main: a crash
        code, escaped = 3, f"{type(e).__name__}: {e}"[:300]
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, old)
    return code, err.getvalue(), time.monotonic() - start, escaped


def classify(code: int | None, err: str, escaped: str) -> str | None:
    """The finding's kind, or None for an outcome that is fine."""
    if code is None:
        return "slow"
    if code == 3 or escaped or "Traceback (most recent call last)" in err:
        return "crash"
    if len(err) > 65536:
        return "huge"
    if code == 2:  # the first line that is not a note or a warning (nor one's quoted line) is the error
        lines = [ln for ln in err.split("\n") if ln and not ln.startswith(" ")]
        first = next((ln for ln in lines if not re.match(r"^(\S.*: )?(note|warning): ", ln)), "")
        if not (LOCATED.match(first) or UNPLACED.match(first)) or re.match(r"^.+:-?\d*-1:-?\d+:|^.+:\d+:-1:", first):
            return "unlocated"
        if first.startswith("error: ") and not first.startswith("error: cannot "):
            return "unlocated"  # a bare "error: …" from an input file: no position
    return None


def fuzz(runs: int, seed: int, timeout: float = 10.0, out: Path | None = None,
         only: tuple[str, ...] = (), log: Callable[[str], None] | None = None) -> dict[str, Tally]:
    """``runs`` mutants, spread over the languages in turn; the tallies per language."""
    rng = random.Random(seed)
    tallies: dict[str, Tally] = {}
    with tempfile.TemporaryDirectory(prefix="synth_fuzz_") as tmp:
        work = Path(tmp)
        languages = [lang for lang in _languages(work) if not only or lang.name in only]
        for n in range(runs):
            lang = languages[n % len(languages)]
            seed_input = rng.choice(lang.seeds)
            original = (ROOT / seed_input).read_text(encoding="utf-8") if lang.is_file else seed_input
            text = mutate(original, rng, TOKENS[lang.ext if lang.ext in TOKENS else lang.name])
            if lang.is_file:
                folder = work / f"in_{Path(seed_input).parent.as_posix().replace('/', '_')}"
                if not folder.exists():  # the original's siblings, for `use` and the like
                    folder.mkdir()
                    for sibling in (ROOT / seed_input).parent.iterdir():
                        if sibling.is_file():
                            os.symlink(sibling, folder / sibling.name)
                path = folder / f"mutant.{lang.ext}"
                path.write_bytes(text.encode("utf-8", errors="surrogatepass"))
                argv = lang.argv(str(path))
            else:
                argv = lang.argv(text)
            code, err, seconds, escaped = run_one(argv, timeout)
            t = tallies.setdefault(lang.name, Tally())
            t.runs += 1
            key = -1 if code is None else code
            t.codes[key] = t.codes.get(key, 0) + 1
            t.seconds += seconds
            t.longest = max(t.longest, seconds)
            kind = classify(code, err, escaped)
            if kind is not None:
                setattr(t, kind, getattr(t, kind) + 1)
                first = escaped or err.lstrip("\n").split("\n", 1)[0][:300]
                finding = {"run": n, "language": lang.name, "kind": kind, "from": seed_input, "message": first,
                           "argv": [a if len(a) < 300 else a[:300] + "…" for a in argv]}
                t.findings.append(finding)
                if out is not None:
                    out.mkdir(parents=True, exist_ok=True)
                    (out / f"{lang.name}_{n}.{lang.ext}").write_bytes(text.encode("utf-8", errors="surrogatepass"))
                    (out / f"{lang.name}_{n}.json").write_text(json.dumps(finding, ensure_ascii=False, indent=1))
                if log is not None:
                    log(f"{kind}: {lang.name} run {n} (from {seed_input}): {first}")
            if log is not None and (n + 1) % 500 == 0:
                log(f"{n + 1}/{runs} runs\n{report(tallies)}")
    return tallies


def report(tallies: dict[str, Tally]) -> str:
    lines = [f"{'language':<8} {'runs':>6} {'crash':>6} {'unloc':>6} {'slow':>5} {'huge':>5} {'exit 0/1/2':>14} "
             f"{'mean s':>7} {'max s':>6}"]
    total = Tally()
    for name, t in tallies.items():
        codes = f"{t.codes.get(0, 0)}/{t.codes.get(1, 0)}/{t.codes.get(2, 0)}"
        lines.append(f"{name:<8} {t.runs:>6} {t.crash:>6} {t.unlocated:>6} {t.slow:>5} {t.huge:>5} {codes:>14} "
                     f"{t.seconds / max(t.runs, 1):>7.3f} {t.longest:>6.2f}")
        for k in ("runs", "crash", "unlocated", "slow", "huge"):
            setattr(total, k, getattr(total, k) + getattr(t, k))
        total.seconds += t.seconds
    lines.append(f"{'all':<8} {total.runs:>6} {total.crash:>6} {total.unlocated:>6} {total.slow:>5} {total.huge:>5} "
                 f"{'':>14} {total.seconds:>7.0f} s in all")
    return "\n".join(lines) + "\n"


def cli(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--runs", type=int, default=2000)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--timeout", type=float, default=10.0, help="seconds before a run counts as slow (default 10)")
    ap.add_argument("--out", type=Path, help="keep each finding's input and command here")
    ap.add_argument("--only", default="", help="comma-separated languages (default: all nine)")
    ap.add_argument("--json", action="store_true", help="print the tallies as JSON")
    a = ap.parse_args(argv)
    only = tuple(x for x in a.only.split(",") if x)
    tallies = fuzz(a.runs, a.seed, a.timeout, a.out, only, log=lambda s: print(s, file=sys.stderr, flush=True))
    if a.json:
        print(json.dumps({k: {**vars(t), "codes": {str(c): n for c, n in t.codes.items()}} for k, t in tallies.items()},
                         indent=1, ensure_ascii=False))
    else:
        sys.stdout.write(report(tallies))
    return 1 if any(t.crash or t.unlocated or t.slow or t.huge for t in tallies.values()) else 0


if __name__ == "__main__":
    sys.exit(cli())
