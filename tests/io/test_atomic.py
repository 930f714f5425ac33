"""Atomic writes (core/io/atomic.py) and the scene's JSON + .npz pair written as one unit."""
import json
import os

import numpy as np
import pytest
from helpers import furnace_scene

from spectral_gi.core import scene as S
from spectral_gi.core.io import atomic


def _files(folder):
    return sorted(p.name for p in folder.iterdir())


def test_atomic_paths_replaces_both_files(tmp_path):
    a, b = tmp_path / "x.exr", tmp_path / "x.png"
    a.write_bytes(b"old a")
    with atomic.atomic_paths([a, b]) as (ta, tb):
        assert ta.parent == tmp_path and tb.parent == tmp_path and ta.name != tb.name
        ta.write_bytes(b"new a")
        tb.write_bytes(b"new b")
    assert a.read_bytes() == b"new a" and b.read_bytes() == b"new b"
    assert _files(tmp_path) == ["x.exr", "x.png"]


@pytest.mark.parametrize("error", [OSError(28, "No space left on device"), KeyboardInterrupt()])
def test_a_failure_while_writing_replaces_neither_and_leaves_no_temporary_file(tmp_path, error):
    a, b = tmp_path / "x.exr", tmp_path / "x.png"
    a.write_bytes(b"old a")
    b.write_bytes(b"old b")
    with pytest.raises(type(error)):
        with atomic.atomic_paths([a, b]) as (ta, tb):
            ta.write_bytes(b"new a")
            raise error
    assert (a.read_bytes(), b.read_bytes()) == (b"old a", b"old b")
    assert _files(tmp_path) == ["x.exr", "x.png"]


def test_a_failed_second_rename_gives_the_first_file_its_old_content_back(tmp_path, monkeypatch):
    a, b, c = tmp_path / "x.exr", tmp_path / "x.png", tmp_path / "x.txt"
    a.write_bytes(b"old a")
    b.write_bytes(b"old b")
    real = os.replace
    calls = []

    def failing_second(src, dst):
        calls.append(dst)
        if len(calls) == 2:
            raise OSError(5, "Input/output error")
        return real(src, dst)

    monkeypatch.setattr(atomic.os, "replace", failing_second)
    with pytest.raises(OSError, match="Input/output"):
        with atomic.atomic_paths([a, b, c]) as tmps:
            for t, data in zip(tmps, (b"new a", b"new b", b"new c")):
                t.write_bytes(data)
    monkeypatch.setattr(atomic.os, "replace", real)
    assert (a.read_bytes(), b.read_bytes()) == (b"old a", b"old b")
    assert not c.exists()
    assert _files(tmp_path) == ["x.exr", "x.png"]


def test_temporary_names_are_unpredictable(tmp_path):
    names = set()
    for _ in range(20):
        with atomic.atomic_path(tmp_path / "f.bin") as t:
            names.add(t.name)
            t.write_bytes(b"x")
    assert len(names) == 20


def test_temporary_files_of_killed_writers_are_removed_by_the_next_write(tmp_path):
    """A writer killed outright (SIGKILL) leaves its temporary file; the next write of the same
    target on this host removes it, and leaves those of running processes and other hosts."""
    import signal
    import subprocess
    import sys

    target = tmp_path / "render.exr"
    code = ("import os, sys; from spectral_gi.core.io import atomic; "
            "cm = atomic.atomic_path(sys.argv[1]); tmp = cm.__enter__(); open(tmp, 'wb').write(b'half'); "
            "print(tmp, flush=True); os.kill(os.getpid(), 9)")
    killed = subprocess.run([sys.executable, "-c", code, str(target)], capture_output=True, text=True)
    assert killed.returncode == -signal.SIGKILL
    stale = tmp_path / killed.stdout.strip().rsplit("/", 1)[-1]
    assert stale.is_file() and not target.exists()
    live = subprocess.Popen([sys.executable, "-c", "import time; time.sleep(60)"])
    try:
        running = tmp_path / f".render.exr.{atomic._HOST}.{live.pid}-abc.tmp.exr"
        other_host = tmp_path / ".render.exr.elsewhere.1-abc.tmp.exr"
        other_target = tmp_path / f".other.exr.{atomic._HOST}.{2 ** 22 + 1}-abc.tmp.exr"
        for p in (running, other_host, other_target):
            p.write_bytes(b"x")
        atomic.write_bytes(target, b"whole")
        assert target.read_bytes() == b"whole"
        assert not stale.exists() and running.exists() and other_host.exists() and other_target.exists()
    finally:
        live.kill()
        live.wait()


def test_a_scene_save_that_fails_after_the_arrays_keeps_the_old_pair(tmp_path, monkeypatch):
    path = S.save(furnace_scene(), tmp_path / "s.json")
    before = path.read_bytes(), path.with_suffix(".npz").read_bytes()
    real = atomic.fsync_write
    calls = []

    def fail_on_json(f, data):
        calls.append(f.name)
        if len(calls) == 2:  # the .npz is written, the JSON fails (a full disk)
            raise OSError(28, "No space left on device")
        return real(f, data)

    monkeypatch.setattr(S, "fsync_write", fail_on_json)
    other = furnace_scene(rho=0.3)
    with pytest.raises(OSError, match="No space"):
        S.save(other, path)
    assert (path.read_bytes(), path.with_suffix(".npz").read_bytes()) == before
    assert _files(tmp_path) == ["s.json", "s.npz"]
    S.load(path)


def test_a_mixed_pair_of_scene_files_is_detected(tmp_path):
    a = S.save(furnace_scene(rho=0.5), tmp_path / "a" / "s.json")
    b = S.save(furnace_scene(rho=0.3), tmp_path / "b" / "s.json")
    b.with_suffix(".npz").write_bytes(a.with_suffix(".npz").read_bytes())  # the JSON of b, the arrays of a
    with pytest.raises(S.SceneError, match="arrays: s.npz is not the array file s.json was saved with"):
        S.load(b)


@pytest.mark.parametrize("name", ["../s.npz", "/etc/passwd", "sub/s.npz", "..", "s.json", "", "s.npz\x00.txt"])
def test_the_array_file_must_lie_beside_the_scene(tmp_path, name):
    path = S.save(furnace_scene(), tmp_path / "s.json")
    doc = json.loads(path.read_text())
    doc["arrays"] = name
    path.write_text(json.dumps(doc))
    with pytest.raises(S.SceneError, match="arrays: .*not a .npz file name in the scene's folder"):
        S.load(path)


def test_arrays_are_read_only_when_referenced_and_within_their_declared_size(tmp_path):
    from spectral_gi.core.io.npz import NpzError, NpzReader

    path = tmp_path / "a.npz"
    np.savez_compressed(path, small=np.zeros(4), big=np.zeros((1000, 1000)))
    with NpzReader(path, max_array_bytes=1 << 16) as z:
        assert z.get("small").shape == (4,)  # the large member is never read
        with pytest.raises(NpzError, match="'big'.*declares 8000000 bytes"):
            z.get("big")
    with NpzReader(path, max_total_bytes=8 * 4 + 10) as z:
        z.get("small")
        with pytest.raises(NpzError, match="exceed the limit"):
            z.get("small")
