"""``@frozen``: ``@dataclass(frozen=True)`` made cheaper to create.

``dataclasses`` compiles each method it writes (``__init__``, ``__repr__``, ``__eq__``,
``__hash__``, ``__setattr__``, ``__delattr__``, the orderings) from source text, one
``exec`` each: about 0.6 ms per class on Python 3.11, a third of what synth's own modules
cost a short command (docs/performance.md, "Session 28"). ``frozen`` lets ``dataclasses``
collect the fields (so ``dataclasses.fields``, ``replace``, ``asdict``, ``is_dataclass``
and ``__match_args__`` work as ever), then gives the class the same methods, made of
closures instead of compiled text, and an ``__init__`` made on the class's first
instantiation (a class a run never instantiates never pays for it): a renamed copy of
one compiled template per number of fields (the bytecode ``dataclasses``' text gives),
or for fields with factories or a ``__post_init__``, ``dataclasses``' text compiled. What the code relies
on stays: equality and hash over the compared fields as tuples (the same hash values),
the same ``repr``, ordering with ``order=True``, ``FrozenInstanceError`` on assignment,
``__post_init__``, defaults and default factories, and ``__dataclass_params__`` saying
``frozen=True``. A class the decorator cannot serve that way (one with ``ClassVar``,
``InitVar`` or keyword-only fields, a base that is a dataclass, or no docstring, which
``dataclasses`` writes from the signature) is handed to ``dataclasses.dataclass`` itself.

>>> @frozen(order=True)
... class P:
...     '''A point.'''
...     x: int
...     y: int = 0
>>> P(1), P(1) == P(1, 0), hash(P(1)) == hash((1, 0)), P(1) < P(1, 1)
(P(x=1, y=0), True, True, True)
"""

from __future__ import annotations

import dataclasses
import operator
from operator import attrgetter
from reprlib import recursive_repr
from types import FunctionType
from typing import TYPE_CHECKING, Any, Callable, TypeVar

__all__ = ["frozen"]

T = TypeVar("T")

# the cases ``frozen`` leaves to ``dataclasses.dataclass`` itself: pseudo-fields and
# keyword-only fields change ``__init__``'s signature in ways it does not write
_SPECIAL = ("ClassVar", "InitVar", "KW_ONLY")

_ORDERS = (("__lt__", "<"), ("__le__", "<="), ("__gt__", ">"), ("__ge__", ">="))


def _getter(names: tuple[str, ...]) -> Callable[[Any], tuple[Any, ...]]:
    """The tuple of an object's ``names`` attributes (``dataclasses`` compares and hashes
    these tuples, even of one field or none)."""
    if not names:
        return lambda obj: ()
    if len(names) == 1:
        one = attrgetter(names[0])
        return lambda obj: (one(obj),)
    return attrgetter(*names)


def _init_source(cls: type, fields: tuple[dataclasses.Field[Any], ...]) -> tuple[str, dict[str, Any]]:
    """The text of ``dataclasses``' ``__init__`` for a frozen class of these fields (the
    same parameters, defaults and annotations), and the names it reads."""
    self_name = "__dataclass_self__" if any(f.name == "self" for f in fields) else "self"
    names: dict[str, Any] = {"__dataclass_builtins_object__": object, "_HAS_DEFAULT_FACTORY": _HAS_DEFAULT_FACTORY,
                             "_return_type": None}
    params, body = [self_name], []
    for f in fields:
        names[f"_type_{f.name}"] = f.type
        factory = f.default_factory is not dataclasses.MISSING
        if f.init:
            if factory:
                names[f"_dflt_{f.name}"] = f.default_factory
                params.append(f"{f.name}:_type_{f.name}=_HAS_DEFAULT_FACTORY")
                value = f"_dflt_{f.name}() if {f.name} is _HAS_DEFAULT_FACTORY else {f.name}"
            elif f.default is not dataclasses.MISSING:
                names[f"_dflt_{f.name}"] = f.default
                params.append(f"{f.name}:_type_{f.name}=_dflt_{f.name}")
                value = f.name
            else:
                params.append(f"{f.name}:_type_{f.name}")
                value = f.name
        elif factory:
            names[f"_dflt_{f.name}"] = f.default_factory
            value = f"_dflt_{f.name}()"
        else:
            continue  # the class attribute holds the default
        body.append(f"  __dataclass_builtins_object__.__setattr__({self_name},{f.name!r},{value})")
    if hasattr(cls, "__post_init__"):
        body.append(f"  {self_name}.__post_init__()")
    text = (f"def __create_fn__({', '.join(names)}):\n def __init__({','.join(params)})->_return_type:\n"
            + "\n".join(f" {line}" for line in body or ["  pass"]) + "\n return __init__")
    return text, names


