"""CPU seconds of ``synth import`` on large SFC charts written the way PLC IDEs write them
(issue 37: any chart of at most 200 steps in under 2 s).

    python3 bench/import_scale.py [--tree DIR]... [--sizes 50,100,150,200,300] [--runs 3]
                                  [--dialect codesys,beremiz] [--write DIR]

The charts are generated here, in two dialects:

- ``codesys``: TC6 2.00 (``tc6_0200``, a CODESYS V3.5 export): conditions wired from FBD
  ``<inVariable>`` expressions and ``AND`` blocks with a negated input, step timers as inline
  ST ``S12.t >= T#2s``, vendor ``addData``;
- ``beremiz``: TC6 2.01 (``tc6_0201``, Beremiz/OpenPLC): every condition inline ST in
  ``<xhtml:p>`` CDATA, step timers ``S12.T >= T#2s``.

Both hold one program, an initial step and a loop of blocks back to it (a ``jumpStep``):
sequences, selection divergences of two to eight branches (the SFC priority rewrite and
its warning), simultaneous divergences of two to four branches of two steps, step timers; actions
``N``, ``S``, ``R`` on outputs and ``P`` inline bodies. Each ``synth import FILE -o OUT``
runs in a fresh process (that tree first on ``PYTHONPATH``, run from a neutral folder),
timed in CPU seconds (user + system of the child); trees and runs are interleaved and
the minimum is printed, with whether every tree wrote the same ``.g7`` and the same notes and
warnings (``--json``).
``--write DIR`` keeps the generated charts.
"""

from __future__ import annotations

import argparse
import sys
import tempfile
from pathlib import Path

from speed import _child  # one fresh process, its CPU seconds (bench/speed.py)

HEADERS = {
    "codesys": ('<project xmlns="http://www.plcopen.org/xml/tc6_0200">\n'
                '  <fileHeader companyName="" productName="CODESYS" productVersion="CODESYS V3.5 SP16 Patch 3" '
                'creationDateTime="2021-03-01T10:00:00.0000000" />\n'),
    "beremiz": ('<project xmlns="http://www.plcopen.org/xml/tc6_0201" xmlns:xhtml="http://www.w3.org/1999/xhtml">\n'
                '  <fileHeader companyName="Unknown" productName="Beremiz" productVersion="1.3" '
                'creationDateTime="2024-01-01T10:00:00" />\n'),
}


