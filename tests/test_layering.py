"""Architecture boundaries of core/ and presets/, and the Numba policy."""
import ast
import re
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[1]
CORE_FILES = sorted((REPO / "core").rglob("*.py"))


@pytest.mark.parametrize("path", CORE_FILES, ids=lambda p: str(p.relative_to(REPO)))
def test_core_never_imports_bpy_or_the_addon(path):
    tree = ast.parse(path.read_text(encoding="utf-8"))
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            for a in node.names:
                assert a.name.split(".")[0] not in ("bpy", "mathutils", "bmesh", "spectral_gi", "core", "addon"), \
                    f"{path}:{node.lineno} imports {a.name}"
        elif isinstance(node, ast.ImportFrom):
            mod = node.module or ""
            if node.level == 0:
                assert mod.split(".")[0] not in ("bpy", "mathutils", "bmesh", "spectral_gi", "core", "addon"), \
                    f"{path}:{node.lineno} imports from {mod}"
            else:
                depth = len(path.relative_to(REPO / "core").parts) - 1
                assert node.level <= depth + 1, f"{path}:{node.lineno} climbs out of core"
                assert not (node.level == depth + 1 and mod.startswith("addon")), f"{path}:{node.lineno}"


def test_presets_hold_no_code():
    code = [p for p in (REPO / "presets").rglob("*")
            if p.is_file() and p.suffix.lower() in (".py", ".pyc", ".so", ".sh", ".pkl", ".pickle", ".npy")]
    assert not code, code
    for p in (REPO / "presets").rglob("*.npz"):
        import numpy as np
        with np.load(p, allow_pickle=False) as z:
            for k in z.files:
                z[k]


def test_one_numba_decorator_policy():
    """Only core/jit.py calls numba.njit; no fastmath anywhere; at most ten entry kernels."""
    offenders = []
    entry = 0
    for path in CORE_FILES:
        text = path.read_text(encoding="utf-8")
        if path.name != "jit.py" and re.search(r"\b(njit|numba\.jit|@jit)\b", text):
            offenders.append(str(path))
        if "fastmath" in text:
            offenders.append(f"{path}: fastmath")
        entry += len(re.findall(r"^@kernel\b", text, flags=re.M))
    assert not offenders, offenders
    assert 0 < entry <= 10, entry
    jit = (REPO / "core" / "jit.py").read_text()
    assert "cache=True" in jit and "nogil=True" in jit


def test_no_jitclass_or_object_mode():
    for path in CORE_FILES:
        text = path.read_text(encoding="utf-8")
        assert "jitclass" not in text and "forceobj" not in text and "objmode" not in text, path


def _product_modules():
    """{dotted name under the package: file} of core/, addon/ and the command line."""
    files = [*CORE_FILES, *sorted((REPO / "addon").rglob("*.py")), REPO / "cli.py"]
    out = {}
    for p in files:
        parts = list(p.relative_to(REPO).with_suffix("").parts)
        if parts[-1] == "__init__":
            parts = parts[:-1]
        out[".".join(parts)] = p
    return out


def _import_graph(modules):
    """Edges module → module for every relative import, at module level or inside a function
    (a function-level import that only dodges a circle is still a circle), plus the edge to
    the package whose ``__init__`` an import of one of its modules runs first."""
    graph = {m: set() for m in modules}
    for m, path in modules.items():
        package = m if path.name == "__init__.py" else m.rpartition(".")[0]
        for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
            if not isinstance(node, ast.ImportFrom) or node.level == 0:
                continue
            base = package.split(".") if package else []
            base = base[:len(base) - (node.level - 1)]
            target = ".".join(base + ([node.module] if node.module else []))
            for a in node.names:
                sub = f"{target}.{a.name}".lstrip(".")
                t = sub if sub in modules else target
                if t in modules and t != m:
                    graph[m].add(t)
    for m in list(graph):
        for t in list(graph[m]):
            parent = t.rpartition(".")[0]
            while parent and parent in graph and not (m == parent or m.startswith(parent + ".")):
                graph[m].add(parent)
                parent = parent.rpartition(".")[0]
    return graph


def test_no_import_cycles():
    """Each name sits where it belongs: no two modules of the product import each other,
    directly or through others."""
    graph = _import_graph(_product_modules())
    state = {}
    cycles = []

    def visit(m, stack):
        state[m] = 1
        stack.append(m)
        for t in sorted(graph[m]):
            if state.get(t) == 1:
                cycles.append(stack[stack.index(t):] + [t])
            elif t not in state:
                visit(t, stack)
        stack.pop()
        state[m] = 2

    for m in sorted(graph):
        if m not in state:
            visit(m, [])
    assert not cycles, "\n".join(" → ".join(c) for c in cycles)


def test_the_cycle_check_finds_a_cycle():
    graph = _import_graph({"core.a": REPO / "core" / "jit.py"})
    assert graph == {"core.a": set()}
    # two modules that import each other inside functions
    import textwrap
    import tempfile
    with tempfile.TemporaryDirectory() as d:
        a, b = Path(d) / "a.py", Path(d) / "b.py"
        a.write_text(textwrap.dedent("def f():\n    from .b import g\n"))
        b.write_text(textwrap.dedent("def g():\n    from .a import f\n"))
        g = _import_graph({"core.a": a, "core.b": b})
        assert g == {"core.a": {"core.b"}, "core.b": {"core.a"}}
