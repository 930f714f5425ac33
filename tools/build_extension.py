#!/usr/bin/env python3
"""Build the Blender extension zip of spectral-gi.

Stages a clean copy of the repository (the files git tracks or would track, i.e.
``git ls-files --cached --others --exclude-standard``, or only tracked files with
``--tracked-only``; without tests, benchmarks, CI, tools and docs) and runs Blender's own extension build tool on it — the
standard-library script shipped inside the ``bpy`` wheel
(``bpy/<version>/scripts/addons_core/bl_pkg/cli/blender_ext.py``).

    python tools/build_extension.py [--output-dir DIR]

Prints the path of the zip. The zip does not bundle wheels yet: numba, llvmlite and
OpenEXR must already be importable in Blender's Python.
"""
from __future__ import annotations

import argparse
import importlib.util
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

REPO = Path(__file__).resolve().parent.parent
EXCLUDED_TOP = ("tests", "benchmarks", ".ci", "tools", "docs", "dist", "build")
EXCLUDED_SUFFIXES = (".pyc", ".nbi", ".nbc", ".zip")
EXTENSION_ID = "spectral_gi"


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


def build(output_dir=None, repo=REPO, python=sys.executable, quiet=False, tracked_only=False):
    """Build the extension zip into ``output_dir`` (default: ``<repo>/dist``); returns its path."""
    output_dir = Path(output_dir) if output_dir is not None else repo / "dist"
    output_dir.mkdir(parents=True, exist_ok=True)
    script = blender_ext_script()
    with tempfile.TemporaryDirectory(prefix="spectral-gi-stage-") as tmp:
        src = Path(tmp) / EXTENSION_ID
        src.mkdir()
        n = stage(src, repo, tracked_only)
        before = set(output_dir.glob("*.zip"))
        proc = subprocess.run([python, str(script), "build", "--source-dir", str(src),
                               "--output-dir", str(output_dir)], capture_output=True, text=True)
        if proc.returncode != 0:
            raise RuntimeError(f"blender_ext.py build failed ({proc.returncode}):\n{proc.stdout}\n{proc.stderr}")
        if not quiet:
            print(proc.stdout.strip())
    zips = sorted(set(output_dir.glob("*.zip")) - before) or sorted(output_dir.glob(f"{EXTENSION_ID}-*.zip"))
    if not zips:
        raise RuntimeError(f"the build reported success but no zip is in {output_dir}")
    zip_path = max(zips, key=lambda p: p.stat().st_mtime)
    if not quiet:
        print(f"staged {n} files; built {zip_path}")
    return zip_path


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--output-dir", default=None, help="where to write the zip (default: <repo>/dist)")
    ap.add_argument("--tracked-only", action="store_true",
                    help="ship only files git tracks (default: also untracked files not ignored)")
    args = ap.parse_args(argv)
    try:
        build(args.output_dir, tracked_only=args.tracked_only)
    except (RuntimeError, subprocess.CalledProcessError) as exc:
        print(f"build_extension: {exc}", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
