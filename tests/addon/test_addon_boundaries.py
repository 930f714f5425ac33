"""Architecture boundaries of the add-on (no Blender needed)."""
import ast
import subprocess
import sys
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[2]
ADDON = REPO / "addon"
FORBIDDEN_MODULES = ("numba", "llvmlite", "spectral_gi", "core", "colour")


def addon_files():
    return sorted(ADDON.rglob("*.py"))


def resolve(path, node):
    """Absolute dotted name (relative to the repo root package) of an ImportFrom."""
    pkg = list(path.relative_to(REPO).with_suffix("").parts[:-1])
    if node.level == 0:
        return None
    base = pkg[: len(pkg) - (node.level - 1)] if node.level > 1 else pkg
    if node.level - 1 > len(pkg):
        raise AssertionError(f"{path}: relative import climbs above the package root")
    return ".".join(base + ([node.module] if node.module else []))


@pytest.mark.parametrize("path", addon_files(), ids=lambda p: str(p.relative_to(REPO)))
def test_addon_reaches_core_only_through_its_public_names(path):
    import spectral_gi.core as core

    tree = ast.parse(path.read_text(encoding="utf-8"), filename=str(path))
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            for alias in node.names:
                top = alias.name.split(".")[0]
                assert top not in FORBIDDEN_MODULES, f"{path}:{node.lineno}: absolute import of {alias.name}"
        elif isinstance(node, ast.ImportFrom):
            if node.level == 0:
                top = (node.module or "").split(".")[0]
                assert top not in FORBIDDEN_MODULES, f"{path}:{node.lineno}: absolute import from {node.module}"
                continue
            target = resolve(path, node)
            if target == "core":
                for alias in node.names:
                    assert alias.name in core.__all__, \
                        f"{path}:{node.lineno}: core.{alias.name} is not in core.__all__"
            else:
                assert not target.startswith("core"), \
                    f"{path}:{node.lineno}: reaches into {target}; use names from core.__all__"
                assert target.startswith("addon") or target == "", \
                    f"{path}:{node.lineno}: relative import of {target} outside the add-on"


@pytest.mark.parametrize("path", addon_files(), ids=lambda p: str(p.relative_to(REPO)))
def test_addon_has_no_kernels(path):
    tree = ast.parse(path.read_text(encoding="utf-8"), filename=str(path))
    kernel_names = {"njit", "jit", "prange", "vectorize", "guvectorize", "cfunc"}
    for node in ast.walk(tree):
        name = node.id if isinstance(node, ast.Name) else node.attr if isinstance(node, ast.Attribute) else None
        assert name not in kernel_names, f"{path}:{node.lineno}: uses {name}; kernels belong in core"


def test_importing_the_package_does_not_import_bpy():
    code = ("import sys, spectral_gi, spectral_gi.addon, spectral_gi.addon.export.convert; "
            "assert 'bpy' not in sys.modules, 'bpy imported'; "
            "assert 'numba' not in sys.modules, 'numba imported'")
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=REPO)
    assert proc.returncode == 0, proc.stderr
