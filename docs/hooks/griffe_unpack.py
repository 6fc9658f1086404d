"""Griffe extension: module constants assigned by tuple unpacking (``A, B = 0, 1``) are attributes.

Griffe's static analysis skips such assignments, so constants the modules export in ``__all__``
(``loopshaping.controller.MIN_OMEGA``, the kernel's parameter indices ``P_*``) would be missing
from the API reference. Only literal tuples of equal length are read; anything else is left alone.
"""
from __future__ import annotations

import ast

import griffe


class TupleUnpacking(griffe.Extension):
    """Add one module attribute per name of a module-level ``A, B = x, y`` assignment."""

    def on_module_members(self, *, node: ast.AST, mod: griffe.Module, **kwargs) -> None:  # noqa: D102
        for stmt in getattr(node, "body", []):
            if not (isinstance(stmt, ast.Assign) and len(stmt.targets) == 1):
                continue
            target, value = stmt.targets[0], stmt.value
            if not (isinstance(target, ast.Tuple) and isinstance(value, ast.Tuple)
                    and len(target.elts) == len(value.elts)
                    and all(isinstance(t, ast.Name) for t in target.elts)):
                continue
            for t, v in zip(target.elts, value.elts):
                if t.id in mod.members:
                    continue
                attr = griffe.Attribute(t.id, lineno=stmt.lineno, endlineno=stmt.end_lineno,
                                        value=ast.unparse(v), parent=mod)
                attr.labels.add("module-attribute")
                mod.set_member(t.id, attr)
