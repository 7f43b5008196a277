"""Modules over ~600 lines and functions over ~80 lines in bearing_lab/.

    python tools/sizes.py            # the offenders, longest first
    python tools/sizes.py --all      # every module's line count

Function length: from the ``def`` line to the last line of its body, without the docstring
(the numpy-style parameter lists and examples are documentation, not code); nested functions
count inside their parent and on their own.
"""
from __future__ import annotations

import ast
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
MODULE_LINES = 600
FUNCTION_LINES = 80


def module_sizes(pkg: Path = ROOT / "bearing_lab") -> dict[str, int]:
    return {str(p.relative_to(ROOT)): len(p.read_text().splitlines()) for p in sorted(pkg.rglob("*.py"))}


def function_sizes(pkg: Path = ROOT / "bearing_lab") -> dict[str, int]:
    """``{"path::Class.func": lines}`` for every function and method."""
    out = {}
    for p in sorted(pkg.rglob("*.py")):
        rel = str(p.relative_to(ROOT))

        def walk(node, prefix):
            for child in ast.iter_child_nodes(node):
                if isinstance(child, (ast.FunctionDef, ast.AsyncFunctionDef)):
                    name = prefix + child.name
                    n = child.end_lineno - child.lineno + 1
                    body0 = child.body[0]
                    if (isinstance(body0, ast.Expr) and isinstance(body0.value, ast.Constant)
                            and isinstance(body0.value.value, str)):
                        n -= body0.end_lineno - body0.lineno + 1
                    out[f"{rel}::{name}"] = n
                    walk(child, name + ".")
                elif isinstance(child, ast.ClassDef):
                    walk(child, prefix + child.name + ".")
        walk(ast.parse(p.read_text()), "")
    return out


def offenders():
    mods = {k: v for k, v in module_sizes().items() if v > MODULE_LINES}
    funcs = {k: v for k, v in function_sizes().items() if v > FUNCTION_LINES}
    return mods, funcs


def main(argv=None) -> int:
    argv = sys.argv[1:] if argv is None else argv
    if "--all" in argv:
        for k, v in sorted(module_sizes().items(), key=lambda kv: -kv[1]):
            print(f"{v:5d}  {k}")
        return 0
    mods, funcs = offenders()
    print(f"modules over {MODULE_LINES} lines:")
    for k, v in sorted(mods.items(), key=lambda kv: -kv[1]):
        print(f"  {v:5d}  {k}")
    print(f"functions over {FUNCTION_LINES} lines:")
    for k, v in sorted(funcs.items(), key=lambda kv: -kv[1]):
        print(f"  {v:5d}  {k}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
