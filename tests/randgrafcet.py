"""Random Grafcets for the differential test of the generated ST (``tests/test_codegen_differential.py``).

Every construct the code generator maps: OR and AND divergences/convergences, source and sink
transitions, level and edge receptivities, step variables across partial grafcets, timers,
continuous, conditional and stored actions (on activation, deactivation and events).
Inputs are lower case (a, b, c), outputs upper case (P, Q, R assigned; M, N stored).
"""

from __future__ import annotations

import random

INPUTS = ("a", "b", "c")
ASSIGNED = ("P", "Q", "R")
STORED = ("M", "N")
DURATIONS = ("500ms", "1s", "2s")


def _atom(rng: random.Random, steps: list[str], src: list[str], edges: bool, data: bool = False) -> str:
    if data and rng.random() < 0.3:
        return rng.choice(("k >= 1", "k < 2", "k = 0", "k <> 2", "f", "!f"))
    r = rng.random()
    if edges and r < 0.25:
        return rng.choice("↑↓") + rng.choice(INPUTS)
    if r < 0.55:
        return rng.choice(("", "!")) + rng.choice(INPUTS)
    if r < 0.75:
        return rng.choice(("", "!")) + "X" + rng.choice(steps)
    if r < 0.93:
        step = rng.choice(src) if src and rng.random() < 0.8 else rng.choice(steps)
        return f"{rng.choice(DURATIONS)}/X{step}"
    return rng.choice("01")


def _expr(rng: random.Random, steps: list[str], src: list[str], edges: bool = True, data: bool = False) -> str:
    parts = [_atom(rng, steps, src, edges, data) for _ in range(rng.randint(1, 3))]
    if len(parts) == 1:
        return parts[0]
    if len(parts) == 3 and rng.random() < 0.5:
        return f"({parts[0]} + {parts[1]}) . {parts[2]}"
    return rng.choice((" . ", " + ")).join(parts)


ASSIGNMENTS = ("k := k + 1", "k := k - 1 on deactivation", "k := 0", "k := k + 1 on ↑a", "f := 1",
               "f := 0 on deactivation", "set f on ↓b", "reset f")


def random_grafcet(seed: int, data: bool = False) -> str:
    """The ``.g7`` text of a random Grafcet (deterministic in ``seed``); with ``data``, the
    internal variables ``k : 0..2`` and ``f : bool``, assignments and comparisons.

    >>> random_grafcet(1) == random_grafcet(1), "grafcet G1" in random_grafcet(1)
    (True, True)
    >>> "internal k : 0..2" in random_grafcet(1, data=True)
    True
    """
    rng = random.Random(seed)
    sizes = [rng.randint(2, 3)] + ([2] if rng.random() < 0.35 else [])
    names = [[f"{10 * (g + 1) + i}" for i in range(n)] for g, n in enumerate(sizes)]
    every = [s for group in names for s in group]
    lines = [f"inputs {', '.join(INPUTS)}", f"outputs {', '.join(ASSIGNED + STORED)}"]
    if data:
        lines += ["internal k : 0..2 = 0", "internal f : bool"]
    for g, steps in enumerate(names):
        lines.append(f"grafcet G{g + 1} {{")
        for i, s in enumerate(steps):
            actions = []
            for _ in range(rng.choice((0, 1, 1))):
                kind = rng.random()
                if data and kind < 0.4:
                    actions.append(rng.choice(ASSIGNMENTS))
                elif kind < 0.4:
                    actions.append(rng.choice(ASSIGNED))
                elif kind < 0.6:
                    actions.append(f"{rng.choice(ASSIGNED)} if {_expr(rng, every, [s], edges=False, data=data)}")
                elif kind < 0.8:
                    verb = rng.choice(("set", "reset"))
                    when = rng.choice(("", " on activation", " on deactivation"))
                    actions.append(f"{verb} {rng.choice(STORED)}{when}")
                else:
                    verb = rng.choice(("set", "reset"))
                    actions.append(f"{verb} {rng.choice(STORED)} on {rng.choice('↑↓')}{rng.choice(INPUTS)}")
            initial = "initial " if i == 0 else ""
            lines.append(f"  {initial}step {s}" + (": " + ", ".join(dict.fromkeys(actions)) if actions else ""))
        trans: list[tuple[list[str], list[str]]] = [([s], [steps[(i + 1) % len(steps)]]) for i, s in enumerate(steps)]
        for _ in range(rng.randint(0, 2) if len(steps) > 2 else rng.randint(0, 1)):
            r = rng.random()
            if r < 0.35:  # OR divergence
                trans.append(([rng.choice(steps)], [rng.choice(steps)]))
            elif r < 0.6 and len(steps) >= 3:  # AND divergence
                trans.append(([rng.choice(steps)], rng.sample(steps, 2)))
            elif r < 0.85 and len(steps) >= 3:  # AND convergence
                trans.append((rng.sample(steps, 2), [rng.choice(steps)]))
            elif r < 0.93:  # source transition, on an edge
                trans.append(([], [rng.choice(steps)]))
            else:  # sink transition
                trans.append(([rng.choice(steps)], []))
        seen = set()
        for src, dst in trans:
            if src == dst or (tuple(src), tuple(dst)) in seen:
                continue
            seen.add((tuple(src), tuple(dst)))
            rec = _expr(rng, every, src, data=data)
            if not src:
                rec = f"{rng.choice('↑↓')}{rng.choice(INPUTS)}"
            lines.append(f"  transition {', '.join(src)} -> {', '.join(dst)} when {rec}")
        lines.append("}")
    return "\n".join(lines) + "\n"


