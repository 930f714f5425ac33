#!/usr/bin/env python3
"""Build the Blender extension zip of spectral-gi.

Stages a clean copy of the repository (the files git tracks or would track, i.e.
``git ls-files --cached --others --exclude-standard``, or only tracked files with
``--tracked-only``; without tests, benchmarks, CI, tools and docs) and runs Blender's own
extension build tool on it — the standard-library script shipped inside the ``bpy`` wheel
(``bpy/<version>/scripts/addons_core/bl_pkg/cli/blender_ext.py``).

    python tools/build_extension.py [--wheels] [--output-dir DIR]

Without ``--wheels`` it builds one *development* zip without wheels: numba, llvmlite and
OpenEXR must already be importable in Blender's Python.

With ``--wheels`` it builds the *release* zips: the pinned wheels (``WHEEL_PINS``) of the
run-time imports that Blender's Python lacks (numba, llvmlite, OpenEXR; Blender ships numpy)
for CPython 3.11 (Blender 4.2-5.0) on ``WHEEL_PLATFORMS`` are fetched with ``pip download``
into ``<repo>/wheels/`` (a cache, git-ignored; every file is checked against ``WHEEL_SHA256``),
the staged manifest gains ``platforms`` and ``wheels``, and Blender's build is run with
``--split-platforms``: one zip per platform carrying only that platform's wheels, which install
without network.
"""
from __future__ import annotations

import argparse
import hashlib
import importlib.util
import re
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

REPO = Path(__file__).resolve().parent.parent
EXCLUDED_TOP = ("tests", "benchmarks", ".ci", "tools", "docs", "dist", "build")
EXCLUDED_SUFFIXES = (".pyc", ".nbi", ".nbc", ".zip")
EXTENSION_ID = "spectral_gi"
WHEEL_DIR = REPO / "wheels"

# Run-time imports missing from Blender's Python, pinned to the versions the tests run with
# (tests/test_packaging.py checks them against the installed packages).
WHEEL_PINS = {"numba": "0.68.1", "llvmlite": "0.50.0", "OpenEXR": "3.5.3"}
WHEEL_PYTHON = "3.11"  # Blender 4.2 to 5.0
# Blender platform -> pip ``--platform`` tag. macOS: numba 0.68 / llvmlite 0.50 need macOS 12;
# asking for macosx_11_0_arm64 makes pip fall back silently to older numba/llvmlite.
WHEEL_PLATFORMS = {
    "linux-x64": "manylinux_2_28_x86_64",
    "windows-x64": "win_amd64",
    "macos-arm64": "macosx_12_0_arm64",
}
# sha256 of every wheel, as downloaded by pip from PyPI (pip checks the index's hashes) on
# 2026-05; update together with WHEEL_PINS. Downloads use ``--require-hashes`` with these.
WHEEL_SHA256 = {
    "numba-0.68.1-cp311-cp311-manylinux_2_27_x86_64.manylinux_2_28_x86_64.whl":
        "58fe7a3810261cf13797d8aa94c018cfe91e1e8adf634df60eb60ef834f9367b",
    "llvmlite-0.50.0-cp311-cp311-manylinux_2_27_x86_64.manylinux_2_28_x86_64.whl":
        "a6ffde00d4be8772a24e3e8b3af6bf86a79e7cf066d944ef56136b3957d707dc",
    "openexr-3.5.3-cp311-cp311-manylinux_2_28_x86_64.whl":
        "45a35cb35b38b83635dc149d82627a618f8537f339753dc045f409b6dec0ac4c",
    "numba-0.68.1-cp311-cp311-win_amd64.whl":
        "e5a2d544d8a2da45f9cc5856ed794c31f133ada51ef7a734a9b7cd4596e1887f",
    "llvmlite-0.50.0-cp311-cp311-win_amd64.whl":
        "ffe46ef508df226e54b5fe1f7bf11122e5297bcdbb3902cc5b670a429d56ff47",
    "openexr-3.5.3-cp311-cp311-win_amd64.whl":
        "6dd26f84df0cbd1468937bbbff8f06e598dcdc19f011139b775dab37898b9deb",
    "numba-0.68.1-cp311-cp311-macosx_12_0_arm64.whl":
        "fb83f1043e53753503d303036065990ff48fe0ef901e897153f57b2aec12c38d",
    "llvmlite-0.50.0-cp311-cp311-macosx_12_0_arm64.whl":
        "818b3d4845ac8e126e23cb500867570d0602a42a43e67b14acec31f046e03130",
    "openexr-3.5.3-cp311-cp311-macosx_11_0_arm64.whl":
        "1d50c03e12baa9a469f71e33aab890c5cc897a0d4abe3eae90b32b8555ce4cd2",
}


