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
    """Only core/jit.py calls numba.njit; no fastmath anywhere; fewer than ten entry kernels."""
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
    assert 0 < entry < 10, entry
    jit = (REPO / "core" / "jit.py").read_text()
    assert "cache=True" in jit and "nogil=True" in jit


def test_no_jitclass_or_object_mode():
    for path in CORE_FILES:
        text = path.read_text(encoding="utf-8")
        assert "jitclass" not in text and "forceobj" not in text and "objmode" not in text, path