class _HasDefaultFactory:
    """The sentinel default of a parameter whose field has a default factory."""

    def __repr__(self) -> str:
        return "<factory>"


_HAS_DEFAULT_FACTORY = _HasDefaultFactory()


# the ``__init__`` of a class of N fields without factories, compiled once per N; each class
# gets a copy of its code with its own names (the same bytecode as its own text would give)
_TEMPLATES: dict[int, Callable[..., None]] = {}


def _template_init(cls: type, fields: tuple[dataclasses.Field[Any], ...]) -> Callable[..., None] | None:
    """``cls``'s ``__init__`` made from the template of its number of fields, or ``None``
    when its fields need more (a factory, a field left out of ``__init__``, a field named
    ``self``, a ``__post_init__``)."""
    if hasattr(cls, "__post_init__") or any(not f.init or f.default_factory is not dataclasses.MISSING
                                            or f.name == "self" for f in fields):
        return None
    n = len(fields)
    if (template := _TEMPLATES.get(n)) is None:
        text = (f"def __init__(self{''.join(f', _f{i}_' for i in range(n))}):\n"
                + "".join(f"  __dataclass_builtins_object__.__setattr__(self,'_f{i}_',_f{i}_)\n" for i in range(n))
                + "  pass\n")
        space: dict[str, Any] = {"__dataclass_builtins_object__": object}
        exec(compile(text, "<string>", "exec", dont_inherit=True), space)  # noqa: S102 - made above
        template = _TEMPLATES[n] = space["__init__"]
    names = {f"_f{i}_": f.name for i, f in enumerate(fields)}
    code = template.__code__
    code = code.replace(co_varnames=tuple(names.get(v, v) for v in code.co_varnames),
                        co_consts=tuple(names.get(c, c) if isinstance(c, str) else c for c in code.co_consts),
                        co_qualname=f"{cls.__qualname__}.__init__")
    defaults = tuple(f.default for f in fields if f.default is not dataclasses.MISSING)
    init: Callable[..., None] = FunctionType(code, template.__globals__, "__init__", defaults or None)
    init.__annotations__ = {**{f.name: f.type for f in fields}, "return": None}
    init.__qualname__ = f"{cls.__qualname__}.__init__"
    return init


def _compiled_init(cls: type, fields: tuple[dataclasses.Field[Any], ...]) -> Callable[..., None]:
    if (init := _template_init(cls, fields)) is not None:
        return init
    text, names = _init_source(cls, fields)
    space: dict[str, Any] = {}
    # compiled without this module's ``from __future__ import annotations``, as dataclasses' text is
    exec(compile(text, "<string>", "exec", dont_inherit=True), {}, space)  # noqa: S102 - made above
    made: Callable[..., None] = space["__create_fn__"](**names)
    made.__qualname__ = f"{cls.__qualname__}.__init__"
    return made


def _lazy_init(cls: type, fields: tuple[dataclasses.Field[Any], ...]) -> Callable[..., None]:
    """An ``__init__`` that compiles the real one on the first instantiation, puts it on
    the class, and calls it."""

    def __init__(self: Any, *args: Any, **kwargs: Any) -> None:
        init = _compiled_init(cls, fields)
        setattr(cls, "__init__", init)
        init(self, *args, **kwargs)

    __init__.__qualname__ = f"{cls.__qualname__}.__init__"
    return __init__


def _check_defaults(fields: tuple[dataclasses.Field[Any], ...]) -> None:
    """``dataclasses``' error, raised when the class is made, for a parameter without a
    default after one with a default."""
    seen_default = False
    for f in fields:
        if f.init:
            if f.default is not dataclasses.MISSING or f.default_factory is not dataclasses.MISSING:
                seen_default = True
            elif seen_default:
                raise TypeError(f"non-default argument {f.name!r} follows default argument")


def _method(cls: type, name: str, fn: Callable[..., Any]) -> None:
    """Put ``fn`` on ``cls`` as ``name`` unless the class body defines it (as ``dataclasses`` does)."""
    if name not in cls.__dict__:
        fn.__qualname__ = f"{cls.__qualname__}.{name}"
        setattr(cls, name, fn)


def _frozen_attributes(cls: type[Any], names: tuple[str, ...]) -> None:
    """``__setattr__`` and ``__delattr__`` raising ``FrozenInstanceError`` on the fields
    (and on every attribute of an instance of ``cls`` itself), as ``dataclasses`` writes them."""

    def __setattr__(self: Any, name: str, value: Any) -> None:
        if type(self) is cls or name in names:
            raise dataclasses.FrozenInstanceError(f"cannot assign to field {name!r}")
        super(cls, self).__setattr__(name, value)

    def __delattr__(self: Any, name: str) -> None:
        if type(self) is cls or name in names:
            raise dataclasses.FrozenInstanceError(f"cannot delete field {name!r}")
        super(cls, self).__delattr__(name)

    _method(cls, "__setattr__", __setattr__)
    _method(cls, "__delattr__", __delattr__)