def check_seed(seed: int, depth: int = 3, data: bool = False, semantics: str = "grafcet") -> tuple[int, int, int, str]:
    """The differential check of ``random_grafcet(seed)`` (compact ST): (seed, sequences,
    cycles, mismatch text or ""). A top-level function, so a process pool can run it."""
    from synth.codegen.check import differential_check
    from synth.codegen.grafcet_st import generate_program
    from synth.grafcet.language_check import parse_grafcet

    g = parse_grafcet(random_grafcet(seed, data), f"random{seed}.g7", semantics=semantics)
    report = differential_check(g, depth=depth, program=generate_program(g, version="test", comments=False))
    return seed, report.sequences, report.cycles, "" if report.ok else report.text()


def constructs(text: str) -> set[str]:
    """The constructs of the generator found in one of its Grafcets (``random_grafcet``'s
    text): what the differential's sample must cover.

    >>> sorted(constructs("grafcet G1 {\\n  initial step 10: P, set M on ↑a\\n  step 11\\n"
    ...                   "  transition 10 -> 11 when 1s/X10 . !b\\n  transition -> 11 when ↓c\\n}\\n"))
    ['AND in a receptivity', 'a negation', 'a source transition', 'a stored action on an event', 'a timer in a receptivity', 'a timer of 1s', 'an OR convergence', 'an edge receptivity', 'continuous action']
    """
    import re

    found: set[str] = set()
    trans = [line.split("transition ", 1)[1] for line in text.splitlines() if line.startswith("  transition ")]
    moves = [tuple(tuple(side.strip().split(", ")) if side.strip() else () for side in t.split(" when ")[0].split("->"))
             for t in trans]
    sources = [src for src, _ in moves if src]
    targets = [dst for _, dst in moves if dst]
    checks = {
        "an AND divergence": any(len(dst) > 1 for _, dst in moves),
        "an AND convergence": any(len(src) > 1 for src, _ in moves),
        "an OR divergence": len(set(sources)) < len(sources),
        "an OR convergence": len(set(targets)) < len(targets),
        "a source transition": any(not src for src, _ in moves),
        "a sink transition": any(not dst for _, dst in moves),
        "partial grafcets": text.count("grafcet G") > 1,
    }
    found |= {name for name, held in checks.items() if held}
    for t in trans:
        rec = t.split(" when ", 1)[1]
        found |= {name for name, pattern in (
            ("an edge receptivity", "[↑↓][abc]"), ("a step variable in a receptivity", r"(^|[ !(])X\d"),
            ("a timer in a receptivity", "/X"), ("a constant", r"(^|[ (])[01]($|[ )])"), ("a negation", "!"),
            ("(a + b) . c", r"\("), ("OR in a receptivity", r" \+ "), ("AND in a receptivity", r" \. "),
        ) if re.search(pattern, rec)}
    found |= {f"a timer of {d}" for d in DURATIONS if re.search(rf"\b{d}/X", text)}
    for line in text.splitlines():
        if not re.match(r"  (initial )?step \d+: ", line):
            continue
        for action in line.split(": ", 1)[1].split(", "):
            if action in ASSIGNED:
                found.add("continuous action")
            elif " if " in action:
                found.add("a conditional action")
                condition = action.split(" if ", 1)[1]
                found |= {"a timer in a condition"} if "/X" in condition else set()
                found |= {"a step variable in a condition"} if re.search(r"(^|[ !(])X\d", condition) else set()
            elif action.startswith(("set ", "reset ")):
                when = action.split(" on ", 1)[1] if " on " in action else ""
                found.add({"": "a stored action while active", "activation": "a stored action on activation",
                           "deactivation": "a stored action on deactivation"}.get(when, "a stored action on an event"))
    return found
