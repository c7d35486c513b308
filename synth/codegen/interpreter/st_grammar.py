"""synth's LALR grammar of the Structured Text it emits, derived at run time from the grammar
of the installed blark (its ``iec.lark``).

The subset must keep blark's rule and terminal names and shapes, so that its LALR parse is the
tree blark's Earley parser gives and blark's transformer reads it; synth ships no grammar text
of blark's. :data:`DERIVATION` is synth's description of the subset, by definition name: the
definitions kept as blark writes them, and for the others an operation on blark's definition
(``synth.codegen.interpreter.grammar_edit``: keep some alternatives, a terminal that never
matches but keeps blark's placeholder, a run of ``";"`` made one, a priority added...);
:data:`_OWN` holds the two definitions of synth's own.

When the installed blark's grammar lacks a definition the derivation needs, or an operation
does not apply to it (another blark version), :func:`derive` gives ``None``: the fast path is
off and every text goes to blark's own Earley parser.

Example
-------
>>> derive('exit_statement.1: _EXIT ";"+\\n') is None  # a grammar without the rest of the subset
True
>>> installed = installed_grammar()
>>> installed is None or 'exit_statement.1: _EXIT ";"' in derive(installed[1]).splitlines()
True
"""

from __future__ import annotations

from functools import lru_cache
from typing import Any

from synth.codegen.interpreter.grammar_edit import (
    Alternatives, Drop, InlineFlags, Keep, Never, Op, Priority, Rename, Required, Run, Semicolons, Words, derive_definitions)

__all__ = ["DERIVATION", "derive", "installed_grammar", "st_parser"]


# ---- the subset: blark's definitions synth keeps, and how --------------------------------

_ONE, _NO_RUN = Semicolons(Run.ONE), Semicolons(Run.NONE)
_DECLARATIONS = ("input_declarations", "output_declarations", "input_output_declarations", "var_declarations", "temp_var_decls")

_AS_IS = """
iec_source IDENTIFIER INTEGER FIXED_POINT integer_literal duration _interval days hours minutes seconds milliseconds
pointer_type simple_type_name _subscript array_spec_init array_specification _variable symbolic_variable variable_name
direct_variable LOCATION_PREFIX SIZE_PREFIX subscript_list multi_element_variable variable_attributes var1_list
array_var_init_decl location derived_function_block_name access_specifier extends implements
function_block_body program_type_name program_var_declarations
LOGICAL_OR LOGICAL_XOR LOGICAL_AND LOGICAL_NOT LOGICAL_AND_THEN LOGICAL_OR_ELSE MODULO EQUALS EQUALS_NOT LESS_OR_EQUAL
GREATER_OR_EQUAL LESS_THAN GREATER_THAN ADDING SUBTRACTING MULTIPLY_WITH DIVIDE_BY MINUS PLUS ASSIGNMENT
assignment_expression or_else_expression and_then_expression xor_expression and_expression comparison_expression
equality_expression COMPARE_OP add_expression ADD_OPERATOR expression_term MULTIPLY_OPERATOR unary_expression
UNARY_OPERATOR parenthesized_expression else_if_clause else_clause control_variable _for_list
_AND _AND_THEN _AT _BY _DO _ELSE _ELSIF _END_FOR _END_IF _END_PROGRAM _END_REPEAT _END_VAR _END_WHILE _EXIT _FOR _IF
_MOD _NOT _OF _OR _OR_ELSE _PROGRAM _REPEAT _RETURN _THEN _TO _UNTIL _VAR _VAR_INPUT _VAR_IN_OUT _VAR_OUTPUT _VAR_TEMP
_WHILE _XOR MULTI_LINE_COMMENT SINGLE_LINE_COMMENT
"""