def _norm(name):
    """PEP 503 normalised project name (``OpenEXR`` -> ``openexr``)."""
    return re.sub(r"[-_.]+", "-", name).lower()


def wheel_info(filename):
    """``(project, version, blender_platforms)`` of a wheel file name. Platforms use Blender's
    names (``linux-x64``, ``windows-x64``, ``macos-arm64``, ``macos-x64``); a compressed tag set
    (``manylinux_2_27_x86_64.manylinux_2_28_x86_64``) counts once per platform."""
    parts = Path(filename).name[:-len(".whl")].split("-") if filename.endswith(".whl") else []
    if not 5 <= len(parts) <= 6:
        raise ValueError(f"not a wheel file name: {filename!r}")
    platforms = set()
    for tag in parts[-1].split("."):
        if tag == "any":
            platforms.update(WHEEL_PLATFORMS)
        elif tag.startswith(("manylinux", "musllinux", "linux")):
            arch = "x64" if tag.endswith("x86_64") else "arm64" if tag.endswith("aarch64") else None
            platforms.add(f"linux-{arch}" if arch else tag)
        elif tag == "win_amd64":
            platforms.add("windows-x64")
        elif tag == "win_arm64":
            platforms.add("windows-arm64")
        elif tag.startswith("macosx_"):
            arch = tag.rsplit("_", 1)[1]
            platforms.update({"arm64": ["macos-arm64"], "x86_64": ["macos-x64"],
                              "universal2": ["macos-arm64", "macos-x64"]}.get(arch, [tag]))
        else:
            platforms.add(tag)
    return _norm(parts[0]), parts[1], sorted(platforms)


def wheels_by_platform(wheel_files, platforms=tuple(WHEEL_PLATFORMS), pins=WHEEL_PINS):
    """``{platform: [file names]}`` of ``wheel_files``; raises ``RuntimeError`` naming the
    problem unless each platform has exactly one wheel of each pinned project at its version."""
    wanted = {_norm(k): v for k, v in pins.items()}
    table = {p: {} for p in platforms}
    for f in wheel_files:
        name = Path(f).name
        project, version, plats = wheel_info(name)
        if project not in wanted:
            raise RuntimeError(f"unexpected wheel {name}: {project} is not pinned in WHEEL_PINS")
        if version != wanted[project]:
            raise RuntimeError(f"wheel {name} has {project} {version}, pinned {wanted[project]}")
        hit = [p for p in plats if p in table]
        if not hit:
            raise RuntimeError(f"wheel {name} is for none of the platforms {list(platforms)}")
        for p in hit:
            if project in table[p]:
                raise RuntimeError(f"two {project} wheels for {p}: {table[p][project]} and {name}")
            table[p][project] = name
    for p, got in table.items():
        missing = sorted(set(wanted) - set(got))
        if missing:
            raise RuntimeError(f"no wheel of {', '.join(missing)} for {p}")
    return {p: sorted(got.values()) for p, got in table.items()}


def manifest_with_wheels(manifest_text, wheel_files, platforms=tuple(WHEEL_PLATFORMS)):
    """The manifest text with top-level ``platforms`` and ``wheels`` (``./wheels/<file>``) for
    ``wheel_files`` inserted before its first table. The manifest must not declare them already."""
    import tomllib
    current = tomllib.loads(manifest_text)
    for key in ("platforms", "wheels"):
        if key in current:
            raise RuntimeError(f"blender_manifest.toml already declares {key!r}; the build writes it")
    per = wheels_by_platform(wheel_files, platforms)
    files = sorted({f for fs in per.values() for f in fs})
    block = "platforms = [" + ", ".join(f'"{p}"' for p in platforms) + "]\n"
    block += "wheels = [\n" + "".join(f'  "./wheels/{f}",\n' for f in files) + "]\n"
    lines = manifest_text.splitlines(keepends=True)
    at = next((i for i, ln in enumerate(lines) if ln.lstrip().startswith("[")), len(lines))
    head = "".join(lines[:at])
    if head and not head.endswith("\n"):
        head += "\n"
    text = head + "\n# Generated by tools/build_extension.py --wheels\n" + block + "\n" + "".join(lines[at:])
    tomllib.loads(text)  # must stay valid TOML
    return text


