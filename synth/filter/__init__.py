"""The safety logic filter (the lab's second method): the ``.filter`` language, coherence checks P1–P4, algebraic synthesis, Structured Text, closed-loop verification.

The names below are re-exported lazily (on first use), so importing the package costs nothing.
"""

from synth._lazy import lazy_exports

__getattr__, __all__ = lazy_exports(
    __name__,
    {
        "Filter": "language",
        "Safety": "language",
        "load_filter": "language_check",
        "parse_filter": "language_check",
        "FilterFunctions": "model",
        "functions": "model",
        "Coherence": "coherence",
        "coherence": "coherence",
        "Synthesis": "solve",
        "synthesis": "solve",
    },
)
