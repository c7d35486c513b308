"""Random, well-formed rule sets for differential tests against libFAUDES."""

from __future__ import annotations

import random


def _literal(rng: random.Random, names: list[str]) -> str:
    n = rng.choice(names)
    return n if rng.random() < 0.5 else "!" + n


def _conj(rng: random.Random, names: list[str], k: int) -> str:
    return " & ".join(_literal(rng, names) for _ in range(k))


def random_rules(seed: int) -> str:
    """A rule set of 2-4 elements with orders, sensors, incoherences, rules,
    precedences, sometimes a free input or a held order, and 1-4 constraints."""
    rng = random.Random(seed)
    lines: list[str] = []
    orders_all: list[str] = []
    levels_all: list[str] = []
    for e in range(rng.randint(2, 4)):
        orders = [f"O{e}{i}" for i in range(rng.randint(1, 2))]
        sensors = [f"s{e}{i}" for i in range(rng.randint(1, 3))]
        lines.append(f"element E{e} {{")
        lines.append("  orders " + ", ".join(f"{o} = 0" for o in orders))
        init = {s: rng.random() < 0.3 for s in sensors}
        lines.append("  sensors " + ", ".join(f"{s} = {int(v)}" for s, v in init.items()))
        if len(sensors) >= 2 and rng.random() < 0.7:
            a, b = rng.sample(sensors, 2)
            if not (init[a] and init[b]):
                lines.append(f"  incoherent {a} & {b}")
        for _ in range(rng.randint(1, 5)):
            cause = rng.choice(["↑", "↓"]) + rng.choice(orders)
            cons = rng.choice(["↑", "↓"]) + rng.choice(sensors)
            guard = f" [{_conj(rng, sensors + orders, rng.randint(1, 2))}]" if rng.random() < 0.5 else ""
            lines.append(f"  {cause}{guard} -> {cons}")
        if len(sensors) >= 2 and rng.random() < 0.4:
            a, b = rng.sample(sensors, 2)
            lines.append(f"  ↑{orders[0]}: ↓{a} < ↑{b}")
        if rng.random() < 0.2:
            lines.append(f"  free f{e} = 0")
            levels_all.append(f"f{e}")
        lines.append("}")
        orders_all += orders
        levels_all += orders + sensors
    if rng.random() < 0.2:
        lines.append(f"hold {orders_all[-1]} = 1")
    for c in range(rng.randint(1, 4)):
        if rng.random() < 0.25:
            o = rng.choice([o for o in orders_all])
            expr = f"{rng.choice(['↑', '↓'])}{o} & {_literal(rng, levels_all)}"
        else:
            expr = _conj(rng, levels_all, rng.randint(1, 3))
        lines.append(f'constraint K{c} "random {c}": {expr} = 0')
    return "\n".join(lines) + "\n"
