"""SUP: the supremal controllable sub-plant that respects the safety constraints (the maximal admissible behaviour).

The names below are re-exported lazily (on first use), so importing the package costs nothing.
"""

from synth._lazy import lazy_exports

__getattr__, __all__ = lazy_exports(
    __name__,
    {
        "Supervisor": "supervisor",
        "supremal_controllable": "supervisor",
        "Explanation": "explain",
        "CompiledConstraints": "constraints",
    },
)