def _comparisons(cls: type, names: tuple[str, ...], order: bool) -> None:
    get = _getter(names)

    def __eq__(self: Any, other: Any) -> Any:
        if other.__class__ is self.__class__:
            return get(self) == get(other)
        return NotImplemented

    _method(cls, "__eq__", __eq__)
    if not order:
        return
    for name, op in _ORDERS:
        if name in cls.__dict__:
            raise TypeError(f"Cannot overwrite attribute {name} in class {cls.__name__}. "
                            "Consider using functools.total_ordering")
        _method(cls, name, _order(get, op))


def _order(get: Callable[[Any], tuple[Any, ...]], op: str) -> Callable[[Any, Any], Any]:
    compare: Callable[[Any, Any], Any] = {"<": operator.lt, "<=": operator.le, ">": operator.gt, ">=": operator.ge}[op]

    def method(self: Any, other: Any) -> Any:
        if other.__class__ is self.__class__:
            return compare(get(self), get(other))
        return NotImplemented

    return method


def _hash(cls: type, names: tuple[str, ...]) -> None:
    get = _getter(names)

    def __hash__(self: Any) -> int:
        return hash(get(self))

    __hash__.__qualname__ = f"{cls.__qualname__}.__hash__"
    setattr(cls, "__hash__", __hash__)


def _repr(cls: type, names: tuple[str, ...]) -> None:
    def __repr__(self: Any) -> str:
        return self.__class__.__qualname__ + "(" + ", ".join([f"{n}={getattr(self, n)!r}" for n in names]) + ")"

    if "__repr__" not in cls.__dict__:
        __repr__.__qualname__ = f"{cls.__qualname__}.__repr__"
        setattr(cls, "__repr__", recursive_repr()(__repr__))


def _process(cls: type, eq: bool, order: bool) -> type:
    if order and not eq:
        raise ValueError("eq must be true if order is true")
    annotations = cls.__dict__.get("__annotations__", {})
    special = any(not isinstance(a, str) or any(s in a for s in _SPECIAL) for a in annotations.values())
    if special or not cls.__dict__.get("__doc__") or any(dataclasses.is_dataclass(b) for b in cls.__mro__[1:]):
        return dataclasses.dataclass(cls, frozen=True, eq=eq, order=order)
    for name in ("__setattr__", "__delattr__"):
        if name in cls.__dict__:
            raise TypeError(f"Cannot overwrite attribute {name} in class {cls.__name__}")
    # ``dataclasses`` adds a hash to a frozen class with ``eq`` unless its body defines
    # one (a body that defines ``__eq__`` alone gets ``__hash__ = None`` from Python)
    body_hash = cls.__dict__.get("__hash__", dataclasses.MISSING)
    explicit_hash = not (body_hash is dataclasses.MISSING or (body_hash is None and "__eq__" in cls.__dict__))
    done: type[Any] = dataclasses.dataclass(cls, init=False, repr=False, eq=False, frozen=False)
    fields = dataclasses.fields(done)
    _check_defaults(fields)
    if "__init__" not in cls.__dict__:
        setattr(cls, "__init__", _lazy_init(cls, fields))
    _repr(cls, tuple(f.name for f in fields if f.repr))
    compared = tuple(f.name for f in fields if f.compare)
    if eq:
        _comparisons(cls, compared, order)
        if not explicit_hash:
            _hash(cls, tuple(f.name for f in fields if (f.compare if f.hash is None else f.hash)))
    _frozen_attributes(cls, tuple(f.name for f in fields))
    params = getattr(cls, "__dataclass_params__")
    params.init, params.repr, params.eq, params.order, params.frozen = True, True, eq, order, True
    return cls


if TYPE_CHECKING:
    from typing import dataclass_transform, overload

    @overload
    def frozen(cls: type[T], /) -> type[T]: ...

    @overload
    def frozen(*, eq: bool = True, order: bool = False) -> Callable[[type[T]], type[T]]: ...

    @dataclass_transform(frozen_default=True, field_specifiers=(dataclasses.field, dataclasses.Field))
    def frozen(cls: type[T] | None = None, /, *, eq: bool = True, order: bool = False) -> Any: ...

else:

    def frozen(cls=None, /, *, eq=True, order=False):
        """``@frozen``, ``@frozen(order=True)``, ``@frozen(eq=False)``: as
        ``@dataclass(frozen=True, ...)``, made cheaper to create (the module's docstring)."""
        if cls is None:
            return lambda c: _process(c, eq, order)
        return _process(cls, eq, order)
