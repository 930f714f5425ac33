"""The tree passes the project's lint rules (ruff, configured in pyproject.toml)."""
import subprocess
import sys
from pathlib import Path

REPO = Path(__file__).resolve().parents[1]


def test_ruff_finds_nothing():
    out = subprocess.run([sys.executable, "-m", "ruff", "check", "--no-cache", "--output-format", "concise", str(REPO)],
                         capture_output=True, text=True, cwd=REPO, timeout=300)
    assert "No module named ruff" not in out.stderr, "ruff is a test dependency: pip install -e \".[test]\""
    assert out.returncode == 0, out.stdout[-4000:] + out.stderr[-2000:]


def test_ruff_reports_a_violation(tmp_path):
    """The check can fail: an unused import in a file under the same configuration is reported."""
    bad = tmp_path / "bad.py"
    bad.write_text("import os\n")
    out = subprocess.run([sys.executable, "-m", "ruff", "check", "--no-cache", "--config",
                          str(REPO / "pyproject.toml"), str(bad)], capture_output=True, text=True, timeout=300)
    assert out.returncode == 1 and "F401" in out.stdout, out.stdout + out.stderr
