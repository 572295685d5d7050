"""BT.CPP 4.10's scripting language: an own tokenizer, a Pratt parser and a tree-walking evaluator.

Nothing here ever hands text to Python's ``eval``/``exec``: a script is tokenized, parsed into a small
AST (:mod:`.ast`) and evaluated against a blackboard and the factory's scripting enums.
"""

from __future__ import annotations

from kinema.bt.script.parser import Script, parse_script, validate_script

__all__ = ["Script", "parse_script", "validate_script"]