class Chart:
    """One SFC body being written: elements with their ``localId``, steps ``S1``, ``S2``..."""

    def __init__(self, dialect: str) -> None:
        self.dialect = dialect
        self.parts: list[str] = []
        self.next_id = 0
        self.steps = 0
        self.y = 0
        self.inputs: list[str] = []
        self.reads = 0
        self.outputs: list[str] = []

    def ident(self) -> int:
        self.next_id += 1
        return self.next_id

    def pos(self) -> str:
        self.y += 40
        return f'<position x="100" y="{self.y}" />'

    @staticmethod
    def into(ref: int, param: str | None = None) -> str:
        fp = f' formalParameter="{param}"' if param is not None else ""
        return f'<connectionPointIn><connection refLocalId="{ref}"{fp} /></connectionPointIn>'

    def sensor(self) -> str:
        """The next of the station's sensors, in turn (a chart reads the same end switches again
        and again: at most :data:`SENSORS`, within what the import's note explores)."""
        self.reads += 1
        name = f"x{self.reads % SENSORS}"
        if name not in self.inputs:
            self.inputs.append(name)
        return name

    def step(self, into: str, initial: bool = False) -> tuple[int, str]:
        self.steps += 1
        name = "Init" if initial else f"S{self.steps}"
        i = self.ident()
        head = f'<step localId="{i}" name="{name}"' + (' initialStep="true"' if initial else "") + ">"
        self.parts.append(f'{head}{self.pos()}{into}<connectionPointOut formalParameter="sfc" />'
                          '<connectionPointOutAction formalParameter="x" /></step>')
        self.actions(i, name, initial)
        return i, name

    def actions(self, step: int, name: str, initial: bool) -> None:
        """An action: N on a new output, S of a stored one (R in the initial step), a P inline body
        setting a new output (R in the next step)."""
        k = self.steps % 4
        lines = []
        if initial:
            lines.append(("R", '<reference name="BUSY" />'))
        elif k == 0:
            out = f"Y{len(self.outputs)}"
            self.outputs.append(out)
            lines.append(("N", f'<reference name="{out}" />'))
        elif k == 1:
            lines.append(("S", '<reference name="BUSY" />'))
        elif k == 2:
            out = f"P{len(self.outputs)}"
            self.outputs.append(out)
            lines.append(("P", self.inline(f"{out} := TRUE;")))
        elif self.outputs and self.outputs[-1].startswith("P"):
            lines.append(("R", f'<reference name="{self.outputs[-1]}" />'))
        if not lines:
            return
        body = "".join(f'<action localId="{self.ident()}" qualifier="{q}"><relPosition x="0" y="0" />{what}</action>'
                       for q, what in lines)
        self.parts.append(f'<actionBlock localId="{self.ident()}">{self.pos()}{self.into(step)}{body}</actionBlock>')

    def inline(self, st: str, condition: bool = False) -> str:
        head = '<inline name="">' if condition else "<inline>"
        if self.dialect == "beremiz":
            return f"{head}<ST><xhtml:p><![CDATA[{st}]]></xhtml:p></ST></inline>"
        return f'{head}<ST><xhtml xmlns="http://www.w3.org/1999/xhtml">{st}</xhtml></ST></inline>'

    def condition(self, kind: str, step_name: str = "") -> str:
        """The ``<condition>`` of a transition: a sensor, a sensor and a negated one, or a step timer."""
        if kind == "timer":
            seconds = 1 + self.steps % 3
            t = "t" if self.dialect == "codesys" else "T"
            return f"<condition>{self.inline(f'{step_name}.{t} >= T#{seconds}s', True)}</condition>"
        a = self.sensor()
        b = self.sensor() if kind == "and" else ""
        if self.dialect == "beremiz":
            st = f"{a} AND NOT {b}" if b else a
            return f"<condition>{self.inline(st, True)}</condition>"
        if not b:
            v = self.ident()
            self.parts.append(f'<inVariable localId="{v}">{self.pos()}<connectionPointOut /><expression>{a}</expression>'
                              '</inVariable>')
            return f"<condition>{self.into(v)}</condition>"
        va, vb, blk = self.ident(), self.ident(), self.ident()
        for v, name in ((va, a), (vb, b)):
            self.parts.append(f'<inVariable localId="{v}">{self.pos()}<connectionPointOut /><expression>{name}'
                              '</expression></inVariable>')
        self.parts.append(
            f'<block localId="{blk}" typeName="AND">{self.pos()}<inputVariables>'
            f'<variable formalParameter="IN1">{self.into(va)}</variable>'
            f'<variable formalParameter="IN2" negated="true">{self.into(vb)}</variable>'
            '</inputVariables><inOutVariables /><outputVariables><variable formalParameter="OUT"><connectionPointOut />'
            '</variable></outputVariables></block>')
        return f"<condition>{self.into(blk)}</condition>"

    def transition(self, into: str, kind: str, step_name: str = "") -> int:
        cond = self.condition(kind, step_name)
        i = self.ident()
        self.parts.append(f'<transition localId="{i}">{self.pos()}{into}<connectionPointOut />{cond}</transition>')
        return i

    def sequence(self, at: tuple[int, str], kind: str) -> tuple[int, str]:
        t = self.transition(self.into(at[0]), kind, at[1])
        return self.step(self.into(t))

    def selection(self, at: tuple[int, str], branches: int) -> tuple[int, str]:
        """A selection divergence from ``at``: each branch a transition, a step and a transition."""
        div = self.ident()
        outs = "".join(f'<connectionPointOut formalParameter="{b}" />' for b in range(branches))
        self.parts.append(f'<selectionDivergence localId="{div}">{self.pos()}{self.into(at[0])}{outs}</selectionDivergence>')
        ends = []
        for b in range(branches):
            t = self.transition(self.into(div, str(b)), "and" if b == 0 else "one")
            s = self.step(self.into(t))
            ends.append(self.transition(self.into(s[0]), "timer" if b == 1 else "one", s[1]))
        conv = self.ident()
        ins = "".join(self.into(e) for e in ends)
        self.parts.append(f'<selectionConvergence localId="{conv}">{self.pos()}{ins}<connectionPointOut />'
                          '</selectionConvergence>')
        return self.step(self.into(conv))

    def simultaneous(self, at: tuple[int, str], branches: int) -> tuple[int, str]:
        """A simultaneous divergence after a transition from ``at``: each branch two steps."""
        t = self.transition(self.into(at[0]), "one")
        div = self.ident()
        outs = "".join(f'<connectionPointOut formalParameter="{b}" />' for b in range(branches))
        self.parts.append(f'<simultaneousDivergence localId="{div}">{self.pos()}{self.into(t)}{outs}'
                          '</simultaneousDivergence>')
        lasts = []
        for b in range(branches):
            first = self.step(self.into(div, str(b)))
            lasts.append(self.sequence(first, "one")[0])
        conv = self.ident()
        ins = "".join(self.into(s) for s in lasts)
        self.parts.append(f'<simultaneousConvergence localId="{conv}">{self.pos()}{ins}<connectionPointOut />'
                          '</simultaneousConvergence>')
        t2 = self.transition(self.into(conv), "and")
        return self.step(self.into(t2))


