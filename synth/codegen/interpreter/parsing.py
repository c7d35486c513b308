"""Which parser reads Structured Text: synth's LALR grammar of the ST it emits, else blark's.

blark (the IEC 61131-3 parser the interpreter reads the tree of) parses with lark's Earley
parser on a scannerless lexer: about 1 ms of CPU per character, seconds for a generated
program or filter block. Its grammar cannot run under lark's LALR parser as it is (lark
reports reduce/reduce collisions: an identifier is a variable, a type or a block name
depending on what follows, an array initialiser nests either way). synth's LALR grammar is
the subset of blark's grammar that synth's generators write, with blark's rule and terminal
names, so its LALR parse is the tree blark's Earley parser gives (``tests/test_st_parsing.py``
compares them, Earley being the oracle: on every generated program, target and filter block
nightly), some 70 times faster on the box sorting's filter block. It is derived at run time
from the installed blark's own grammar (:mod:`synth.codegen.interpreter.st_grammar`): synth
ships no grammar text of blark's, and the subset follows the blark installed; when that
blark's grammar is not one the derivation knows, there is no LALR grammar and every text goes
to blark's parser.

:func:`parse_st` tries that grammar first. A text it refuses (anything outside the subset,
and every syntax error) goes to blark's own parser, whose tree or error the caller gets as
before: the language accepted is blark's, the error messages are blark's.

Two places where the trees would differ are mended after the LALR parse (:func:`_as_earley`):

* blark's grammar lets a bracketed array initialiser ``[a, b, c, ...]`` nest its elements in
  pairs many ways, and Earley's choice is the pairs grouped from the right
  (``[B(B(a, b), B(c, d)), B(e, f)]``...): built from the flat list the LALR grammar reads,
  for lists of constants (another list goes to Earley);
* a ``VAR`` block of a ``PROGRAM`` whose variables are all located (``x AT %QX0.0 : BOOL``)
  is blark's ``located_var_declarations``, one that also holds another variable its
  ``var_declarations``: which one is known at ``END_VAR``, after the declarations are read.

Example
-------
>>> result = parse_st("PROGRAM P\\nVAR x : BOOL; END_VAR\\nx := NOT x;\\nEND_PROGRAM\\n", "p.st")
>>> type(result.transform().items[0]).__name__, result.exception is None
('Program', True)
"""

from __future__ import annotations

from typing import Any, Iterator

__all__ = ["parse_st", "parse_item", "fast_tree", "STARTS"]

STARTS = ("iec_source", "program_declaration", "function_block_type_declaration", "statement_list")
"""blark's start rules synth's grammar has (a whole file; a TwinCAT POU's declaration and body)."""

_ITEM, _BARE, _BRACKETED = "array_initial_element", "bare_array_initialization", "bracketed_array_initialization"


def parse_st(text: str, file: str, start: str = "iec_source", line_map: dict[int, int] | None = None) -> Any:
    """blark's ``ParseResult`` of ``text`` from blark's rule ``start`` (the tree of synth's
    grammar when it reads the text, else blark's Earley parse, its tree or its exception);
    ``line_map``: blark's, for a part of a TwinCAT file."""
    from blark.parse import parse_source_code

    from synth.codegen.interpreter.st_grammar import st_parser

    if start in STARTS and (fast_parser := st_parser(start)) is not None:
        fast = parse_source_code(text, fn=file, parser=fast_parser, starting_rule=start, line_map=line_map)
        if fast.exception is None and fast.tree is not None and _as_earley(fast.tree):
            return fast
    return parse_source_code(text, fn=file, starting_rule=start, line_map=line_map)


def parse_item(item: Any, file: str) -> Iterator[Any]:
    """blark's ``parse_item`` with :func:`parse_st`: the ``ParseResult`` of every part of a
    blark source item (a TwinCAT POU's declaration, its implementation)."""
    from blark.input import BlarkCompositeSourceItem

    if isinstance(item, BlarkCompositeSourceItem):
        for part in item.parts:
            yield from parse_item(part, file)
        return
    code, line_map = item.get_code_and_line_map()
    yield parse_st(code, file, item.grammar_rule, line_map)


