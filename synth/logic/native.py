"""Direct calls into CUDD for what dd makes slow: the relational product ``∃V. u ∧ v`` over
a cube built once, the test ``u ≤ v`` (dd has none: ``u & ~v == false`` builds the
conjunction, ``let`` of a cube builds the cofactor), the count of computed-table lookups,
the indices of a support (dd's ``support`` builds a set of names), the cofactor on one
literal or on a cube of many (dd's ``let`` first fills an array over every declared variable), the expansion
of a cube to a prime implicant, and the transfer of a function to another manager (dd's
``copy`` first lists its support by name).

dd's ``and_exists(u, v, names)`` builds the cube of ``names`` on every call by walking
every variable the manager declares (a Python loop: 10 µs at 400 variables, against 1 µs
for the product of two small functions), and dd offers no call that takes a cube already
built; its ``statistics()``, the only way to the lookups, scans the unique table and the
cache (17 ms at 128 chained outputs). CUDD's ``Cudd_bddAndAbstract`` and
``Cudd_ReadCacheLookUps`` are called here through ctypes, on the manager and node pointers
of dd's objects. dd exposes a node's pointer (``int(f) - 2``; ``BDD._add_int`` wraps a
pointer back, referenced), not its manager's: that pointer is read from the ``BDD``
object's fields, after checking that the fields after it are the ones dd declares public
(``vars``, ``_index_of_var``, ``_var_with_index``, in this order). A dd whose layout
differs, or a dd without CUDD, gets ``None`` and keeps dd's own calls.

Example
-------
>>> import dd.cudd as cudd
>>> b = cudd.BDD(); b.declare("x", "y", "z")
>>> n = native(b)
>>> u, v = b.add_expr("x & y"), b.add_expr("~x | z")
>>> n is None or (n.product(u, v, b.cube({"x"})) == cudd.and_exists(u, v, ["x"]) and n.lookups() > 0)
True
>>> n is None or (n.leq(u, b.add_expr("y")), n.leq(b.add_expr("y"), u)) == (True, False)
True
>>> n is None or (n.support_indices(b.add_expr("z & y")), n.support_indices(b.true)) == ([1, 2], [])
True
>>> n is None or (n.cofactor(v, "x", False), n.cofactor(v, "x", True)) == (b.true, b.add_expr("z"))
True
>>> n is None or (n.assigner(["z", "x"])(v, [False, True]), n.assigner(["z"])(v, [True])) == (b.false, b.true)
True
>>> n is None or n.prime(b.add_expr("x & y & z"), u | b.add_expr("z")) == b.add_expr("z")
True
>>> n is None or (n.quantified(v, [0, 2], True), n.quantified(v, [0, 2], False)) == (b.false, b.true)
True
"""

from __future__ import annotations

from functools import lru_cache
from typing import Any, Callable, Sequence

__all__ = ["Native", "native"]

Function = Any  # a dd.cudd Function


