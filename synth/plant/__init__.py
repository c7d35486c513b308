"""The plant: the rules language, element automata, and their asynchronous composition.

The names below are re-exported lazily (on first use), so importing the package costs nothing.
"""

from synth._lazy import lazy_exports

__getattr__, __all__ = lazy_exports(
    __name__,
    {
        "RuleSet": "rules",
        "Constraint": "rules",
        "ElementSpec": "rules",
        "load_rules": "rules_check",
        "parse_rules": "rules_check",
        "ElementAutomaton": "element",
        "element_automaton": "element",
        "Plant": "composition",
        "LocalTransition": "composition",
        "plant": "composition",
    },
)
