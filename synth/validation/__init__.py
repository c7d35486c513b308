"""Validation: SUP × ASS (SYNC), its analysis (blocking, traps, traces), diagnosis and the validation result.

The names below are re-exported lazily (on first use), so importing the package costs nothing.
"""

from synth._lazy import lazy_exports

__getattr__, __all__ = lazy_exports(
    __name__,
    {
        "Validation": "result",
        "validate": "validate",
        "reduced_controller": "result",
    },
)