def _sha256(path):
    h = hashlib.sha256()
    with open(path, "rb") as fh:
        for chunk in iter(lambda: fh.read(1 << 20), b""):
            h.update(chunk)
    return h.hexdigest()


def fetch_wheels(wheel_dir=WHEEL_DIR, python=sys.executable, quiet=False):
    """Make ``wheel_dir`` hold every wheel of ``WHEEL_SHA256`` with the right hash: files already
    there are checked (a mismatch is deleted and fetched again), missing ones are fetched per
    platform with ``pip download --only-binary=:all: --no-deps --require-hashes``. Returns the
    paths of the pinned wheels."""
    wheel_dir = Path(wheel_dir)
    wheel_dir.mkdir(parents=True, exist_ok=True)
    for plat, tag in WHEEL_PLATFORMS.items():
        expected = [f for f in WHEEL_SHA256 if plat in wheel_info(f)[2]]
        todo = []
        for f in expected:
            path = wheel_dir / f
            if path.is_file() and _sha256(path) == WHEEL_SHA256[f]:
                continue
            if path.exists():
                print(f"build_extension: {f} has a wrong sha256, fetching it again", file=sys.stderr)
                path.unlink()
            todo.append(f)
        if not todo:
            if not quiet:
                print(f"wheels for {plat}: cached")
            continue
        projects = {wheel_info(f)[0] for f in todo}
        with tempfile.TemporaryDirectory(prefix="spectral-gi-wheels-") as tmp:
            req = Path(tmp) / "requirements.txt"
            req.write_text("".join(
                f"{name}=={ver} " + " ".join(f"--hash=sha256:{WHEEL_SHA256[f]}" for f in expected
                                             if wheel_info(f)[0] == _norm(name)) + "\n"
                for name, ver in WHEEL_PINS.items() if _norm(name) in projects))
            cmd = [python, "-m", "pip", "download", "--only-binary=:all:", "--no-deps",
                   "--require-hashes", "--platform", tag, "--python-version", WHEEL_PYTHON,
                   "--implementation", "cp", "--dest", str(Path(tmp) / "out"), "-r", str(req)]
            proc = subprocess.run(cmd, capture_output=True, text=True)
            if proc.returncode != 0:
                raise RuntimeError(f"pip download for {plat} failed ({proc.returncode}):\n{proc.stdout}\n{proc.stderr}")
            for f in todo:
                got = Path(tmp) / "out" / f
                if not got.is_file():
                    have = sorted(p.name for p in (Path(tmp) / "out").glob("*.whl"))
                    raise RuntimeError(f"pip did not fetch {f} for {plat} (got {have})")
                if _sha256(got) != WHEEL_SHA256[f]:
                    raise RuntimeError(f"{f}: sha256 differs from WHEEL_SHA256")
                shutil.move(str(got), wheel_dir / f)
        if not quiet:
            print(f"wheels for {plat}: fetched {', '.join(todo)}")
    return [wheel_dir / f for f in WHEEL_SHA256]


def blender_ext_script():
    """Path of ``blender_ext.py`` inside the installed bpy package (bpy is not imported)."""
    spec = importlib.util.find_spec("bpy")
    if spec is None or not spec.submodule_search_locations:
        raise RuntimeError("the bpy package is not installed: cannot find Blender's extension build tool")
    for root in spec.submodule_search_locations:
        hits = sorted(Path(root).glob("*/scripts/addons_core/bl_pkg/cli/blender_ext.py"))
        if hits:
            return hits[-1]
    raise RuntimeError("blender_ext.py not found inside the bpy package")


def source_files(repo=REPO, tracked_only=False):
    """Repository files to ship, relative paths: tracked files plus, unless ``tracked_only``,
    untracked files that .gitignore does not exclude (so a build matches the work tree)."""
    cmd = ["git", "ls-files", "--cached", "-z"] + ([] if tracked_only else ["--others", "--exclude-standard"])
    out = subprocess.run(cmd, cwd=repo, check=True, capture_output=True).stdout
    files = []
    for raw in out.split(b"\0"):
        if not raw:
            continue
        rel = Path(raw.decode("utf-8"))
        if rel.parts[0] in EXCLUDED_TOP or rel.parts[0].startswith("."):
            continue
        if rel.suffix in EXCLUDED_SUFFIXES or "__pycache__" in rel.parts:
            continue
        if not (repo / rel).is_file():  # deleted in the work tree
            continue
        files.append(rel)
    return sorted(set(files))


