"""The words a validation's state is written in (Sit, E, Z, ORD, PROH), once for the HTML
report's legend and for a command's ``--help`` (text only, no imports).

Example
-------
>>> [term for term, _ in GLOSSARY_TERMS]
['Sit', 'E', 'Z', 'ORD', 'PROH']
>>> print(GLOSSARY.splitlines()[3])
  ORD   the orders the Grafcet emits in that state and SUP authorises (so they are set in Z)
"""

__all__ = ["GLOSSARY_TERMS", "GLOSSARY"]

GLOSSARY_TERMS: tuple[tuple[str, str], ...] = (
    ("Sit", "the situation: the Grafcet's active steps (X1 is step 1 active)"),
    ("E", "the plant's inputs that are true: sensors, operator inputs (the Grafcet reads them)"),
    ("Z", "the plant's outputs that are true: the orders as the plant holds them (actuators on)"),
    ("ORD", "the orders the Grafcet emits in that state and SUP authorises (so they are set in Z)"),
    ("PROH", "the order changes (↑ or ↓ of an order) the Grafcet asks for in that state and SUP forbids, "
             "with the ids of the constraints that forbid them"),
)

GLOSSARY: str = "\n".join(f"  {term:<5} {text}" for term, text in GLOSSARY_TERMS)
