"""The documentation: the Sphinx site builds without a warning, the README stays short,
README and docs describe the product (no work diary), and the generated or quoted parts
(benchmarks page, command-line synopsis, API page, architecture table) match the code."""
import argparse
import importlib
import importlib.util
import re
import subprocess
import sys
import tomllib
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
DOCS = ROOT / "docs"
README = ROOT / "README.md"
PAGES = sorted(DOCS.rglob("*.md"))


def _prose_files():
    return [README, *PAGES]


@pytest.mark.slow
def test_sphinx_build_has_no_warnings(tmp_path):
    """`python -m sphinx -W --keep-going -b html docs OUT` succeeds and prints no warning."""
    import myst_parser  # noqa: F401  (a test dependency: pip install -e ".[test]")
    import sphinx  # noqa: F401

    r = subprocess.run([sys.executable, "-m", "sphinx", "-W", "--keep-going", "-b", "html", str(DOCS),
                        str(tmp_path / "html")], capture_output=True, text=True, timeout=900, cwd=ROOT)
    out = r.stdout + r.stderr
    problems = [line for line in out.splitlines() if "WARNING" in line or "ERROR" in line]
    assert r.returncode == 0 and not problems, out[-6000:]
    assert (tmp_path / "html" / "index.html").exists()


def test_readme_is_at_most_200_lines():
    n = len(README.read_text(encoding="utf-8").splitlines())
    assert n <= 200, f"README.md has {n} lines; move the details to docs/"


# A work diary in the product's text: session labels, issue numbers, commit hashes in prose.
DIARY = [
    (re.compile(r"\bsession\s*\d", re.I), "a session label"),
    (re.compile(r"\bissue\s*#?\d", re.I), "an issue reference"),
    (re.compile(r"(?<![\w&/])#\d+\b"), "an issue number"),
    (re.compile(r"\bfacts\.md\b"), "a citation of a design note outside the repository"),
]
HASH = re.compile(r"(?<![\w.-])(?=[0-9a-f]*[a-f])(?=[0-9a-f]*\d)[0-9a-f]{7,40}(?![\w-])")


def _diary_lines(path, root=ROOT):
    found = []
    for no, line in enumerate(path.read_text(encoding="utf-8").splitlines(), 1):
        for pattern, what in DIARY:
            if pattern.search(line):
                found.append(f"{path.relative_to(root)}:{no}: {what}: {line.strip()}")
        for m in HASH.finditer(line):
            # a commit is named only as provenance of a measurement ("commit `abc1234`")
            if not re.search(r"commit:?\s*`?$", line[:m.start()], re.I):
                found.append(f"{path.relative_to(root)}:{no}: a commit hash in prose: {line.strip()}")
    return found


def test_readme_and_docs_hold_no_work_diary():
    found = [f for p in _prose_files() for f in _diary_lines(p)]
    assert not found, "\n".join(found)


def test_the_diary_check_catches_each_pattern(tmp_path):
    page = tmp_path / "page.md"
    label = "Sess" + "ion 8"  # spelled in two parts so that this file is not itself a diary line
    page.write_text(f"In {label} we fixed issue #5 (see #12); the change a1b2c3d did it.\n"
                    "Measured at commit `0e27b52`; see facts.md.\n", encoding="utf-8")
    found = _diary_lines(page, tmp_path)
    kinds = " ".join(found)
    for what in ("a session label", "an issue reference", "an issue number", "a commit hash in prose",
                 "outside the repository"):
        assert what in kinds, (what, found)
    assert not any("0e27b52" in f and "hash" in f for f in found)


def _load_make_page():
    spec = importlib.util.spec_from_file_location("make_page", ROOT / "benchmarks" / "make_page.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_benchmarks_page_is_generated_from_the_latest_results():
    """docs/benchmarks.md is exactly what `python benchmarks/make_page.py` writes."""
    page = _load_make_page()
    expected = page.render_page()
    actual = (DOCS / "benchmarks.md").read_text(encoding="utf-8")
    assert actual == expected, "docs/benchmarks.md is out of date: run python benchmarks/make_page.py"


def test_every_benchmark_result_names_its_provenance():
    page = _load_make_page()
    records = page.results.load_all()
    assert records
    for r in records:
        assert r["date"] and r["commit"] and r["machine"] and r["tables"], r["name"]
        assert r["source"] == "measured" or "recorded" in r["source"], r["name"]


def _cli_parser():
    """The parser of the `spectral-gi` console script named in pyproject.toml."""
    with open(ROOT / "pyproject.toml", "rb") as f:
        target = tomllib.load(f)["project"]["scripts"]["spectral-gi"]
    module = importlib.import_module(target.split(":")[0])
    return module._parser()


def test_command_line_page_quotes_every_help_of_the_parser(monkeypatch):
    """docs/user/cli.md holds the output of `spectral-gi --help` and of each subcommand's."""
    monkeypatch.setenv("COLUMNS", "80")
    parser = _cli_parser()
    page = (DOCS / "user" / "cli.md").read_text(encoding="utf-8")
    helps = {"spectral-gi": parser.format_help()}
    sub = next(a for a in parser._actions if isinstance(a, argparse._SubParsersAction))
    for name, p in sub.choices.items():
        helps[name] = p.format_help()
    missing = [name for name, text in helps.items() if text.rstrip() not in page]
    assert not missing, f"docs/user/cli.md does not quote the current --help of: {missing}"


def test_api_page_documents_every_public_name():
    from spectral_gi import core

    page = (DOCS / "reference" / "api.md").read_text(encoding="utf-8")
    missing = [n for n in core.__all__ if not re.search(rf"spectral_gi\.core\.{re.escape(n)}\b", page)]
    assert not missing, missing


def test_architecture_table_places_every_compendium_item():
    text = (DOCS / "design" / "architecture.md").read_text(encoding="utf-8")
    rows = [line for line in text.splitlines() if line.startswith("| ")]
    items = set()
    for row in rows:
        cells = row.split("|")
        if len(cells) < 5:
            continue
        for m in re.finditer(r"(?<![\w.])(\d{1,2})(?:[–-](\d{1,2}))?(?![\w.%])", cells[3]):
            a, b = int(m.group(1)), int(m.group(2) or m.group(1))
            items.update(range(a, b + 1))
    assert set(range(1, 69)) <= items, sorted(set(range(1, 69)) - items)


def test_docs_name_only_paths_that_exist():
    """Every repository path quoted in README and docs (`core/...`, `tests/...`, ...) exists."""
    prefixes = ("core/", "addon/", "tests/", "benchmarks/", "presets/", "tools/", "docs/")
    planned = set()  # paths named as the home of items not implemented yet
    missing = []
    for path in _prose_files():
        for m in re.finditer(r"`([\w./-]+)`|\]\(([\w./-]+)\)", path.read_text(encoding="utf-8")):
            ref = m.group(1) or m.group(2)
            if (not ref.startswith(prefixes + ("cli.py",)) or "<" in ref or "*" in ref or "_build" in ref
                    or ref in planned):
                continue
            target = ROOT / ref if m.group(1) else (path.parent / ref)
            if not target.exists() and not (ROOT / ref).exists():
                missing.append(f"{path.relative_to(ROOT)}: {ref}")
    assert not missing, "\n".join(missing)
