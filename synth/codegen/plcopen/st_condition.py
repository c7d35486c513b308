"""The ST of an imported SFC's conditions and actions, read into ``.g7`` expressions: a
small recursive-descent reader for NOT, AND/&, OR, parentheses, TRUE/FALSE, names,
``S12.X``, ``S12.T >= T#2s`` and the edge flags ``_RE_x``/``_FE_x``, each error located
in the XML file.

Why not blark: its Earley parser takes seconds on a project's worth of conditions and its
tree would need a second mapping; this reader knows exactly the subset ``.g7`` can hold
and says where the rest is.
"""

from __future__ import annotations

import contextvars
import re

from synth.codegen.plcopen.data import DATA, duration
from synth.errors import InputError, Location, Severity, close_names

__all__ = ["st_text", "ExprReader", "PREDICATES", "predicate_name"]


def st_text(el) -> str:
    """The text of a formattedText-like element (``<ST><xhtml:p>…</xhtml:p></ST>`` or plain text)."""
    return "".join(el.itertext())


# A tiny reader for the ST expressions of conditions: NOT, AND/&, OR, parentheses, TRUE/FALSE,
# names, S12.X, S12.T >= T#2s, _RE_x/_FE_x.
_TOKEN = re.compile(r"\s*(?:(?P<dur>T#[0-9A-Za-z_.]+)|(?P<name>[A-Za-z_]\w*(?:\.[A-Za-z_]\w*)?)"
                    r"|(?P<num>\d+(?:\.\d+)?(?:[eE][+-]?\d+)?)"
                    r"|(?P<op>>=|<=|<>|:=|[()&>=<;+\-*/]))", re.I)
_COMPARE = {">": "gt", ">=": "ge", "<": "lt", "<=": "le", "=": "eq", "<>": "ne"}
_FLIP = {">": "<", ">=": "<=", "<": ">", "<=": ">=", "=": "=", "<>": "<>"}

PREDICATES: contextvars.ContextVar[dict[str, tuple[str, Location]] | None] = contextvars.ContextVar(
    "PREDICATES", default=None)
"""While a chart is read (``synth import``): the comparisons met, each a *declared predicate*
(a Boolean input named after it: ``rPos > 24290.0`` is ``rPos_gt_24290_0``) with the text it
stands for and where it is; outside, a comparison is an error."""


def predicate_name(name: str, op: str, operand: str) -> str:
    """The input that stands for ``name op operand``.

    >>> predicate_name("rPos", ">", "24290.0"), predicate_name("Cnt", "<>", "-3")
    ('rPos_gt_24290_0', 'Cnt_ne_m3')
    """
    literal = operand.replace(".", "_").replace("-", "m").replace("+", "")
    return re.sub(r"_+", "_", f"{name}_{_COMPARE[op]}_{literal}")


