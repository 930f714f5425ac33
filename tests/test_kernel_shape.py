"""The shape of core's code: numba-compiled functions take at most 16 parameters (bundles of
scalars travel as tuples, arrays as records) and no function in core is longer than 150
lines (the path kernel is split into fragments and helpers)."""
import ast
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[1]
CORE_FILES = sorted((REPO / "core").rglob("*.py"))
JIT_DECORATORS = {"kernel", "inline", "fragment", "function"}
MAX_PARAMS = 16
MAX_LINES = 150


def _decorator_name(node):
    if isinstance(node, ast.Call):
        node = node.func
    if isinstance(node, ast.Attribute):
        return node.attr
    if isinstance(node, ast.Name):
        return node.id
    return None


def shape_violations(source, label):
    """[message] for each numba-decorated function over MAX_PARAMS parameters and each
    function over MAX_LINES lines (decorators and docstring included) in ``source``."""
    found = []
    for node in ast.walk(ast.parse(source)):
        if not isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
            continue
        a = node.args
        n_params = len(a.posonlyargs) + len(a.args) + len(a.kwonlyargs) + (a.vararg is not None) \
            + (a.kwarg is not None)
        jitted = any(_decorator_name(d) in JIT_DECORATORS for d in node.decorator_list)
        if jitted and n_params > MAX_PARAMS:
            found.append(f"{label}:{node.lineno} {node.name} takes {n_params} parameters (at most {MAX_PARAMS})")
        first = min([node.lineno] + [d.lineno for d in node.decorator_list])
        n_lines = node.end_lineno - first + 1
        if n_lines > MAX_LINES:
            found.append(f"{label}:{node.lineno} {node.name} is {n_lines} lines long (at most {MAX_LINES})")
    return found


@pytest.mark.parametrize("path", CORE_FILES, ids=lambda p: str(p.relative_to(REPO)))
def test_core_functions_are_small(path):
    assert not shape_violations(path.read_text(encoding="utf-8"), path.relative_to(REPO))


def test_the_shape_check_finds_violations():
    params = ", ".join(f"a{i}" for i in range(MAX_PARAMS + 1))
    body = "\n".join(f"    x{i} = {i}" for i in range(MAX_LINES))
    src = (f"@inline\ndef wide({params}):\n    return a0\n\n"
           f"@kernel(parallel=True)\ndef wide_kernel({params}):\n    return a0\n\n"
           f"def plain_wide({params}):\n    return a0\n\n"
           f"def long():\n{body}\n")
    found = shape_violations(src, "x.py")
    assert len(found) == 3, found
    assert "wide takes 17" in found[0] and "wide_kernel takes 17" in found[1] and "long is 151" in found[2]
