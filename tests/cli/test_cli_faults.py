"""The command line under bad input and faults: one line and exit status 2 for bad input,
never a crash or a traceback, and no fault loses a finished render or an earlier output.

Inputs that used to crash the process (a camera whose frame overflows, a damaged
checkpoint) run in a subprocess; the others through ``cli.main`` in this process.
Signals are sent to a subprocess at each phase: start-up, kernel preparation, rendering;
the write phase and a full disk are injected in this process (a writer that raises, a
writer during which the process signals itself) and with a file-size limit.
"""
import copy
import json
import os
import signal
import subprocess
import sys
import time

import numpy as np
import pytest

from spectral_gi import cli
from spectral_gi.core.io.exr import read_channels

CLI = [sys.executable, "-m", "spectral_gi.cli"]
POSIX = pytest.mark.skipif(sys.platform == "win32", reason="POSIX signals")


def run(args, cwd, **kw):
    return subprocess.run(CLI + args, cwd=cwd, capture_output=True, text=True, timeout=600, **kw)


def one_error_line(stderr):
    lines = [ln for ln in stderr.strip().splitlines() if ln.strip()]
    assert "Traceback" not in stderr, stderr
    assert lines and lines[-1].startswith("spectral-gi: error:"), stderr
    return lines[-1]


@pytest.fixture
def scene_doc(tmp_path):
    assert cli.main(["save-default-scene", str(tmp_path / "s.json")]) == 0
    return json.loads((tmp_path / "s.json").read_text())


def write_doc(tmp_path, doc, name="c.json"):
    """The mutated document beside the saved arrays (s.npz, which it names)."""
    (tmp_path / name).write_text(json.dumps(doc))
    return tmp_path / name


# --------------------------------------------------------------------------- crashes → one line (subprocess)

def test_a_camera_frame_that_overflows_is_refused_before_any_kernel(tmp_path, scene_doc, scale=1.4e154):
    doc = copy.deepcopy(scene_doc)
    for k in range(3):
        doc["camera"]["to_world"][k] = [scale * x for x in doc["camera"]["to_world"][k][:3]] + \
                                       [doc["camera"]["to_world"][k][3]]
    write_doc(tmp_path, doc)
    (tmp_path / "c.exr").write_bytes(b"earlier render")
    r = run(["render", "c.json", "--spp", "1", "--width", "8", "--height", "8"], tmp_path)
    assert r.returncode == 2, r.stderr
    assert "camera.to_world" in one_error_line(r.stderr)
    assert (tmp_path / "c.exr").read_bytes() == b"earlier render"


def test_a_damaged_checkpoint_is_refused_before_any_kernel(tmp_path):
    from spectral_gi.core.film import Film

    film = Film(8, 8, spectral_bins=4)
    film.spp = 1
    film.save(tmp_path / "f.npz")
    with np.load(tmp_path / "f.npz") as z:
        arrays = {k: z[k] for k in z.files}
    arrays["spectral"] = np.zeros((2, 2, 4))  # the probe's out-of-bounds write
    np.savez(tmp_path / "bad.npz", **arrays)
    r = run(["render", "--width", "8", "--height", "8", "--spp", "2", "--resume", "bad.npz"], tmp_path)
    assert r.returncode == 2, r.stderr
    assert "--resume: film bad.npz: spectral: expected shape (8, 8, N)" in one_error_line(r.stderr)
    assert not (tmp_path / "cornell.exr").exists()


# --------------------------------------------------------------------------- tracebacks → one line (in process)

def _mutations():
    def setp(path, value):
        def f(doc):
            d = doc
            for k in path[:-1]:
                d = d[k]
            d[path[-1]] = value
        return f

    return {
        "Infinity in an integer field": (setp(("settings", "spp"), float("inf")), "settings.spp"),
        "an index written as 0.0": (setp(("materials", 0, "reflectance"), 0.0), "materials[0].reflectance"),
        "metadata of the wrong type": (setp(("metadata",), "box"), "metadata"),
        "material params of the wrong type": (setp(("materials", 0, "params"), {"a": 1}), "materials[0].params"),
        "a string as a flag": (setp(("materials", 3, "two_sided"), "no"), "materials[3].two_sided"),
        "a huge luminance": (setp(("materials", 3, "emission_luminance"), 1e30), "emission_luminance"),
        "a huge integer": (setp(("settings", "seed"), 10 ** 400), "settings.seed"),
        "a resolution beyond memory": (lambda d: d["camera"].update(width=65536, height=65536), "camera.width"),
        "nesting 1000 deep": (setp(("metadata",), {"k": json.loads("[" * 200 + "]" * 200)}), "nests deeper"),
    }


