"""Atomic file writes: a file is either the old one or the complete new one.

:func:`atomic_path` replaces one file; :func:`atomic_paths` replaces several (a scene's
JSON and its arrays, a render's EXR and its PNG preview) together: each is first written
in full to a temporary file beside its target, then all are renamed into place; if a
rename fails, the targets already replaced are given their old content back. Temporary
files have unpredictable names (``tempfile.mkstemp``) and are removed on every exit path
that runs Python code (an exception, ``KeyboardInterrupt``, ``SystemExit``). A process
killed outright (SIGKILL, a power cut) cannot remove its own: each temporary name carries
the writer's host and process id, and the next write of the same target on that host
removes the ones whose process is gone (those of other hosts, which may share the folder,
and of running processes are left alone).
"""
import contextlib
import os
import re
import socket
import tempfile
from pathlib import Path

_HOST = re.sub(r"[^A-Za-z0-9-]", "-", socket.gethostname())[:64] or "host"


def _process_gone(pid):
    if pid <= 0:
        return False
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return True
    except OSError:  # it exists (another user's) or cannot be asked about: keep its file
        return False
    return False


def _sweep_stale(path):
    """Remove the temporary files of ``path`` left by killed writers on this host."""
    head = "." + path.name + "." + _HOST + "."
    with contextlib.suppress(OSError):
        for entry in os.scandir(path.parent):
            name = entry.name
            if not name.startswith(head):
                continue
            pid = name[len(head):].split("-", 1)[0]
            if pid.isdigit() and int(pid) != os.getpid() and _process_gone(int(pid)):
                _remove(entry.path)


def _temp_beside(path, tag="tmp"):
    path.parent.mkdir(parents=True, exist_ok=True)
    _sweep_stale(path)
    prefix = f".{path.name}.{_HOST}.{os.getpid()}-"
    fd, tmp = tempfile.mkstemp(prefix=prefix, suffix=f".{tag}" + path.suffix, dir=path.parent)
    os.close(fd)
    umask = os.umask(0)
    os.umask(umask)
    os.chmod(tmp, 0o666 & ~umask)  # mkstemp creates 0600; give the file the usual permissions
    return Path(tmp)


def _remove(p):
    with contextlib.suppress(OSError):
        os.unlink(p)


@contextlib.contextmanager
def atomic_path(path):
    """Yield a temporary path in the target's folder; on success move it over ``path``.

    On any exception the temporary file is removed and ``path`` is left untouched.
    """
    path = Path(path)
    tmp = _temp_beside(path)
    try:
        yield tmp
        os.replace(tmp, path)
    except BaseException:
        _remove(tmp)
        raise


@contextlib.contextmanager
def atomic_paths(paths):
    """Yield one temporary path per target of ``paths``; on success rename them all into place.

    All targets are replaced, or (on any exception, in the body or in a rename) none is:
    a target that was already replaced gets its previous content back (kept meanwhile as a
    hard link, or a copy where the file system has no links), a target that did not exist
    is removed again.
    """
    paths = [Path(p) for p in paths]
    if len({p.resolve() for p in paths}) != len(paths):
        raise ValueError(f"atomic_paths: the targets {[str(p) for p in paths]} are not distinct")
    tmps = []
    backups = []  # (target, backup path or None when the target did not exist)
    try:
        for p in paths:
            tmps.append(_temp_beside(p))
        yield list(tmps)
        for p in paths:  # keep the previous files until every new one is in place
            if p.exists():
                b = _temp_beside(p, "old")
                _remove(b)
                try:
                    os.link(p, b)
                except OSError:
                    import shutil

                    shutil.copy2(p, b)
                backups.append((p, b))
            else:
                backups.append((p, None))
        done = []
        try:
            for t, p in zip(tmps, paths):
                os.replace(t, p)
                done.append(p)
        except BaseException:
            for p, b in backups:
                if p in done:
                    if b is None:
                        _remove(p)
                    else:
                        with contextlib.suppress(OSError):
                            os.replace(b, p)
            raise
    finally:
        for t in tmps:
            _remove(t)
        for _, b in backups:
            if b is not None:
                _remove(b)


def fsync_write(f, data):
    f.write(data)
    f.flush()
    os.fsync(f.fileno())


def write_bytes(path, data):
    with atomic_path(path) as tmp:
        with open(tmp, "wb") as f:
            fsync_write(f, data)


def write_text(path, text):
    write_bytes(path, text.encode("utf-8"))