def stage(dest, repo=REPO, tracked_only=False):
    """Copy the files to ship into ``dest`` (created); returns the number of files."""
    files = source_files(repo, tracked_only)
    if Path("blender_manifest.toml") not in files:
        raise RuntimeError("blender_manifest.toml is not among the repository's files")
    for rel in files:
        target = Path(dest) / rel
        target.parent.mkdir(parents=True, exist_ok=True)
        shutil.copy2(repo / rel, target)
    return len(files)


def build(output_dir=None, repo=REPO, python=sys.executable, quiet=False, tracked_only=False,
          wheels=False, wheel_dir=None):
    """Build the extension into ``output_dir`` (default: ``<repo>/dist``). Without ``wheels``:
    one development zip, returns its path. With ``wheels``: one zip per platform of
    ``WHEEL_PLATFORMS`` bundling the pinned wheels, returns ``{platform: path}``."""
    output_dir = Path(output_dir) if output_dir is not None else repo / "dist"
    output_dir.mkdir(parents=True, exist_ok=True)
    script = blender_ext_script()
    wheel_paths = fetch_wheels(wheel_dir or repo / "wheels", python, quiet) if wheels else []
    with tempfile.TemporaryDirectory(prefix="spectral-gi-stage-") as tmp:
        src = Path(tmp) / EXTENSION_ID
        src.mkdir()
        n = stage(src, repo, tracked_only)
        cmd = [python, str(script), "build", "--source-dir", str(src), "--output-dir", str(output_dir)]
        if wheels:
            (src / "wheels").mkdir(exist_ok=True)
            for w in wheel_paths:
                shutil.copy2(w, src / "wheels" / w.name)
            manifest = src / "blender_manifest.toml"
            manifest.write_text(manifest_with_wheels(manifest.read_text(encoding="utf-8"),
                                                     [w.name for w in wheel_paths]), encoding="utf-8")
            cmd.append("--split-platforms")
        before = {p: p.stat().st_mtime_ns for p in output_dir.glob("*.zip")}
        proc = subprocess.run(cmd, capture_output=True, text=True)
        if proc.returncode != 0:
            raise RuntimeError(f"blender_ext.py build failed ({proc.returncode}):\n{proc.stdout}\n{proc.stderr}")
        if not quiet:
            print(proc.stdout.strip())
    made = [p for p in output_dir.glob("*.zip") if before.get(p) != p.stat().st_mtime_ns]
    if wheels:
        out = {}
        for plat in WHEEL_PLATFORMS:
            suffix = "-" + plat.replace("-", "_") + ".zip"
            hits = [p for p in made if p.name.startswith(EXTENSION_ID + "-") and p.name.endswith(suffix)]
            if len(hits) != 1:
                raise RuntimeError(f"expected one *{suffix} from the build in {output_dir}, found {hits}")
            out[plat] = hits[0]
        if not quiet:
            print(f"staged {n} files + {len(wheel_paths)} wheels; release zips (pinned wheels bundled, "
                  "install without network):")
            for plat, z in out.items():
                print(f"  {plat:12s} {z.stat().st_size / 1e6:7.1f} MB  {z}")
        return out
    zips = sorted(made) or sorted(output_dir.glob(f"{EXTENSION_ID}-*.zip"))
    if not zips:
        raise RuntimeError(f"the build reported success but no zip is in {output_dir}")
    zip_path = max(zips, key=lambda p: p.stat().st_mtime)
    if not quiet:
        print(f"staged {n} files; built {zip_path}")
        print("development zip: no wheels bundled, numba, llvmlite and OpenEXR must already be "
              "importable in Blender's Python (use --wheels for the release zips)")
    return zip_path


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--output-dir", default=None, help="where to write the zip (default: <repo>/dist)")
    ap.add_argument("--tracked-only", action="store_true",
                    help="ship only files git tracks (default: also untracked files not ignored)")
    ap.add_argument("--wheels", action="store_true",
                    help="release build: fetch the pinned wheels into <repo>/wheels (cached) and build "
                         "one zip per platform that bundles them")
    args = ap.parse_args(argv)
    try:
        build(args.output_dir, tracked_only=args.tracked_only, wheels=args.wheels)
    except (RuntimeError, ValueError, subprocess.CalledProcessError) as exc:
        print(f"build_extension: {exc}", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
