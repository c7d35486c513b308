r"""Checking the rules language: ``use`` files, models and instances resolved, then every
name, ownership, precedence and constraint checked, all errors of a file reported together;
``load_rules`` / ``parse_rules``.

``load_rules(path)`` reads a ``.rules`` file (and the files it ``use``-s), checks it and
returns an immutable :class:`~synth.plant.rules.RuleSet`. Every mistake is an
:class:`~synth.errors.InputError` pointing at the offending token.

Example
-------
>>> text = '''
... element V3 {
...   order AVANCER3 = 0
...   sensor v30 = 1, v31 = 0
...   incoherent v30 & v31
...   ↑AVANCER3 [v30] -> ↓v30
...   ↑AVANCER3 [!v30 & !v31] -> ↑v31
...   ↓AVANCER3 [v31] -> ↓v31
...   ↓AVANCER3 [!v30 & !v31] -> ↑v30
... }
... constraint C1 "never out": v31 = 0
... '''
>>> rs = parse_rules(text, "v3.rules")
>>> [e.name for e in rs.elements], [c.id for c in rs.constraints]
(['V3'], ['C1'])
>>> c = RulesChecker()
>>> c.collect(rules_items("element E { sensor a = 0 }\nconstraint K: b = 0", "x.rules"), None)
>>> c.check()
>>> [e.message for e in c.errors]
["constraint K uses undeclared variable 'b'"]
"""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path
from typing import Mapping

from synth.errors import InputError, Location, close_names, location_in
from synth.logic.expr import Edge, Expr, NegatedEdge, NormalFormTooLarge, Var, disjunctive_normal_form, evaluate, names, renamed
from synth.plant.library import library_file
from synth.plant.rules import Constraint, ElementSpec, Precedence, Read, Rule, RuleSet, VarDecl, VarKind
from synth.plant.rules_reader import Hold, Inline, Instance, Item, Model, Use, Vector, rules_items
from synth.syntax import Checker, VectorKind, read_source

__all__ = ["RulesChecker", "parse_rules", "load_rules"]