def fast_tree(text: str, start: str = "iec_source") -> Any:
    """The tree of synth's grammar for ``text`` from rule ``start`` (comments blanked as blark
    does), or ``None`` when the text is outside it or there is no such grammar (for the
    comparison with blark's parser)."""
    from blark import util
    from lark import LarkError

    from synth.codegen.interpreter.st_grammar import st_parser

    _, clean = util.find_and_clean_comments(text)
    if (fast_parser := st_parser(start)) is None:
        return None
    try:
        tree = fast_parser.parse(clean)
    except LarkError:
        return None
    return tree if _as_earley(tree) else None


def _as_earley(tree: Any) -> bool:
    """Mend, in place, the two places where the LALR tree is not yet Earley's (initialisers,
    located declarations); ``False`` when the text is one whose Earley tree is not assumed."""
    for node in list(tree.find_data(_BRACKETED)):
        if not all(_constant(item) for item in node.children):
            return False
        node.children = _grouped(node.children)
    for pou in (*tree.find_data("program_declaration"), *tree.find_data("function_block_type_declaration")):
        blocks = pou.children[1].children if pou.data == "program_declaration" else pou.children
        for block in (b for b in blocks if getattr(b, "data", None) == "var_declarations"):
            attributes, body = block.children
            if not body.children:  # an empty VAR block: Earley reads another rule
                return False
            if pou.data == "program_declaration" and all(d.data == "located_var_decl" for d in body.children):
                block.data, block.children = "located_var_declarations", [attributes, *body.children]
            else:
                body.children = [_unlocated(d) if d.data == "located_var_decl" else d for d in body.children]
    return True


def _unlocated(decl: Any) -> Any:
    """``located_var_decl(name, location, spec)`` as ``var1_init_decl(var1_list(var1(name,
    location)), spec)``, as blark reads a located variable among others."""
    from lark import Tree

    name, location, spec = decl.children
    return _placed(Tree("var1_init_decl", [_placed(Tree("var1_list", [_placed(Tree("var1", [name, location]))])), spec]))


def _grouped(items: list[Any]) -> list[Any]:
    """Earley's children for the elements ``items``: up to two as they are, three as the first
    and a pair, more as the group of all but the last two, then the pair of those."""
    if len(items) <= 2:
        return list(items)
    if len(items) == 3:
        return [items[0], _wrapped(items[1:])]
    return [_wrapped(items[:-2]), _wrapped(items[-2:])]


def _wrapped(items: list[Any]) -> Any:
    """``array_initial_element(bare_array_initialization(grouped items))``."""
    from lark import Tree

    return _placed(Tree(_ITEM, [_placed(Tree(_BARE, _grouped(items)))]))


def _placed(node: Any) -> Any:
    """``node`` placed as lark places a rule: from its first child's start to its last child's end."""
    first, last = node.children[0].meta, node.children[-1].meta
    for key in ("line", "column", "start_pos"):
        setattr(node.meta, key, getattr(first, key))
        setattr(node.meta, "container_" + key, getattr(first, key))
    for key in ("end_line", "end_column", "end_pos"):
        setattr(node.meta, key, getattr(last, key))
        setattr(node.meta, "container_" + key, getattr(last, key))
    node.meta.empty = False
    return node


def _constant(item: Any) -> bool:
    """An initialiser's element that is a constant, signed or not (``expression`` down to
    ``unary_expression(sign, constant)`` through one child at each level)."""
    node = item.children[0] if item.data == _ITEM and len(item.children) == 1 else None
    while node is not None and getattr(node, "data", None) != "unary_expression":
        node = node.children[0] if len(node.children) == 1 else None
    return node is not None and getattr(node.children[1], "data", None) == "constant"