DERIVATION: dict[str, tuple[Op, ...]] = {
    **{name: () for name in _AS_IS.split()},
    "_library_element_declaration": (Keep(("function_block_type_declaration", "program_declaration")),),
    "constant": (Keep(("time_literal", "numeric_literal", "boolean_literal")),),
    "numeric_literal": (Keep(("integer_literal",)),),
    "any_integer": (Keep(("integer",)),),
    "integer": (Drop(),),
    "boolean_literal": (Drop(),),
    "TRUE_VALUE": (Alternatives((1,)),),
    "FALSE_VALUE": (Alternatives((1,)),),
    "time_literal": (Keep(("duration",)),),
    "non_generic_type_name": (Keep(("elementary_type_name",)),),
    "elementary_type_name": (Keep(("NUMERIC_TYPE_NAME", "DATE_TYPE_NAME", "BIT_STRING_TYPE_NAME")),),
    "NUMERIC_TYPE_NAME": (Words(), Priority(2)),
    "DATE_TYPE_NAME": (Words(), Priority(2)),
    "BIT_STRING_TYPE_NAME": (Words(), Priority(2)),
    "VAR_ATTRIB": (Words(), Priority(2)),
    "FUNCTION_BLOCK": (Words(),),
    "END_FUNCTION_BLOCK": (Words(),),
    "EQUALS_OP": (Priority(2),),
    "_ARRAY": (Priority(2),),
    **{name: (Never(),) for name in ("INTEGER_TYPE_NAME", "POINTER_TO", "DEREFERENCED", "ACCESS_SPECIFIER", "_EXTENDS",
                                     "_IMPLEMENTS", "DOTTED_IDENTIFIER")},
    "indirection_type": (Alternatives((1,)),),
    "simple_spec_init": (Keep(("simple_specification",)),),
    "simple_specification": (Keep(("elementary_type_name", "simple_type_name")),),
    "subrange": (Keep(("expression",)),),
    "_array_spec_type": (Keep(("non_generic_type_name",)),),
    "array_initialization": (Alternatives((0,)),),  # parsing.py nests the elements as Earley does
    "array_initial_element": (Alternatives((1,)),),
    "_array_initial_element": (Keep(("expression",)),),
    "field_selector": (Rename("DEREFERENCED", "FIELD_DEREFERENCED"),),
    **{name: (_NO_RUN,) for name in ("input_declarations", "output_declarations", "input_output_declarations",
                                     "temp_var_decls", "var_body")},
    "_var_input_body": (_ONE,),
    "_var_input_body_item": (Keep(("var_init_decl",)),),
    "var1": (Alternatives((0,)),),
    "var_init_decl": (Keep(("array_var_init_decl", "var1_init_decl")),),
    "var1_init_decl": (Keep(("simple_spec_init",)),),
    "var_declarations": (Rename("var_body", "located_body"), _NO_RUN),
    "located_var_decl": (Required("variable_name"), _ONE),
    "_located_var_spec_init": (Keep(("simple_spec_init",)),),
    "function_block_type_declaration": (_ONE,),
    "fb_var_declaration": (Keep(_DECLARATIONS),),
    "program_declaration": (_ONE,),
    "program_var_declaration": (Keep(_DECLARATIONS),),
    "expression": (Drop(("ASSIGNMENT",)),),
    "function_call": (Drop(("DEREFERENCED",)), Drop()),
    "primary_expression": (Keep(("parenthesized_expression", "function_call", "_variable", "constant")),),
    "statement_list": (Drop(("end_of_statement_list_label",)),),
    "_statement": (Keep(("assignment_statement", "return_statement", "function_call_statement", "if_statement",
                         "for_statement", "while_statement", "repeat_statement", "exit_statement")),),
    "assignment_statement": (Drop(("_variable",)), _ONE),
    "param_assignment": (Alternatives((1, 2)),),
    **{name: (_ONE,) for name in ("return_statement", "function_call_statement", "if_statement", "for_statement",
                                  "while_statement", "repeat_statement", "exit_statement")},
    "PRAGMA": (InlineFlags(),),
}
"""blark's definitions in the subset, each with the operations that make it synth's (none: as
blark writes it). The subset: FUNCTION_BLOCKs and PROGRAMs; VAR, VAR_INPUT, VAR_OUTPUT,
VAR_IN_OUT, VAR_TEMP blocks of variables of an elementary type, an array of one or a named type;
assignment (one target), call, IF, FOR, WHILE, REPEAT, EXIT, RETURN; no ``:=`` inside an
expression, no dereference, no typed, real, string or date literal (the terminals that never
match keep blark's placeholders, the ``None`` children of its optional parts); one ``;`` where
blark allows a run (a run is ambiguous in blark's grammar), none after ``END_VAR`` (blark's
parser reads it as an empty statement); type names and attributes ahead of identifiers, the
choice blark's parser makes where both are allowed."""

_OWN = (
    # A VAR block's declarations, a located one read as blark's located_var_decl (lark's LALR
    # prefers the shift to it); parsing.py makes the block blark's located_var_declarations when
    # it is in a PROGRAM and all its declarations are located, else turns them back into
    # var1_init_decl.
    'located_body: ( located_var_decl | var_init_decl ";" )* -> var_body',
    "FIELD_DEREFERENCED: /(?!)FIELD_DEREFERENCED/",  # field_selector's placeholder, apart from variable_name's
)


@lru_cache(maxsize=2)
def derive(grammar: str) -> str | None:
    """synth's LALR grammar from blark's ``grammar`` text, or ``None`` (the fast path off);
    about 6 ms of CPU, once a process."""
    derived = derive_definitions(grammar, DERIVATION, _OWN)
    return None if derived is None else derived + "\n"


def installed_grammar() -> tuple[str, str] | None:
    """The installed blark's version and grammar text (its ``GRAMMAR_FILENAME``), ``None``
    without them."""
    try:
        from blark import GRAMMAR_FILENAME, __version__

        return str(__version__), GRAMMAR_FILENAME.read_text(encoding="utf-8")
    except (ImportError, OSError):
        return None


@lru_cache(maxsize=None)
def st_parser(start: str) -> Any:
    """The cached LALR parser of the grammar derived from the installed blark's, from rule
    ``start``; ``None`` when there is none (every text then goes to blark's Earley parser)."""
    from lark import LarkError

    from synth.syntax import parser

    installed = installed_grammar()
    text = derive(installed[1]) if installed is not None else None
    if installed is None or text is None:
        return None
    try:  # cached by blark's version and the derived text
        return parser(f"st-blark{installed[0]}", start, text)
    except LarkError:
        return None
