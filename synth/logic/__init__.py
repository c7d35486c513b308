"""Boolean expressions, events and cubes: the vocabulary every language of synth shares.

The names below are re-exported lazily (on first use), so importing the package costs nothing.
"""

from synth._lazy import lazy_exports

__getattr__, __all__ = lazy_exports(
    __name__,
    {
        "Expr": "expr",
        "Var": "expr",
        "Const": "expr",
        "Not": "expr",
        "And": "expr",
        "Or": "expr",
        "Edge": "expr",
        "Literal": "expr",
        "Monomial": "expr",
        "evaluate": "expr",
        "names": "expr",
        "disjunctive_normal_form": "expr",
    },
)
