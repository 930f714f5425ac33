"""Benchmark results as JSON: one file per benchmark, written at the end of its run.

Every script in ``benchmarks/`` ends with::

    results.write("qmc_bench", tables=[results.table("title", columns, rows)], conditions={...})

which writes ``benchmarks/results/qmc_bench.json`` atomically (a temporary file in the
same folder, then ``os.replace``), holding the figures and where they come from:

* ``date``: UTC, ISO 8601; ``commit``: ``git rev-parse HEAD`` of this checkout, and
  ``dirty`` when the work tree has uncommitted changes;
* ``machine``: CPU model, logical cores and a summary of the vector flags (SSE4.2,
  AVX, AVX2, FMA, AVX-512F), the figures most renderers' speed depends on;
* ``load``: ``os.getloadavg()`` when this module was imported (the start of the
  script) and when the results were written, since other jobs on a shared machine
  change every timing;
* ``conditions``: the arguments the figures depend on (sizes, samples, threads);
* ``tables``: a list of ``{"title", "columns", "rows"}``, what the page shows;
* ``source``: ``"measured"`` for a run of the script, or a sentence saying where
  recorded figures come from.

``python benchmarks/make_page.py`` turns the latest file of each benchmark into
``docs/benchmarks.md``.
"""
import datetime
import json
import os
import platform
import subprocess
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
RESULTS_DIR = os.path.join(HERE, "results")
_LOAD_BEFORE = os.getloadavg() if hasattr(os, "getloadavg") else None

FLAGS = ("sse4_2", "avx", "avx2", "fma", "avx512f")


def table(title, columns, rows):
    """A table of figures: ``columns`` names, ``rows`` lists of cells (numbers or strings)."""
    return {"title": title, "columns": list(columns), "rows": [list(r) for r in rows]}


def git_commit(path=HERE):
    """(commit, dirty) of the checkout holding ``path``; (None, None) outside git."""
    try:
        sha = subprocess.run(["git", "-C", path, "rev-parse", "HEAD"], capture_output=True, text=True,
                             check=True).stdout.strip()
        status = subprocess.run(["git", "-C", path, "status", "--porcelain", "--untracked-files=no"],
                                capture_output=True, text=True, check=True).stdout
        return sha, bool(status.strip())
    except (OSError, subprocess.CalledProcessError):
        return None, None


def machine():
    """CPU model, logical cores and vector flags of this machine."""
    model, flags = platform.processor() or platform.machine(), set()
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                key, _, value = line.partition(":")
                key = key.strip()
                if key == "model name":
                    model = value.strip()
                elif key == "flags":
                    flags = set(value.split())
                if model and flags and key == "":
                    break
    except OSError:
        pass
    present = [f for f in FLAGS if f in flags]
    return {"cpu": model, "cores": os.cpu_count(), "flags": present, "system": platform.system(),
            "python": platform.python_version()}


def _rounded(load):
    return [round(float(v), 2) for v in load] if load else None


def build(name, tables, conditions=None, source="measured", load_after=None):
    """The result record (a dict) without writing it."""
    commit, dirty = git_commit()
    after = load_after if load_after is not None else (os.getloadavg() if hasattr(os, "getloadavg") else None)
    return {
        "name": name,
        "date": datetime.datetime.now(datetime.timezone.utc).replace(microsecond=0).isoformat(),
        "commit": commit,
        "dirty": dirty,
        "machine": machine(),
        "load": {"before": _rounded(_LOAD_BEFORE), "after": _rounded(after)},
        "conditions": dict(conditions or {}),
        "tables": list(tables),
        "source": source,
    }


def save(record, directory=RESULTS_DIR):
    """Write ``record`` to ``<directory>/<name>.json`` atomically; returns the path."""
    os.makedirs(directory, exist_ok=True)
    path = os.path.join(directory, record["name"] + ".json")
    fd, tmp = tempfile.mkstemp(prefix="." + record["name"] + ".", suffix=".tmp", dir=directory)
    try:
        with os.fdopen(fd, "w", encoding="utf-8") as f:
            json.dump(record, f, indent=1, ensure_ascii=False)
            f.write("\n")
        os.chmod(tmp, 0o644)  # mkstemp makes the file private; results are for reading
        os.replace(tmp, path)
    except BaseException:
        if os.path.exists(tmp):
            os.unlink(tmp)
        raise
    return path


def write(name, tables, conditions=None, directory=RESULTS_DIR):
    """Measure the machine and load now, write the results of benchmark ``name``; returns the path."""
    path = save(build(name, tables, conditions), directory)
    print(f"results: {os.path.relpath(path)}")
    return path


def load_all(directory=RESULTS_DIR):
    """Every result file in ``directory``, sorted by benchmark name."""
    out = []
    if not os.path.isdir(directory):
        return out
    for fn in sorted(os.listdir(directory)):
        if fn.endswith(".json") and not fn.startswith("."):
            with open(os.path.join(directory, fn), encoding="utf-8") as f:
                out.append(json.load(f))
    return sorted(out, key=lambda r: r["name"])