@pytest.mark.parametrize("case", sorted(_mutations()))
def test_bad_scene_fields_give_one_line_and_status_2(tmp_path, scene_doc, capsys, case):
    mutate, needle = _mutations()[case]
    doc = copy.deepcopy(scene_doc)
    mutate(doc)
    write_doc(tmp_path, doc)
    (tmp_path / "c.exr").write_bytes(b"earlier render")
    code = cli.main(["render", str(tmp_path / "c.json"), "--spp", "1", "--out", str(tmp_path / "c.exr")])
    err = capsys.readouterr().err
    assert code == 2, err
    assert needle in one_error_line(err)
    assert (tmp_path / "c.exr").read_bytes() == b"earlier render"


def test_json_nested_a_thousand_deep_gives_one_line(tmp_path, capsys):
    (tmp_path / "deep.json").write_text('{"format": "spectral-gi-scene", "version": 1, "metadata": '
                                        + "[" * 1000 + "]" * 1000 + "}")
    assert cli.main(["render", str(tmp_path / "deep.json")]) == 2
    assert "nests deeper than" in one_error_line(capsys.readouterr().err)


@pytest.mark.parametrize("args,needle", [
    (["--spectral-bins", "1e9"], "--spectral-bins"),
    (["--spectral-bins", "50000"], "in [0, 471]"),
    (["--spp", "1_0"], "'1_0'"),
    (["--width", "٣"], "--width"),
    (["--exposure", "nan"], "--exposure"),
    (["--time-limit", "inf"], "--time-limit"),
    (["--threads", "100000"], "--threads"),
])
def test_bad_options_give_one_line_and_status_2(capsys, args, needle):
    with pytest.raises(SystemExit) as e:
        cli.main(["render"] + args)
    assert e.value.code == 2
    err = capsys.readouterr().err
    assert len(err.strip().splitlines()) == 1 and needle in one_error_line(err)


# --------------------------------------------------------------------------- signals at every phase (subprocess)

def _caught(pid, signum):
    """Whether process ``pid`` has installed a handler for ``signum`` (Linux /proc)."""
    try:
        with open(f"/proc/{pid}/status") as f:
            for line in f:
                if line.startswith("SigCgt:"):
                    return bool(int(line.split()[1], 16) >> (signum - 1) & 1)
    except OSError:
        pass
    return False


def _start(tmp_path, extra=()):
    (tmp_path / "cornell.exr").write_bytes(b"earlier render")
    (tmp_path / "cornell.png").write_bytes(b"earlier preview")
    return subprocess.Popen(CLI + ["render", "--width", "48", "--height", "48", "--spp", "100000", *extra],
                            cwd=tmp_path, stderr=subprocess.PIPE, stdout=subprocess.PIPE, text=True)


def _earlier_outputs_kept(tmp_path):
    return ((tmp_path / "cornell.exr").read_bytes(), (tmp_path / "cornell.png").read_bytes()) == \
        (b"earlier render", b"earlier preview")


def _no_temporary_files(tmp_path):
    left = [p.name for p in tmp_path.iterdir() if p.name.startswith(".")]
    assert not left, left


@POSIX
@pytest.mark.skipif(not os.path.exists("/proc/self/status"), reason="needs /proc to see the handler installed")
@pytest.mark.parametrize("signum", [signal.SIGINT, signal.SIGTERM])
def test_a_signal_at_start_up_exits_130_with_one_line(tmp_path, signum):
    p = _start(tmp_path)
    deadline = time.time() + 120
    while not _caught(p.pid, signal.SIGTERM) and time.time() < deadline and p.poll() is None:
        time.sleep(0.005)
    p.send_signal(signum)
    out, err = p.communicate(timeout=300)
    assert p.returncode == 130, err
    assert "Traceback" not in err and err.strip().splitlines()[-1].startswith("spectral-gi: ")
    assert _earlier_outputs_kept(tmp_path)
    _no_temporary_files(tmp_path)


@pytest.mark.slow
@POSIX
@pytest.mark.parametrize("signum", [signal.SIGINT, signal.SIGTERM])
def test_a_signal_while_kernels_are_prepared_writes_nothing(tmp_path, signum):
    p = _start(tmp_path)
    buf = ""
    deadline = time.time() + 300
    while time.time() < deadline:
        line = p.stderr.readline()
        buf += line
        if "Preparing scene" in line or "kernels" in line or not line:
            break
    p.send_signal(signum)
    out, err = p.communicate(timeout=600)
    assert p.returncode == 130, buf + err
    assert "Traceback" not in buf + err
    if "nothing written" in err:
        assert _earlier_outputs_kept(tmp_path)
    else:  # the signal came after the first pass: a consistent partial pair
        assert int(read_channels(tmp_path / "cornell.exr")[1]["spectralgi.spp"]) > 0
    _no_temporary_files(tmp_path)


