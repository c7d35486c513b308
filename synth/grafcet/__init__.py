"""The Grafcet (IEC 60848): the ``.g7`` language, its evolution machine, and the automaton of its stable situations (ASS).

The names below are re-exported lazily (on first use), so importing the package costs nothing.
"""

from synth._lazy import lazy_exports

__getattr__, __all__ = lazy_exports(
    __name__,
    {
        "Grafcet": "language",
        "PartialGrafcet": "language",
        "Step": "language",
        "Transition": "language",
        "Action": "language",
        "Timer": "language",
        "load_grafcet": "language_check",
        "parse_grafcet": "language_check",
        "GrafcetMachine": "machine",
        "Situation": "machine",
    },
)
