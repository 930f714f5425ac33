"""The wheel holds every package of the tree, and the extension manifest is consistent."""
import tomllib
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]


def test_every_package_is_listed_in_pyproject():
    cfg = tomllib.loads((REPO / "pyproject.toml").read_text())
    listed = set(cfg["tool"]["setuptools"]["packages"])
    found = {"spectral_gi"}
    for init in REPO.glob("*/**/__init__.py"):
        rel = init.parent.relative_to(REPO)
        if rel.parts[0] in ("core", "addon"):
            found.add("spectral_gi." + ".".join(rel.parts))
    assert found <= listed, sorted(found - listed)


def test_manifest_matches_pyproject():
    cfg = tomllib.loads((REPO / "pyproject.toml").read_text())
    man = tomllib.loads((REPO / "blender_manifest.toml").read_text())
    assert man["id"] == "spectral_gi"
    assert man["version"] == cfg["project"]["version"]
    assert cfg["project"]["name"] == "spectral-gi"
    assert cfg["project"]["scripts"]["spectral-gi"] == "spectral_gi.core.cli:main"


def test_root_init_is_the_two_line_shim():
    lines = [ln for ln in (REPO / "__init__.py").read_text().splitlines() if ln.strip()]
    assert len(lines) == 2 and "from .addon import register, unregister" in lines[1]