class RulesChecker(Checker):
    """Resolves ``use``, models and instances, then checks names and ownership."""

    def __init__(self) -> None:
        super().__init__()
        self.models: dict[str, Model] = {}
        self.elements: list[ElementSpec] = []
        self.constraints: list[Constraint] = []
        self.holds: list[VarDecl] = []
        self.top_free: list[VarDecl] = []
        self.vectors: list[Vector] = []
        self.order: tuple[str, ...] = ()
        self.loaded: set[Path] = set()
        # new names given by instance renamings: name -> (element, model variable, location)
        self.renamed: dict[str, tuple[str, str, Location]] = {}
        # uses of names no element declares, in vectors and constraints: (name, error)
        self.unknown_uses: list[tuple[str, InputError]] = []

    # ---- collection
    def collect(self, items: list[Item], base: Path | None) -> None:
        for it in items:
            if isinstance(it, Use):
                self.use(it, base)
            elif isinstance(it, Model):
                if it.name in self.models:
                    self.fail(
                        f"model '{it.name}' is defined twice",
                        it.loc,
                        notes=(f"first defined at {self.models[it.name].loc}",),
                    )
                else:
                    self.models[it.name] = it
            elif isinstance(it, Inline):
                self.add_element(ElementSpec(it.name, it.body.decls, it.body.incoherences, it.body.rules, it.body.precedences, it.loc,
                                             reads=it.body.reads))
            elif isinstance(it, Instance):
                self.instantiate(it)
            elif isinstance(it, Hold):
                self.holds.extend(it.decls)
            elif isinstance(it, tuple):  # top-level free inputs
                self.top_free.extend(it)
            elif isinstance(it, Constraint):
                self.constraints.append(it)
            elif isinstance(it, Vector):
                self.vectors.append(it)

    def use(self, u: Use, base: Path | None) -> None:
        try:
            target = library_file(u.path, base)
            resolved = target.resolve()
        except (OSError, ValueError) as exc:  # a name too long, a NUL byte
            self.fail(f"cannot read {u.path[:200]!r}: {getattr(exc, 'strerror', None) or exc}", u.loc)
            return
        if resolved in self.loaded:
            return
        try:
            source = read_source(target, u.loc)
        except InputError as err:
            self.errors.append(err)
            return
        self.loaded.add(resolved)
        try:
            items = rules_items(source, str(target))
        except InputError as err:
            self.errors.append(err)
            return
        self.collect(items, target.parent)

    def instantiate(self, inst: Instance) -> None:
        model = self.models.get(inst.model)
        if model is None:
            self.fail(
                f"unknown model '{inst.model}' for element {inst.name}",
                inst.model_loc,
                suggestions=close_names(inst.model, self.models),
                notes=("models are defined with `model NAME { ... }`, here or in a file named by `use`",),
            )
            return
        declared = {d.name for d in model.body.decls} | {r.name for r in model.body.reads}
        mapping: dict[str, str] = {}
        for old, new, old_loc, new_loc in inst.renaming:
            self.renamed.setdefault(new, (inst.name, old, new_loc))
            if old not in declared:
                self.fail(
                    f"model '{model.name}' has no variable '{old}'",
                    old_loc,
                    suggestions=close_names(old, declared),
                    expected=(", ".join(sorted(declared)),),
                )
                continue
            if old in mapping:
                self.fail(f"'{old}' is renamed twice in element {inst.name}", old_loc)
                continue
            mapping[old] = new
        self.add_element(_rename(inst.name, model, mapping, inst.loc))

    def add_element(self, e: ElementSpec) -> None:
        for other in self.elements:
            if other.name == e.name:
                self.fail(f"element '{e.name}' is declared twice", e.loc, notes=(f"first declared at {other.loc}",))
                return
        self.elements.append(e)

    # ---- checks
    def check(self) -> None:
        owner: dict[str, tuple[ElementSpec, VarDecl]] = {}
        elements: list[ElementSpec] = []
        for v in self.top_free:
            elements.append(ElementSpec(v.name, (v,), loc=v.loc))
        elements.extend(self.elements)
        named: dict[str, ElementSpec] = {}
        for e in elements:
            if e.name in named and e.loc is not None:
                self.fail(
                    f"element '{e.name}' is declared twice",
                    e.loc,
                    notes=(f"first declared at {named[e.name].loc} (a top-level free input is an element of its own)",),
                )
            named.setdefault(e.name, e)
        for e in elements:
            for v in e.variables:
                if v.name in owner:
                    first_el, first = owner[v.name]
                    where = "again" if first_el.name == e.name else f"by element {e.name}"
                    self.fail(
                        f"variable '{v.name}' is declared {where} but already belongs to element {first_el.name}",
                        v.loc,
                        notes=(f"{first_el.name} declares it at {first.loc}", "each variable belongs to exactly one element"),
                    )
                else:
                    owner[v.name] = (e, v)
        # outputs held constant
        held: dict[str, VarDecl] = {}
        for h in self.holds:
            if h.name not in owner:
                self.fail(f"hold: unknown order '{h.name}'", h.loc, suggestions=close_names(h.name, [n for n, (_, d) in owner.items() if d.kind == VarKind.ORDER]))
            elif owner[h.name][1].kind != VarKind.ORDER:
                self.fail(f"hold: '{h.name}' is an input of element {owner[h.name][0].name}; only orders can be held", h.loc)
            else:
                held[h.name] = h
        final: list[ElementSpec] = []
        for e in elements:
            if any(v.name in held for v in e.variables):
                e = replace(
                    e,
                    variables=tuple(
                        replace(v, initial=held[v.name].initial, held=True) if v.name in held else v for v in e.variables
                    ),
                )
            self.check_element(e, owner)
            final.append(e)
        self.elements = final
        listed: dict[str, Location] = {}
        for vec in self.vectors:
            want_input = vec.kind is VectorKind.INPUTS
            pool = [n for n, (_, d) in owner.items() if d.is_input == want_input]
            for n, loc in vec.names:
                if n in listed:
                    self.fail(f"'{n}' is listed twice in the vectors", loc, notes=(f"first listed at {listed[n]}",))
                elif n not in owner:
                    self.unknown_use(n, f"{vec.kind}: unknown variable '{n}'", loc, close_names(n, pool))
                elif owner[n][1].is_input != want_input:
                    what = "an input" if owner[n][1].is_input else "an order"
                    self.fail(f"{vec.kind}: '{n}' is {what} of element {owner[n][0].name}", loc)
                else:
                    listed[n] = loc
        self.order = tuple(listed)
        all_names = set(owner)
        ids: dict[str, Constraint] = {}
        for c in self.constraints:
            if c.id in ids:
                self.fail(f"constraint id '{c.id}' is used twice", c.loc, notes=(f"first used at {ids[c.id].loc}",))
            ids[c.id] = c
            try:
                disjunctive_normal_form(c.forbidden)
            except NegatedEdge:
                self.fail(
                    f"constraint {c.id}: an edge cannot be negated (or the constraint written = 1 around an edge)",
                    c.loc,
                    notes=("write the forbidden case as a conjunction, e.g. `↓AVANCER1 & !v11 = 0`",),
                )
            except NormalFormTooLarge:
                self.fail(
                    f"constraint {c.id} is too large once expanded into monomials (more than 4096)",
                    c.loc,
                    notes=("split it into several constraints",),
                )
            for x in names(c.expr):
                if x.name not in all_names:
                    what = "edge of an undeclared variable" if isinstance(x, Edge) else "undeclared variable"
                    self.unknown_use(x.name, f"constraint {c.id} uses {what} '{x.name}'", x.loc, close_names(x.name, all_names))
                elif isinstance(x, Edge) and owner[x.name][1].kind != VarKind.ORDER:
                    self.fail(
                        f"constraint {c.id}: edges in constraints must be edges of orders; '{x.name}' is an input of element {owner[x.name][0].name}",
                        x.loc,
                        notes=("an edge restricts the matching controllable event; inputs are written as levels",),
                    )

        self.blame_renamings()

    def unknown_use(self, name: str, message: str, loc: Location | None, suggestions: tuple[str, ...]) -> None:
        self.unknown_uses.append((name, InputError(message, loc, suggestions=suggestions)))

    def blame_renamings(self) -> None:
        """Unknown names reported at their cause: when an instance renames a variable to a
        name the file never uses and the unknown name is close to it (``AVANCER=AVANCR2``
        while the vectors and constraints say ``AVANCER2``), one error at the renaming
        replaces the errors at every use."""
        used = {n for n, _ in self.unknown_uses}
        referenced = {n for vec in self.vectors for n, _ in vec.names}
        referenced |= {n.name for c in self.constraints for n in names(c.expr)}
        blamed: dict[str, str] = {}
        for new, (element, old, loc) in sorted(self.renamed.items(), key=lambda kv: str(kv[1][2])):
            if new in referenced:
                continue
            typo_of = [u for u in sorted(used) if u not in blamed and close_names(u, [new])]
            if not typo_of:
                continue
            u = typo_of[0]
            uses = [e for n, e in self.unknown_uses if n == u]
            lines = [str(e.location.line) for e in uses if e.location is not None]
            self.fail(
                f"element {element} renames {old} to '{new}', which the file never uses; "
                f"the vectors and constraints use '{u}' (line{'s' if len(lines) > 1 else ''} {', '.join(lines)})",
                loc,
                suggestions=(u,),
            )
            blamed[u] = new
        self.errors.extend(e for n, e in self.unknown_uses if n not in blamed)

    def check_reads(self, e: ElementSpec, owner: Mapping[str, tuple[ElementSpec, VarDecl]]) -> set[str]:
        """The valid ``reads`` of ``e``: each a variable of another element, declared once."""
        valid: set[str] = set()
        for r in e.reads:
            if r.name in valid:
                self.fail(f"element {e.name} reads '{r.name}' twice", r.loc)
            elif r.name not in owner:
                self.fail(
                    f"element {e.name} reads unknown variable '{r.name}'",
                    r.loc,
                    suggestions=close_names(r.name, [n for n, (el, _) in owner.items() if el.name != e.name]),
                    notes=("`reads` names variables of other elements",),
                )
            elif owner[r.name][0].name == e.name:
                self.fail(f"element {e.name} reads '{r.name}', but it is its own variable: no `reads` needed", r.loc)
            else:
                valid.add(r.name)
        return valid

    def check_element(self, e: ElementSpec, owner: Mapping[str, tuple[ElementSpec, VarDecl]]) -> None:
        own = {v.name: v for v in e.variables}
        reads = self.check_reads(e, owner)
        readable = set(own) | reads

        def unknown(n: Var | Edge, role: str) -> None:
            if n.name in owner and owner[n.name][0].name != e.name:
                other = owner[n.name][0].name
                where = "its own variables" if role == "incoherence" else "its own variables and those it `reads`"
                pool = own if role == "incoherence" else readable
                notes = [f"an element's {role}s may only use {where}: {', '.join(sorted(pool))}"]
                if role != "incoherence":
                    notes.append(f"to read {other}'s variable, declare `reads {n.name}` in element {e.name}")
                self.fail(
                    f"{role} of element {e.name} uses '{n.name}', which belongs to element {other}",
                    n.loc,
                    suggestions=close_names(n.name, pool),
                    notes=tuple(notes),
                )
            else:
                self.fail(f"unknown variable '{n.name}' in element {e.name}", n.loc, suggestions=close_names(n.name, readable))

        def levels_only(x: Expr, role: str, allowed: set[str] | dict[str, VarDecl]) -> None:
            for n in names(x):
                if isinstance(n, Edge):
                    self.fail(f"an edge is not allowed in a {role}; write a level", n.loc)
                elif n.name not in allowed:
                    unknown(n, role)

        for inc in e.incoherences:
            levels_only(inc, "incoherence", own)
        for r in e.rules:
            c, q = r.cause, r.consequence
            if c.name in reads:
                pass  # the edge of a variable it reads: the rule applies while that variable has its post-edge value
            elif c.name not in own:
                unknown(c, "rule")
            elif own[c.name].kind != VarKind.ORDER:
                self.fail(
                    f"the cause of a rule must be an edge of one of {e.name}'s orders (or of a variable it reads); "
                    f"'{c.name}' is an input",
                    c.loc,
                    suggestions=close_names(c.name, [v.name for v in e.orders]),
                )
            decl = own[q.name] if q.name in own else owner[q.name][1] if q.name in owner else None
            if decl is not None and decl.kind == VarKind.FREE:
                self.fail(
                    f"rule of element {e.name} produces {q.text()}, but {q.name} is a free input: "
                    "an operator changes it at any time, no rule produces it",
                    q.loc,
                    notes=(f"declare {q.name} as a sensor of {e.name} if the element drives it",),
                )
            elif q.name not in own:
                if q.name in owner:
                    other = owner[q.name][0].name
                    self.fail(
                        f"rule of element {e.name} produces {q.text()}, but {q.name} is a sensor of element {other}",
                        q.loc,
                        suggestions=close_names(q.name, [v.name for v in e.inputs]),
                        notes=(f"a rule may only produce edges of its own element's sensors: {', '.join(v.name for v in e.inputs)}",),
                    )
                else:
                    unknown(q, "rule")
            elif own[q.name].kind == VarKind.ORDER:
                self.fail(
                    f"the consequence of a rule must be an edge of a sensor of {e.name}; '{q.name}' is an order",
                    q.loc,
                    suggestions=close_names(q.name, [v.name for v in e.inputs]),
                )
            if r.guard is not None:
                levels_only(r.guard, "guard", readable)
        for p in e.precedences:
            for role, x in (("cause", p.cause), ("first", p.first), ("then", p.then)):
                if role == "cause" and x.name in reads:
                    continue
                if x.name not in own:
                    unknown(x, "precedence")
                elif (own[x.name].kind == VarKind.ORDER) != (role == "cause"):
                    want = "an edge of one of its orders" if role == "cause" else "an edge of one of its sensors"
                    self.fail(f"in a precedence of {e.name}, the {role} must be {want}; '{x.name}' is not", x.loc)
        # the initial state must be coherent
        init = {v.name: v.initial for v in e.variables}
        for inc in e.incoherences:
            if all(n.name in init for n in names(inc)) and evaluate(inc, init.__getitem__):
                where = inc.loc or next((n.loc for n in names(inc)), e.loc)
                self.fail(
                    f"the initial state of element {e.name} is incoherent: {inc.text()} holds initially",
                    where,
                    notes=("initial values: " + ", ".join(f"{k}={int(v)}" for k, v in init.items()),),
                )
        if not e.variables:
            self.fail(f"element {e.name} declares no variable", e.loc)