class Native:
    """CUDD's functions bound to one dd.cudd manager (see module docstring)."""

    def __init__(self, bdd: Any, manager: int, library: Any, module: Any) -> None:
        import ctypes

        self.bdd = bdd
        self.manager = manager
        ptr, c_int = ctypes.c_void_p, ctypes.c_int
        self._product = _typed(library.Cudd_bddAndAbstract, ptr, ptr, ptr, ptr, ptr)
        self._lookups = _typed(library.Cudd_ReadCacheLookUps, ctypes.c_double, ptr)
        self._leq = _typed(library.Cudd_bddLeq, c_int, ptr, ptr, ptr)
        self._fallback = module.and_exists
        self._cofactor = _typed(library.Cudd_Cofactor, ptr, ptr, ptr, ptr)
        self._literals: dict[str, tuple[Function, Function]] = {}
        self._transfer = _typed(library.Cudd_bddTransferRename, ptr, ptr, ptr, ptr, ptr)  # dd's own addendum to CUDD
        self._read_index = _typed(library.Cudd_NodeReadIndex, ctypes.c_uint, ptr)
        self._size = _typed(library.Cudd_ReadSize, c_int, ptr)
        self._to_cube = _typed(library.Cudd_IndicesToCube, ptr, ptr, ctypes.POINTER(c_int), c_int)
        self._abstract = {False: _typed(library.Cudd_bddExistAbstract, ptr, ptr, ptr, ptr),
                          True: _typed(library.Cudd_bddUnivAbstract, ptr, ptr, ptr, ptr)}
        self._prime = _typed(library.Cudd_bddMakePrime, ptr, ptr, ptr, ptr)
        self._cube = _typed(library.Cudd_bddComputeCube, ptr, ptr, ctypes.POINTER(ptr), ctypes.POINTER(c_int), c_int)
        self._indices = _typed(library.Cudd_SupportIndices, c_int, ptr, ptr, ctypes.POINTER(ctypes.POINTER(c_int)))
        self._array = ctypes.POINTER(ctypes.c_int)()
        self._array_ref = ctypes.byref(self._array)
        self._free = _free()

    def product(self, u: Function, v: Function, cube: Function) -> Function:
        """``∃cube. u ∧ v`` in one pass (``cube``: a positive cube of the manager)."""
        r = self._product(self.manager, int(u) - 2, int(v) - 2, int(cube) - 2)
        if not r:  # CUDD gave up (memory): dd's call reports it
            return self._fallback(u, v, self.bdd.support(cube))
        return self.wrapped(r)

    def leq(self, u: Function, v: Function) -> bool:
        """``u ≤ v`` (``u`` implies ``v``): CUDD's containment test, which builds no BDD and
        stops at the first point of ``u`` outside ``v``."""
        return bool(self._leq(self.manager, int(u) - 2, int(v) - 2))

    def cofactor(self, u: Function, name: str, value: bool) -> Function:
        """``u`` with the variable ``name`` at ``value``, by CUDD's cofactor on the literal
        (dd's ``let`` builds an array over every declared variable first)."""
        pair = self._literals.get(name)
        if pair is None:
            var = self.bdd.var(name)
            pair = self._literals[name] = (~var, var)
        r = self._cofactor(self.manager, int(u) - 2, int(pair[value]) - 2)
        if not r:  # CUDD gave up (memory): dd's call reports it
            return self.bdd.let({name: value}, u)
        return self.wrapped(r)

    def assigner(self, names: Sequence[str]) -> Callable[[Function, Sequence[bool]], Function]:
        """A function giving ``u`` with the variables ``names`` at ``values`` (one per name):
        CUDD's cofactor on their cube, the cube built by CUDD from an array of the variables
        made here once, in level order so that CUDD builds it in one pass from the bottom up
        (dd's ``let`` fills an array over every declared variable per call)."""
        import ctypes
        from operator import itemgetter

        count = len(names)
        order = sorted(range(count), key=lambda i: self.bdd.level_of_var(names[i]))  # CUDD's cube: one pass up
        nodes = (ctypes.c_void_p * count)(*(int(self.bdd.var(names[i])) - 2 for i in order))
        phases = ctypes.c_int * count
        ordered = itemgetter(*order) if count > 1 else (lambda values: tuple(values))

        def assigned(u: Function, values: Sequence[bool]) -> Function:
            if not count:
                return u
            cube = self._cube(self.manager, nodes, phases(*ordered(values)), count)
            held = self.wrapped(cube) if cube else None  # referenced while the cofactor runs
            r = self._cofactor(self.manager, int(u) - 2, cube) if held is not None else 0
            if not r:  # CUDD gave up (memory): dd's call reports it
                return self.bdd.let(dict(zip(names, values)), u)
            return self.wrapped(r)

        return assigned

    def prime(self, cube: Function, u: Function) -> Function | None:
        """CUDD's prime implicant of ``u`` from the implicant ``cube``: each of the cube's
        literals, from its top variable down, dropped while the cube still implies ``u``
        (None if CUDD gave up)."""
        r = self._prime(self.manager, int(cube) - 2, int(u) - 2)
        return self.wrapped(r) if r else None

    def support_indices(self, u: Function) -> list[int]:
        """The CUDD indices of the variables ``u`` depends on, ascending (CUDD sorts them, in
        an array of its own, freed here): dd's ``support`` names them in a set, 30–60 µs
        for 128 variables."""
        n = self._indices(self.manager, int(u) - 2, self._array_ref)
        if n < 0:
            raise MemoryError("CUDD could not list a support")
        if n == 0:  # CUDD allocated nothing
            return []
        indices = self._array[:n]
        self._free(self._array)
        return indices

    def quantified(self, u: Function, indices: list[int], every: bool) -> Function:
        """``∀`` (``every``) or ``∃`` of the variables of CUDD indices ``indices`` (ascending,
        in a manager whose indices are its levels) in ``u``: their cube built by CUDD from
        the bottom up (dd's ``forall`` and ``exist`` fill an array over every declared
        variable in Python first)."""
        import ctypes

        r = self._to_cube(self.manager, (ctypes.c_int * len(indices))(*indices), len(indices))
        if not r:
            raise MemoryError("CUDD could not build a cube")
        cube = self.wrapped(r)  # referenced while the abstraction runs
        r = self._abstract[every](self.manager, int(u) - 2, int(cube) - 2)
        if not r:
            raise MemoryError("CUDD could not quantify")
        return self.wrapped(r)

    def index(self, u: Function) -> int:
        """The CUDD index of ``u``'s top variable (of a variable's own function: that variable's)."""
        return int(self._read_index(int(u) - 2))

    def size(self) -> int:
        """The number of variables the manager declares (its indices are below it)."""
        return int(self._size(self.manager))

    def transfer(self, u: Function, target: Native, renaming: Any) -> Function:
        """``u`` in the manager of ``target``, the variable of index ``i`` (of ``u``'s support)
        renamed to index ``renaming[i]`` there (an array of C ints), as dd's ``copy`` does
        after listing ``u``'s support by name."""
        r = self._transfer(self.manager, target.manager, int(u) - 2, renaming)
        if not r:  # CUDD gave up (memory): dd's call reports it
            return self.bdd.copy(u, target.bdd)
        return target.wrapped(r)

    def wrapped(self, r: int) -> Function:
        """The dd function of the node CUDD returned at ``r`` (referenced)."""
        return self.bdd._add_int(r + 2)

    def lookups(self) -> int:
        """The manager's computed-table lookups so far."""
        return int(self._lookups(self.manager))