SENSORS = 16
"""The sensors a chart reads."""
SELECTION_WIDTHS = (2, 3, 2, 4, 2, 8)
"""Branches of the successive selection divergences (a mode selector has eight)."""
SIMULTANEOUS_WIDTHS = (2, 3, 4)
"""Branches of the successive simultaneous divergences."""


def chart_xml(steps: int, dialect: str) -> str:
    """A PLCopen project of one SFC program of ``steps`` steps in ``dialect``'s shape."""
    c = Chart(dialect)
    at = c.step("", initial=True)
    block = 0
    while c.steps < steps:
        room = steps - c.steps
        kind = block % 5
        wide = SELECTION_WIDTHS[block // 5 % len(SELECTION_WIDTHS)]
        par = SIMULTANEOUS_WIDTHS[block // 5 % len(SIMULTANEOUS_WIDTHS)]
        if kind == 1 and room >= wide + 1:
            at = c.selection(at, wide)
        elif kind == 3 and room >= 2 * par + 1:
            at = c.simultaneous(at, par)
        elif kind == 4:
            at = c.sequence(at, "timer")
        else:
            at = c.sequence(at, "and" if block % 2 else "one")
        block += 1
    t = c.transition(c.into(at[0]), "one")
    c.parts.append(f'<jumpStep localId="{c.ident()}" targetName="Init">{c.pos()}{c.into(t)}</jumpStep>')
    var = "".join(f'<variable name="{n}"><type><BOOL /></type></variable>' for n in c.inputs)
    out = "".join(f'<variable name="{n}"><type><BOOL /></type></variable>' for n in [*c.outputs, "BUSY"])
    body = "\n            ".join(c.parts)
    return (f'<?xml version="1.0" encoding="utf-8"?>\n{HEADERS[dialect]}'
            f'  <contentHeader name="Station{steps}" modificationDateTime="2024-01-01T10:00:00" />\n'
            '  <types>\n    <dataTypes />\n    <pous>\n'
            f'      <pou name="Station" pouType="program">\n        <interface>\n'
            f'          <inputVars>{var}</inputVars>\n          <outputVars>{out}</outputVars>\n        </interface>\n'
            f'        <body>\n          <SFC>\n            {body}\n          </SFC>\n        </body>\n      </pou>\n'
            '    </pous>\n  </types>\n  <instances><configurations /></instances>\n</project>\n')


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--tree", action="append", type=Path, help="a synth source tree (default: this one); repeat to compare")
    ap.add_argument("--sizes", default="50,100,150,200,300")
    ap.add_argument("--dialect", default="codesys,beremiz")
    ap.add_argument("--runs", type=int, default=3)
    ap.add_argument("--timeout", type=float, default=600.0, help="seconds per process")
    ap.add_argument("--write", type=Path, help="keep the generated charts in this folder")
    args = ap.parse_args()
    trees = args.tree or [Path(__file__).resolve().parent.parent]
    with tempfile.TemporaryDirectory() as tmp:
        work = args.write or Path(tmp)
        work.mkdir(parents=True, exist_ok=True)
        for dialect in args.dialect.split(","):
            for n in [int(s) for s in args.sizes.split(",") if s]:
                xml = work / f"{dialect}_{n}.xml"
                xml.write_text(chart_xml(n, dialect), encoding="utf-8")
                best: dict[Path, float] = {}
                outputs: dict[Path, tuple[str, str, int]] = {}
                for _ in range(args.runs):
                    for tree in trees:
                        g7 = Path(tmp) / "out.g7"  # one name: --json prints it
                        g7.unlink(missing_ok=True)
                        seconds, out, code = _child(tree, ["-m", "synth", "import", str(xml), "-o", str(g7), "--json"],
                                                    args.timeout)
                        outputs[tree] = (g7.read_text() if g7.exists() else "", out, code)
                        best[tree] = min(best.get(tree, seconds), seconds)
                same = len({v for v in outputs.values()}) == 1
                for tree in trees:
                    code = outputs[tree][2]
                    state = "timeout" if code == -1 else f"exit {code}"
                    print(f"{dialect:8} {n:4} steps  {str(tree):34} {best[tree]:6.2f} CPU s  {state}"
                          + ("" if len(trees) == 1 else ("  same output" if same else "  OUTPUT DIFFERS")), flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
