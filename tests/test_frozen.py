"""``synth.frozen.frozen`` against ``dataclasses.dataclass(frozen=True)``: each class body
below is made both ways and the two must behave alike (docs/performance.md, "Session 28")."""

from __future__ import annotations

import copy
import dataclasses
import inspect
import pickle
from dataclasses import field
from typing import Any, Callable

import pytest

from synth.frozen import frozen


def both(body: Callable[[], type], **options: Any) -> tuple[type, type]:
    """The class ``body()`` returns, made by ``frozen`` and by ``dataclasses``."""
    return frozen(**options)(body()), dataclasses.dataclass(frozen=True, **options)(body())


def point() -> type:
    class Point:
        """A point."""

        x: int
        y: int = 0
        tags: tuple[str, ...] = field(default=(), compare=False)
        seen: list[int] = field(default_factory=list, repr=False, hash=False)

        def norm(self) -> int:
            return abs(self.x) + abs(self.y)

    return Point


def test_init_repr_eq_hash_as_dataclasses() -> None:
    mine, theirs = both(point)
    for args, kwargs in [((1,), {}), ((1, 2), {"tags": ("a",)}), ((), {"x": 3, "seen": [1]})]:
        a, b = mine(*args, **kwargs), theirs(*args, **kwargs)
        assert repr(a) == repr(b).replace(theirs.__qualname__, mine.__qualname__)
        assert hash(a) == hash(b)
        assert dataclasses.astuple(a) == dataclasses.astuple(b)
        assert dataclasses.asdict(a) == dataclasses.asdict(b)
    assert repr(mine(1, 2, ("t",))) == "point.<locals>.Point(x=1, y=2, tags=('t',))"
    assert mine(1, 2, ("a",)) == mine(1, 2, ("b",))  # tags are not compared
    assert mine(1, 2) != mine(2, 1) and mine(1) != (1, 0) and mine(1).__eq__(theirs(1)) is NotImplemented
    assert hash(mine(1, 2)) == hash((1, 2))  # the tuple of the compared fields
    assert mine(1).seen == [] and mine(1).seen is not mine(1).seen  # a new list each time
    assert mine(1).norm() == 1


def test_signature_params_and_fields_as_dataclasses() -> None:
    mine, theirs = both(point)
    mine(1)  # the real __init__ is compiled on first use
    assert str(inspect.signature(mine)) == str(inspect.signature(theirs))
    assert [(f.name, f.default, f.compare, f.repr) for f in dataclasses.fields(mine)] == \
        [(f.name, f.default, f.compare, f.repr) for f in dataclasses.fields(theirs)]
    assert repr(mine.__dataclass_params__) == repr(theirs.__dataclass_params__)
    assert mine.__match_args__ == theirs.__match_args__ == ("x", "y", "tags", "seen")
    assert dataclasses.is_dataclass(mine) and mine.__doc__ == "A point."
    assert mine.__init__.__qualname__ == "point.<locals>.Point.__init__"


def test_the_first_instantiation_compiles_init_once() -> None:
    mine, _ = both(point)
    lazy = mine.__dict__["__init__"]
    assert mine(1, 2).y == 2
    real = mine.__dict__["__init__"]
    assert real is not lazy and mine(3).x == 3 and mine.__dict__["__init__"] is real
    with pytest.raises(TypeError, match="missing 1 required positional argument: 'x'"):
        mine()


def test_frozen_errors_as_dataclasses() -> None:
    mine, theirs = both(point)
    for cls in (mine, theirs):
        p = cls(1)
        with pytest.raises(dataclasses.FrozenInstanceError, match="cannot assign to field 'x'"):
            p.x = 2
        with pytest.raises(dataclasses.FrozenInstanceError, match="cannot assign to field 'other'"):
            p.other = 2
        with pytest.raises(dataclasses.FrozenInstanceError, match="cannot delete field 'y'"):
            del p.y


def test_replace_copy_pickle() -> None:
    mine = frozen(point())
    globals()["PicklePoint"] = mine  # pickle finds the class by its module and qualified name
    mine.__qualname__ = "PicklePoint"
    p = mine(1, 2, ("a",))
    q = dataclasses.replace(p, y=5)
    assert (q.x, q.y, q.tags) == (1, 5, ("a",)) and type(q) is mine
    assert copy.deepcopy(p) == p and copy.copy(p) == p
    assert pickle.loads(pickle.dumps(p)) == p