@pytest.mark.slow
@POSIX
def test_sigterm_while_rendering_writes_what_was_rendered(tmp_path):
    p = _start(tmp_path)
    deadline = time.time() + 300
    buf = ""
    while time.time() < deadline:
        line = p.stderr.readline()
        buf += line
        if ("spp" in line and "[" in line) or not line:
            break
    time.sleep(0.3)
    p.send_signal(signal.SIGTERM)
    out, err = p.communicate(timeout=300)
    assert p.returncode == 130, buf + err
    assert "Traceback" not in err
    chans, header = read_channels(tmp_path / "cornell.exr")
    assert 0 < int(header["spectralgi.spp"]) < 100000 and np.all(np.isfinite(chans["R"]))
    assert (tmp_path / "cornell.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    _no_temporary_files(tmp_path)


# --------------------------------------------------------------------------- the write phase (in process)

def _render_args(tmp_path, *extra):
    return ["render", "--width", "12", "--height", "10", "--spp", "2", "--threads", "1",
            "--out", str(tmp_path / "box.exr"), *extra]


@pytest.mark.slow
@POSIX
@pytest.mark.parametrize("signum", [signal.SIGINT, signal.SIGTERM])
def test_a_signal_during_the_final_write_keeps_the_finished_render(tmp_path, monkeypatch, capsys, signum):
    import spectral_gi.core.io.png as png

    real = png.write_png

    def signalled(*a, **kw):
        os.kill(os.getpid(), signum)  # delivered while the EXR is written and the PNG is being written
        return real(*a, **kw)

    monkeypatch.setattr(png, "write_png", signalled)
    code = cli.main(_render_args(tmp_path))
    err = capsys.readouterr().err
    assert code == 130, err
    assert "Traceback" not in err and "will be complete" in err
    chans, header = read_channels(tmp_path / "box.exr")
    assert header["spectralgi.spp"] == "2" and np.all(np.isfinite(chans["R"]))
    assert (tmp_path / "box.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    _no_temporary_files(tmp_path)


@pytest.mark.slow
@pytest.mark.parametrize("which", ["exr", "png"])
def test_a_full_disk_keeps_the_film_and_the_earlier_outputs(tmp_path, monkeypatch, capsys, which):
    import spectral_gi.core.io.exr as exr
    import spectral_gi.core.io.png as png

    (tmp_path / "box.exr").write_bytes(b"earlier render")
    (tmp_path / "box.png").write_bytes(b"earlier preview")
    module, name = (exr, "write_render") if which == "exr" else (png, "write_png")
    real = getattr(module, name)

    def full(*a, **kw):
        raise OSError(28, "No space left on device")

    monkeypatch.setattr(module, name, full)
    code = cli.main(_render_args(tmp_path))
    err = capsys.readouterr().err
    line = one_error_line(err)
    assert code == 1 and "No space left on device" in line and "box.film.npz" in line, err
    assert (tmp_path / "box.exr").read_bytes() == b"earlier render"  # the EXR and its PNG: both or neither
    assert (tmp_path / "box.png").read_bytes() == b"earlier preview"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["box.exr", "box.film.npz", "box.png"]
    # the kept film writes the same image once the disk has room: no sample is rendered again
    monkeypatch.setattr(module, name, real)
    code = cli.main(_render_args(tmp_path, "--resume", str(tmp_path / "box.film.npz")))
    assert code == 0, capsys.readouterr().err
    from spectral_gi.core.film import Film

    film = Film.load(tmp_path / "box.film.npz")
    chans, header = read_channels(tmp_path / "box.exr")
    assert header["spectralgi.spp"] == "2"
    np.testing.assert_array_equal(chans["Luminance.Y"], film.develop().luminance.astype(np.float32))


@pytest.mark.slow
@POSIX
def test_a_file_size_limit_during_the_write_gives_one_line_and_no_temporary_file(tmp_path):
    import resource

    def limit():
        signal.signal(signal.SIGXFSZ, signal.SIG_IGN)  # the write fails with EFBIG instead of killing
        resource.setrlimit(resource.RLIMIT_FSIZE, (4096, 4096))

    (tmp_path / "box.exr").write_bytes(b"earlier render")
    r = subprocess.run(CLI + _render_args(tmp_path), cwd=tmp_path, capture_output=True, text=True, timeout=600,
                       preexec_fn=limit)
    assert r.returncode == 1, r.stderr
    assert "cannot write" in one_error_line(r.stderr)
    assert (tmp_path / "box.exr").read_bytes() == b"earlier render"
    _no_temporary_files(tmp_path)