def native(bdd: Any) -> Native | None:
    """CUDD's functions for the dd.cudd manager ``bdd``, or ``None`` where they cannot be
    called directly."""
    try:
        import ctypes

        module = __import__(type(bdd).__module__, fromlist=["BDD"])
        fields = (ctypes.c_void_p * 7).from_address(id(bdd))  # refcount, type, vtable, manager, vars, ...
        if (fields[4], fields[5], fields[6]) != (id(bdd.vars), id(bdd._index_of_var), id(bdd._var_with_index)):
            return None
        return Native(bdd, int(fields[3] or 0), _library(module.__file__), module)
    except (AttributeError, ImportError, OSError, TypeError, ValueError):
        return None


def _typed(call: Any, restype: Any, *argtypes: Any) -> Any:
    """The C function ``call`` with its result and argument types set."""
    call.restype = restype
    call.argtypes = list(argtypes)
    return call


@lru_cache(maxsize=None)
def _free() -> Any:
    """The C library's ``free``, which releases the arrays CUDD allocates for its caller."""
    import ctypes

    free = ctypes.CDLL(None).free
    free.argtypes = [ctypes.c_void_p]
    free.restype = None
    return free


@lru_cache(maxsize=None)
def _library(path: str) -> Any:
    """The shared library at ``path`` (dd's CUDD extension, already loaded), opened once: the
    covers open a manager, and so a :class:`Native`, per cover."""
    import ctypes

    return ctypes.CDLL(path)