class ExprReader:
    def __init__(self, text: str, where, steps: dict[str, str], what: str = "an ST condition") -> None:
        # comments become spaces, so that offsets still point into the original text
        text = re.sub(r"\(\*.*?\*\)|//[^\n]*", lambda m: re.sub(r"[^\n]", " ", m[0]), text, flags=re.S)
        self.text, self.where, self.steps, self.what = text, where, steps, what
        self.tokens: list[tuple[str, str, int]] = []
        data = re.search(r"(?<![:<>])(<>|>=|<=|<(?![=>])|>(?!=)|=)(?!\s*(?:T#|(?:TRUE|FALSE)\b))", text, re.I)
        if data is not None and PREDICATES.get() is None:
            raise self.error(data.start(), f"a comparison of data in {what} ({' '.join(text.split())}): .g7 reads "
                             "Boolean inputs and step flags; numeric values are not read yet", width=len(data[1]))
        pos = 0
        while pos < len(text):
            if not text[pos:].strip():
                break
            m = _TOKEN.match(text, pos)
            if not m or m.end() == pos:
                raise self.error(len(text) - len(text[pos:].lstrip()), f"unexpected character in {self.what}")
            kind = m.lastgroup or ""
            self.tokens.append((kind, m[kind], m.start(kind)))
            pos = m.end()
        self.i = 0

    def error(self, offset: int, message: str, width: int = 1, **kw) -> InputError:
        return InputError(message, self.where(offset, width), **kw)

    def peek(self) -> tuple[str, str, int]:
        return self.tokens[self.i] if self.i < len(self.tokens) else ("end", "", len(self.text.rstrip()))

    def take(self) -> tuple[str, str, int]:
        tok = self.peek()
        self.i += 1
        return tok

    def expr(self) -> str:
        parts = [self.xor()]
        while self.peek()[1].upper() == "OR":
            self.take()
            parts.append(self.xor())
        return " | ".join(parts)

    def xor(self) -> str:
        """``a XOR b`` (between OR and AND in ST): ``a & !b | !a & b``."""
        out = self.conj()
        while self.peek()[1].upper() == "XOR":
            self.take()
            right = self.conj()
            a, b = (x if re.fullmatch(r"[!\w↑↓/.]+", x) else f"({x})" for x in (out, right))
            out = f"{a} & !{b} | !{a} & {b}"
        return out

    def conj(self) -> str:
        parts = [self.unary()]
        while self.peek()[1].upper() in ("AND", "&"):
            self.take()
            parts.append(self.unary())
        return " & ".join(f"({p})" if " | " in p else p for p in parts)

    def unary(self) -> str:
        if self.peek()[1].upper() == "NOT":
            self.take()
            inner = self.unary()
            return "!" + (inner if re.fullmatch(r"[!\w↑↓/.]+", inner) else f"({inner})")
        return self.primary()

    def primary(self) -> str:
        kind, value, offset = self.take()
        if value == "(":
            inner = self.expr()
            k, v, o = self.take()
            if v != ")":
                raise self.error(o, f"expected ')' in {self.what}", expected=("')'",))
            return inner if re.fullmatch(r"[!\w↑↓/.]+", inner) else f"({inner})"
        following = self.peek()[1]
        if following in ("=", "<>") and kind == "name" and self.i + 1 < len(self.tokens) and \
                self.tokens[self.i + 1][1].upper() in ("TRUE", "FALSE"):  # a Boolean compared with a literal
            self.take()
            literal = self.take()[1].upper()
            inner = self.boolean(kind, value, offset)
            return inner if (literal == "TRUE") == (following == "=") else "!" + inner
        return self.boolean(kind, value, offset)

    def boolean(self, kind: str, value: str, offset: int) -> str:
        """A name, a step flag, a timer, a constant or a comparison (the token just taken)."""
        following = self.peek()[1]
        scope = DATA.get()
        if following in _COMPARE and scope is not None:
            compared = self.compare(kind, value)
            if compared is not None:
                return compared
        if kind == "name" and scope is not None and "." not in value:
            if value.upper() in scope.timers:
                return scope.timers[value.upper()]
            if value.upper() in scope.step_timers:
                return self.step_timer(value, offset)
            known = scope.vars.get(value.upper())
            if known is not None:
                if not known.boolean:
                    raise self.error(offset, f"{value} is an integer ({known.low}..{known.high}): compare it, e.g. "
                                     f"{value} >= 1", width=len(value))
                return scope.find(value).name  # type: ignore[union-attr]
            value = scope.spelling.get(value.upper(), value)  # ST names ignore case
        if kind == "name" and scope is not None and "." in value and value.split(".")[0] not in self.steps \
                and value.split(".")[0].upper() in scope.global_lists:
            return scope.global_name(value, False, self.where(offset, len(value)))
        if kind == "name" and scope is not None and "." in value and value.split(".")[0] not in self.steps \
                and value.split(".")[0].upper() in scope.spelling and value.split(".")[1].upper() not in ("X", "T"):
            return scope.member_read(value, self.where(offset, len(value)))
        if following in _COMPARE and PREDICATES.get() is not None and (kind == "num" or (kind == "name" and "." not in value)):
            return self.predicate(kind, value, offset)
        if kind == "num" and value in ("0", "1"):
            return value
        if kind == "name":
            up = value.upper()
            if up in ("TRUE", "FALSE"):
                return "1" if up == "TRUE" else "0"
            if up in ("AND", "OR", "NOT", "XOR", "MOD"):
                raise self.error(offset, f"{up} is not supported in a .g7 receptivity" if up == "MOD"
                                 else f"expected a variable, not {up}", width=len(value))
            if "." in value:
                step_name, member = value.split(".")
                step = self.steps.get(step_name)
                if step is None:
                    raise self.error(offset, f"unknown step '{step_name}'", width=len(step_name),
                                     suggestions=close_names(step_name, self.steps))
                if member.upper() == "X":
                    return f"X{step}"
                if member.upper() == "T":
                    k, op, o = self.take()
                    k, dur, o2 = self.take()
                    return self.step_time(value, step, op, dur, o, o2, offset)
                raise self.error(offset, f"unsupported step member .{member} (use .X or .T)", width=len(value))
            if value.startswith("_RE_") or value.startswith("_FE_"):
                return ("↑" if value.startswith("_RE_") else "↓") + value[4:]
            return value
        if kind == "dur" and following in _COMPARE and self.i + 1 < len(self.tokens) and \
                re.fullmatch(r"\w+\.T", self.tokens[self.i + 1][1], re.I) and \
                self.tokens[self.i + 1][1].split(".")[0] in self.steps:  # T#2s < Step0.t
            _, op, o = self.take()
            _, name, o2 = self.take()
            return self.step_time(name, self.steps[name.split(".")[0]], _FLIP[op], value, o, offset, o2)
        raise self.error(offset, f"expected a variable, a step flag or '(' in {self.what}, not '{value or 'end'}'",
                         width=max(1, len(value)))

    def step_time(self, member: str, step: str, op: str, dur: str, at_op: int, at_dur: int, start: int) -> str:
        """``S.T op D`` (``member`` is ``S.T``): the step timer ``D/XS`` or its negation."""
        if op not in ("<", "<=", ">", ">="):
            raise self.error(at_op, f"a step time {member} is compared with '{op or 'nothing'}': only < <= > >= with a "
                             "duration have a step-timer meaning (D/XS, or its negation)", expected=("'>='", "'>'",
                                                                                                   "'<'", "'<='"))
        d = duration(dur)
        if d is None:
            raise self.error(at_dur, "expected a duration such as T#2s or T#500ms", width=max(1, len(dur)))
        timer = f"{d}/X{step}"
        scope = DATA.get()
        first = min(start, at_dur)
        text = " ".join(self.text[first:max(start + len(member), at_dur + len(dur))].split())
        if op != ">=" and scope is not None:
            scope.warnings.append(InputError(
                f"{text} is read as {'' if op.startswith('>') else '!'}{timer}: {op} and "
                f"{'>=' if op.startswith('>') else '<' if op == '<=' else '<='} differ only at the instant the step has "
                "been active exactly that long, the same at this abstraction (a step timer elapses once)",
                self.where(first, len(text)), severity=Severity.WARNING))
        return timer if op.startswith(">") else f"!{timer}"

    def step_timer(self, value: str, offset: int) -> str:
        """A TON alias set in several steps (``interconnect := T.Q`` after each): the timer of
        the step the transition being read leaves."""
        scope = DATA.get()
        assert scope is not None
        timers = scope.step_timers[value.upper()]
        found = [timers[s] for s in scope.sources if s in timers]
        if len(found) != 1:
            raise self.error(offset, f"{value} stands for a TON's Q in steps {', '.join(timers)}: read here "
                             f"{'outside a transition' if not scope.sources else 'by a transition leaving ' + ', '.join(scope.sources)}"
                             ", it has no one step timer", width=len(value))
        return found[0]

    def compare(self, kind: str, value: str) -> str | None:
        """``Cnt >= 5`` (or ``5 <= Cnt``) of integer internal variables
        (:data:`~synth.codegen.plcopen.data.DATA`): its ``.g7`` text; None when it is not one."""
        scope = DATA.get()
        assert scope is not None
        j, sign = self.i + 1, ""
        if j < len(self.tokens) and self.tokens[j][1] in ("-", "+"):
            sign, j = self.tokens[j][1].replace("+", ""), j + 1
        if j >= len(self.tokens):
            return None
        op = self.tokens[self.i][1]
        k2, v2, _ = self.tokens[j]
        left = scope.vars.get(value.upper()) if kind == "name" else None
        right = scope.vars.get(v2.upper()) if k2 == "name" else None
        if k2 == "name" and right is None and v2.upper() in scope.constants:  # VAR CONSTANT: its value
            number = scope.constants[v2.upper()] * (-1 if sign == "-" else 1)
            k2, v2, sign = "num", str(abs(number)), "-" if number < 0 else ""
        if left is not None and not left.boolean and k2 == "num" and v2.isdigit():
            text = f"{left.name} {op} {sign}{int(v2)}"
        elif left is not None and not left.boolean and right is not None and not right.boolean and not sign:
            text = f"{left.name} {op} {right.name}"
        elif kind == "num" and value.isdigit() and right is not None and not right.boolean and not sign:
            text = f"{right.name} {_FLIP[op]} {int(value)}"
        elif kind == "name" and left is None and value.upper() in scope.constants and right is not None \
                and not right.boolean and not sign:  # VAR CONSTANT on the left
            text = f"{right.name} {_FLIP[op]} {scope.constants[value.upper()]}"
        else:
            return None
        for v in (left, right):
            if v is not None:
                scope.find(v.name)
        self.i = j + 1
        return text

    def predicate(self, kind: str, value: str, offset: int) -> str:
        """``a > 24290.0`` (or ``24290.0 < a``): a declared predicate, recorded in PREDICATES."""
        _, op, _ = self.take()
        k2, v2, o2 = self.take()
        sign = ""
        if v2 in ("-", "+"):
            sign = "-" if v2 == "-" else ""
            k2, v2, o2 = self.take()
        if k2 not in ("num", "name") or (kind == "num" and k2 != "name"):
            raise self.error(o2, f"expected a variable or a number after '{op}' in {self.what}")
        if kind == "num":  # 24290.0 < a is a > 24290.0
            name, op, operand = v2, _FLIP[op], value
        else:
            name, operand = value, sign + v2
        ident = predicate_name(name, op, operand)
        found = PREDICATES.get()
        assert found is not None
        end = o2 + len(v2)
        found.setdefault(ident, (" ".join(self.text[offset:end].split()), self.where(offset, end - offset)))
        return ident

    def whole(self) -> str:
        out = self.expr()
        kind, value, offset = self.peek()
        if kind != "end":
            before = self.tokens[self.i - 1] if self.i else None
            if kind == "name" and before is not None and before[0] == "name":
                raise self.error(offset, f"unexpected '{value}' in {self.what}: '{before[1]} {value}' is two names in a "
                                 "row, not an ST expression (an operator is missing)", width=len(value))
            raise self.error(offset, f"unexpected '{value}' in {self.what}", width=len(value))
        return out