def _rename(name: str, model: Model, mapping: Mapping[str, str], loc: Location) -> ElementSpec:
    def r(n: str) -> str:
        return mapping.get(n, n)

    def rx(x: Expr) -> Expr:
        return renamed(x, r)

    def re_(x: Edge) -> Edge:
        return Edge(x.rising, r(x.name), x.loc)

    b = model.body
    return ElementSpec(
        name,
        tuple(replace(d, name=r(d.name)) for d in b.decls),
        tuple(rx(i) for i in b.incoherences),
        tuple(Rule(re_(x.cause), rx(x.guard) if x.guard is not None else None, re_(x.consequence), x.loc) for x in b.rules),
        tuple(Precedence(re_(p.cause), re_(p.first), re_(p.then), p.loc) for p in b.precedences),
        loc,
        model.name,
        tuple(Read(r(x.name), x.loc) for x in b.reads),
    )


def parse_rules(source: str, file: str = "<rules>", base: Path | None = None) -> RuleSet:
    """Parse and check rules text; ``base`` is the folder ``use`` paths are relative to."""
    items = rules_items(source, file)
    checker = RulesChecker()
    if base is not None:
        checker.loaded.add((base / Path(file).name).resolve())  # a file that uses itself back
    checker.collect(items, base)
    if not checker.errors:
        checker.check()
    if not checker.elements and not checker.top_free and not checker.errors:
        checker.fail(
            "the plant is empty: no element is declared",
            location_in(file, source, 1, 1),
            notes=("declare elements with `element NAME { ... }` or `element NAME = MODEL(...)`",),
        )
    checker.raise_errors()
    return RuleSet(tuple(checker.elements), tuple(checker.constraints), file, checker.order)


def load_rules(path: str | Path) -> RuleSet:
    """Read, parse and check a ``.rules`` file."""
    return parse_rules(read_source(path), str(path), Path(path).parent)