def test_order() -> None:
    def pair() -> type:
        class Pair:
            """Ordered."""

            a: int
            b: str = ""
            note: str = field(default="", compare=False)

        return Pair

    mine, theirs = both(pair, order=True)
    values = [(2, "a", "z"), (1, "b", "y"), (1, "a", "x"), (2, "", "w")]
    assert [(p.a, p.b) for p in sorted(mine(*v) for v in values)] == [(p.a, p.b) for p in sorted(theirs(*v) for v in values)]
    assert mine(1) <= mine(1, "", "other") and mine(2) > mine(1, "z") and mine(1) >= mine(1)
    with pytest.raises(TypeError):
        assert mine(1) < theirs(2)
    with pytest.raises(ValueError, match="eq must be true if order is true"):
        frozen(eq=False, order=True)(pair())


def test_eq_false_keeps_identity() -> None:
    def box() -> type:
        class Box:
            """Compared by identity."""

            items: list[int]

        return Box

    mine, theirs = both(box, eq=False)
    a = mine([1])
    assert a != mine([1]) and a == a and hash(a) == object.__hash__(a)
    assert (mine.__eq__, mine.__hash__) == (object.__eq__, object.__hash__) == (theirs.__eq__, theirs.__hash__)


def test_a_body_hash_or_eq_or_post_init_is_kept() -> None:
    def custom() -> type:
        class Custom:
            """Hash and repr of its own, checked after init."""

            name: str
            count: int = 1

            def __hash__(self) -> int:
                return 7

            def __repr__(self) -> str:
                return f"<{self.name}>"

            def __post_init__(self) -> None:
                if self.count < 0:
                    raise ValueError("negative")

        return Custom

    mine, theirs = both(custom)
    assert hash(mine("a")) == hash(theirs("a")) == 7 and repr(mine("a")) == "<a>"
    with pytest.raises(ValueError, match="negative"):
        mine("a", -1)

    def equal() -> type:
        class Equal:
            """An __eq__ of its own: Python sets __hash__ to None, dataclasses adds one."""

            name: str

            def __eq__(self, other: object) -> bool:
                return True

        return Equal

    mine, theirs = both(equal)
    assert mine("a") == mine("b") and hash(mine("a")) == hash(theirs("a")) == hash(("a",))
    with pytest.raises(TypeError, match="Cannot overwrite attribute __setattr__"):
        frozen(type("Bad", (), {"__doc__": "x", "__annotations__": {"a": "int"}, "__setattr__": lambda s, n, v: None}))


def test_what_frozen_leaves_to_dataclasses() -> None:
    """A subclass of a dataclass, pseudo-fields, and a class with no docstring (whose
    docstring ``dataclasses`` writes from the signature) are ``dataclasses``' own classes."""

    @frozen
    class Base:
        """Base."""

        a: int

    @frozen
    class Sub(Base):
        """Sub."""

        b: int = 0

    assert Sub(1, 2) == Sub(1, 2) and repr(Sub(1)) == \
        "test_what_frozen_leaves_to_dataclasses.<locals>.Sub(a=1, b=0)"
    with pytest.raises(dataclasses.FrozenInstanceError):
        Sub(1).b = 3

    @frozen
    class Undocumented:
        a: int

    assert Undocumented.__doc__ == "Undocumented(a: 'int')"
    # as in dataclasses, when the class is made, not when it is first instantiated
    with pytest.raises(TypeError, match="non-default argument 'b' follows default argument"):
        frozen(type("Bad", (), {"__doc__": "x", "__annotations__": {"a": "int", "b": "int"}, "a": 0}))


def test_init_made_from_the_template_of_its_field_count() -> None:
    """Classes without factories share one compiled ``__init__`` per number of fields, each
    copy with its own names: the same signature, defaults and errors as dataclasses'."""

    def pair() -> type:
        class Pair:
            """Two fields."""

            left: str
            right: tuple[int, ...] = (1,)

        return Pair

    def other() -> type:
        class Other:
            """Two other fields."""

            name: int
            size: float = 0.5

        return Other

    (mine, theirs), (other_mine, _) = both(pair), both(other)
    assert (mine("a").left, mine("a").right, mine(right=(), left="b").right) == ("a", (1,), ())
    assert other_mine(3).size == 0.5 and other_mine(size=2, name=1).name == 1
    assert str(inspect.signature(mine)) == str(inspect.signature(theirs))
    assert mine.__init__.__code__.co_code == other_mine.__init__.__code__.co_code  # the same template
    assert mine.__init__.__code__.co_varnames == ("self", "left", "right")
    assert mine.__init__.__qualname__ == "test_init_made_from_the_template_of_its_field_count.<locals>.pair.<locals>.Pair.__init__"
    with pytest.raises(TypeError, match="got an unexpected keyword argument 'name'"):
        mine(name=1)
    with pytest.raises(TypeError, match="missing 1 required positional argument: 'left'"):
        mine()
