"""The wheel holds every package of the tree, and the extension manifest is consistent."""
import importlib.util
import tomllib
import zipfile
from pathlib import Path

import pytest

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
    assert cfg["project"]["scripts"]["spectral-gi"] == "spectral_gi.cli:main"


def test_root_init_is_the_two_line_shim():
    lines = [ln for ln in (REPO / "__init__.py").read_text().splitlines() if ln.strip()]
    assert len(lines) == 2 and "from .addon import register, unregister" in lines[1]


# --- Release build: bundled wheels (tools/build_extension.py --wheels), all offline --------------



def _build_tool():
    spec = importlib.util.spec_from_file_location("spectral_gi_build_extension_pkg",
                                                  REPO / "tools" / "build_extension.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def _fake_wheels(folder, names):
    folder.mkdir(parents=True, exist_ok=True)
    for n in names:
        (folder / n).write_bytes(b"")  # empty, correctly named
    return sorted(p.name for p in folder.glob("*.whl"))


def test_pinned_wheel_versions_are_the_installed_ones():
    import llvmlite
    import numba
    from importlib.metadata import version

    pins = _build_tool().WHEEL_PINS
    assert set(pins) == {"numba", "llvmlite", "OpenEXR"}
    assert pins["numba"] == numba.__version__
    assert pins["llvmlite"] == llvmlite.__version__
    assert pins["OpenEXR"] == version("OpenEXR")


def test_wheel_lock_covers_every_platform_once_at_the_pinned_versions():
    tool = _build_tool()
    per = tool.wheels_by_platform(tool.WHEEL_SHA256)
    assert set(per) == {"linux-x64", "windows-x64", "macos-arm64"}
    for plat, files in per.items():
        assert sorted(tool.wheel_info(f)[0] for f in files) == ["llvmlite", "numba", "openexr"], plat
        assert all("cp311" in f for f in files)
    assert sorted(f for fs in per.values() for f in fs) == sorted(tool.WHEEL_SHA256)
    assert all(len(h) == 64 and int(h, 16) >= 0 for h in tool.WHEEL_SHA256.values())


def test_manifest_writer_lists_exactly_the_wheels_of_a_folder(tmp_path):
    import tomllib

    tool = _build_tool()
    names = _fake_wheels(tmp_path / "wheels", tool.WHEEL_SHA256)
    source = (REPO / "blender_manifest.toml").read_text(encoding="utf-8")
    assert "wheels" not in tomllib.loads(source) and "platforms" not in tomllib.loads(source)
    text = tool.manifest_with_wheels(source, names)
    man = tomllib.loads(text)  # valid TOML
    assert man["platforms"] == ["linux-x64", "windows-x64", "macos-arm64"]
    assert sorted(man["wheels"]) == sorted(f"./wheels/{n}" for n in names)
    assert man["id"] == "spectral_gi" and "paths_exclude_pattern" in man["build"]  # rest kept
    per = tool.wheels_by_platform([w.rsplit("/", 1)[1] for w in man["wheels"]])
    assert [n for n in per["linux-x64"] if "manylinux" in n] == per["linux-x64"]
    assert [n for n in per["windows-x64"] if n.endswith("win_amd64.whl")] == per["windows-x64"]
    assert [n for n in per["macos-arm64"] if "macosx" in n and "arm64" in n] == per["macos-arm64"]


def test_manifest_writer_names_a_missing_or_wrong_wheel(tmp_path):
    tool = _build_tool()
    source = (REPO / "blender_manifest.toml").read_text(encoding="utf-8")
    names = [n for n in tool.WHEEL_SHA256 if not (n.startswith("llvmlite") and "win_amd64" in n)]
    with pytest.raises(RuntimeError, match="llvmlite.*windows-x64"):
        tool.manifest_with_wheels(source, names)
    old = list(tool.WHEEL_SHA256) + ["numba-0.64.0-cp311-cp311-macosx_11_0_arm64.whl"]
    with pytest.raises(RuntimeError, match="pinned 0.68"):
        tool.manifest_with_wheels(source, old)
    with pytest.raises(RuntimeError, match="already declares"):
        tool.manifest_with_wheels(tool.manifest_with_wheels(source, list(tool.WHEEL_SHA256)),
                                  list(tool.WHEEL_SHA256))


def test_release_build_splits_the_wheels_by_platform(tmp_path, monkeypatch):
    """The --wheels build, with fake wheels instead of pip: Blender's own build tool makes one
    zip per platform, each carrying (and its manifest listing) only that platform's wheels."""
    import tomllib

    tool = _build_tool()
    try:
        tool.blender_ext_script()
    except RuntimeError as exc:
        pytest.skip(str(exc))
    fake = tmp_path / "wheels"
    _fake_wheels(fake, tool.WHEEL_SHA256)
    monkeypatch.setattr(tool, "fetch_wheels", lambda *a, **k: sorted(fake.glob("*.whl")))
    zips = tool.build(tmp_path / "dist", quiet=True, wheels=True)
    expected = tool.wheels_by_platform(tool.WHEEL_SHA256)
    assert set(zips) == set(expected)
    for plat, path in zips.items():
        with zipfile.ZipFile(path) as z:
            inside = sorted(n.rsplit("/", 1)[1] for n in z.namelist() if n.endswith(".whl"))
            man = tomllib.loads(z.read("blender_manifest.toml").decode("utf-8"))
        assert inside == expected[plat], plat
        generated = man["build"]["generated"]
        assert generated["platforms"] == [plat]
        assert sorted(w.rsplit("/", 1)[1] for w in generated["wheels"]) == expected[plat]
