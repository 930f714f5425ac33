"""Peer renderers for the benchmarks: Mitsuba 3 from PyPI, in a private environment.

    python benchmarks/peers.py            # set up (once) and print what is available

Mitsuba's LLVM variants (``llvm_ad_spectral``) need LLVM ≥ 16 (measured here: with LLVM 15
they abort). The set-up makes ``benchmarks/.peers/`` (git-ignored) with

* ``venv/``: a virtual environment with ``mitsuba`` from PyPI (it brings ``drjit``);
* ``llvm/``: Debian's ``libllvm19`` package unpacked with ``dpkg -x`` (no root needed),
  passed to Dr.Jit through ``DRJIT_LIBLLVM_PATH``.

``render_mitsuba(scene, ...)`` turns a core scene (Lambert and emissive materials,
rectangle/ellipse lights, a perspective camera) into a Mitsuba scene: meshes as PLY
files, spectra sampled every 5 nm from the scene's own Fourier-basis spectra, emitter
radiance in absolute W/(m² sr nm) from their luminance, so the two renderers see the
same physical scene. It renders in a subprocess and returns the times and the linear
Rec.709 image.
"""
from __future__ import annotations

import glob
import json
import os
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
PEERS = HERE / ".peers"
VENV = PEERS / "venv"
LLVM = PEERS / "llvm"
MITSUBA_VERSION = "mitsuba==3.9.1"
CIE_Y_INTEGRAL = 106.856895  # ∫ ȳ(λ) dλ of CIE 1931, the normalisation Mitsuba applies to its film
LLVM_PACKAGE = "libllvm19"


def _venv_python():
    return VENV / "bin" / "python"


def _llvm_library():
    hits = sorted(glob.glob(str(LLVM / "usr" / "lib" / "*" / "libLLVM*.so*")))
    return hits[0] if hits else None


def setup(verbose=True):
    """Create the peer environment if missing. Returns a reason string on failure, else None."""
    say = print if verbose else (lambda *a, **k: None)
    PEERS.mkdir(exist_ok=True)
    if not _venv_python().exists():
        say(f"peers: creating {VENV} and installing {MITSUBA_VERSION} from PyPI")
        r = subprocess.run([sys.executable, "-m", "venv", str(VENV)], capture_output=True, text=True)
        if r.returncode:
            return f"venv failed: {r.stderr.strip()[-300:]}"
    r = subprocess.run([str(_venv_python()), "-c", "import mitsuba"], capture_output=True, text=True)
    if r.returncode:
        r = subprocess.run([str(_venv_python()), "-m", "pip", "install", "-q", MITSUBA_VERSION, "numpy"],
                           capture_output=True, text=True)
        if r.returncode:
            return f"pip install {MITSUBA_VERSION} failed: {r.stderr.strip()[-300:]}"
    if _llvm_library() is None:
        say(f"peers: fetching Debian's {LLVM_PACKAGE} (for Mitsuba's LLVM variants)")
        with tempfile.TemporaryDirectory() as tmp:
            r = subprocess.run(["apt-get", "download", LLVM_PACKAGE], cwd=tmp, capture_output=True, text=True)
            debs = glob.glob(os.path.join(tmp, "*.deb"))
            if r.returncode or not debs:
                return f"apt-get download {LLVM_PACKAGE} failed: {r.stderr.strip()[-300:]}"
            r = subprocess.run(["dpkg", "-x", debs[0], str(LLVM)], capture_output=True, text=True)
            if r.returncode:
                return f"dpkg -x failed: {r.stderr.strip()[-300:]}"
    return None


def _env(threads):
    env = dict(os.environ)
    lib = _llvm_library()
    if lib:
        env["DRJIT_LIBLLVM_PATH"] = lib
    env["SGI_THREADS"] = str(threads)
    return env


def _write_ply(path, positions, indices):
    positions = np.ascontiguousarray(positions, "<f4")
    indices = np.ascontiguousarray(indices, "<i4")
    head = (f"ply\nformat binary_little_endian 1.0\nelement vertex {positions.shape[0]}\n"
            "property float x\nproperty float y\nproperty float z\n"
            f"element face {indices.shape[0]}\nproperty list uchar int vertex_indices\nend_header\n")
    faces = np.empty(indices.shape[0], dtype=[("n", "u1"), ("i", "<i4", (3,))])
    faces["n"] = 3
    faces["i"] = indices
    with open(path, "wb") as fh:
        fh.write(head.encode("ascii"))
        fh.write(positions.tobytes())
        fh.write(faces.tobytes())


def scene_description(scene, folder):
    """A JSON-able description of ``scene`` for the Mitsuba runner (writes PLY files to ``folder``)."""
    from spectral_gi.core import constants as C
    from spectral_gi.core.film.record import cmf_table
    from spectral_gi.core.photometry.units import luminance_scale
    from spectral_gi.core.spectra import moments

    spec = moments.tabulate(scene.spectra.coeffs, scene.spectra.kind)
    cmf = cmf_table()
    grid = np.arange(C.LAMBDA_MIN, C.LAMBDA_MAX + 0.5, C.LAMBDA_STEP)
    pick = slice(0, None, 5)

    def sampled(row, scale=1.0):
        return {"wavelengths": grid[pick].tolist(), "values": (spec[row][pick].astype(float) * scale).tolist()}

    shapes = []
    for mi, mesh in enumerate(scene.meshes):
        for mat_index in np.unique(mesh.material):
            sel = mesh.material == mat_index
            path = os.path.join(folder, f"mesh{mi}_{int(mat_index)}.ply")
            _write_ply(path, mesh.positions, mesh.indices[sel])
            m = scene.materials[int(mat_index)]
            if m.model != C.MAT_LAMBERT:
                raise ValueError(f"material {m.name!r}: only Lambert materials are translated for Mitsuba")
            entry = {"ply": path, "reflectance": sampled(m.reflectance) if m.reflectance >= 0 else None}
            if m.emission >= 0 and m.emission_luminance > 0:
                if not m.two_sided:
                    pass  # Mitsuba's area emitters are one-sided, like this material
                scale = luminance_scale(spec[m.emission], cmf, m.emission_luminance, m.name)
                entry["radiance"] = sampled(m.emission, scale)
            shapes.append(entry)
    for li in scene.lights:
        if li.kind not in (C.LIGHT_RECT,):
            raise ValueError(f"light {li.name!r}: only rectangle lights are translated for Mitsuba")
        scale = luminance_scale(spec[li.spectrum], cmf, li.luminance, li.name)
        u, v = np.asarray(li.axis_u, float), np.asarray(li.axis_v, float)
        n = np.cross(u, v)
        m = np.eye(4)
        m[:3, 0], m[:3, 1], m[:3, 2], m[:3, 3] = u, v, n / np.linalg.norm(n), li.position
        shapes.append({"rectangle": m.tolist(), "radiance": sampled(li.spectrum, scale)})
    cam = scene.camera
    half = 0.5 * cam.sensor_width_mm / cam.lens_mm
    if cam.height > cam.width:
        half *= cam.width / cam.height  # AUTO fit: the sensor width goes along the larger side
    fov_x = float(np.degrees(2.0 * np.arctan(half)))
    to_world = np.asarray(cam.to_world, float) @ np.diag([-1.0, 1.0, -1.0, 1.0])  # Blender → Mitsuba camera axes
    return {"shapes": shapes, "camera": {"to_world": to_world.tolist(), "fov_x": fov_x,
                                         "width": int(cam.width), "height": int(cam.height)}}


_RUNNER = r'''
import json, sys, time, os
import numpy as np
import mitsuba as mi
desc = json.load(open(sys.argv[1]))
variant, spp, max_depth, out = sys.argv[2], int(sys.argv[3]), int(sys.argv[4]), sys.argv[5]
mi.set_variant(variant)
import drjit as dr
threads = int(os.environ.get("SGI_THREADS", "0"))
if threads > 0:
    dr.set_thread_count(threads)
def spectrum(d):
    return {"type": "spectrum", "value": [(float(w), float(v)) for w, v in zip(d["wavelengths"], d["values"])]}
sc = {"type": "scene", "integrator": {"type": "path", "max_depth": max_depth}}
c = desc["camera"]
sc["sensor"] = {"type": "perspective", "fov": c["fov_x"], "fov_axis": "x",
                "to_world": mi.ScalarTransform4f(c["to_world"]),
                "film": {"type": "hdrfilm", "width": c["width"], "height": c["height"],
                         "rfilter": {"type": "box"}, "pixel_format": "rgb"},
                "sampler": {"type": "independent", "sample_count": spp}}
for i, s in enumerate(desc["shapes"]):
    if "ply" in s:
        shape = {"type": "ply", "filename": s["ply"], "face_normals": True}
    else:
        shape = {"type": "rectangle", "to_world": mi.ScalarTransform4f(s["rectangle"])}
    refl = s.get("reflectance")
    shape["bsdf"] = {"type": "diffuse", "reflectance": spectrum(refl) if refl else {"type": "rgb", "value": [0, 0, 0]}}
    if s.get("radiance"):
        shape["emitter"] = {"type": "area", "radiance": spectrum(s["radiance"])}
    sc[f"shape{i}"] = shape
t0 = time.perf_counter()
scene = mi.load_dict(sc)
t_load = time.perf_counter() - t0
times = []
img = None
for rep in range(2):  # the first render includes Dr.Jit's kernel compilation
    t0 = time.perf_counter()
    img = mi.render(scene, spp=spp, seed=rep)
    dr.eval(img)
    dr.sync_thread()
    times.append(time.perf_counter() - t0)
np.save(out, np.array(img, dtype=np.float64))
print(json.dumps({"load": t_load, "first": times[0], "warm": times[1], "variant": variant}))
'''


def render_mitsuba(scene, spp, max_depth, variant="llvm_ad_spectral", threads=None):
    """Render a core scene with Mitsuba. Returns (dict of times, rgb image) or raises RuntimeError."""
    reason = setup(verbose=False)
    if reason:
        raise RuntimeError(reason)
    threads = threads or os.cpu_count() or 1
    with tempfile.TemporaryDirectory(prefix="sgi-mitsuba-") as tmp:
        desc = scene_description(scene, tmp)
        dpath = os.path.join(tmp, "scene.json")
        with open(dpath, "w") as fh:
            json.dump(desc, fh)
        runner = os.path.join(tmp, "run.py")
        with open(runner, "w") as fh:
            fh.write(_RUNNER)
        out = os.path.join(tmp, "img.npy")
        r = subprocess.run([str(_venv_python()), runner, dpath, variant, str(spp), str(max_depth), out],
                           capture_output=True, text=True, env=_env(threads))
        if r.returncode:
            raise RuntimeError(f"Mitsuba ({variant}) failed: {(r.stderr or r.stdout).strip()[-500:]}")
        times = json.loads(r.stdout.strip().splitlines()[-1])
        # Mitsuba's spectral film divides XYZ by the integral of CIE ȳ (106.856895 nm); this
        # renderer's film does not (its Y is ∫ L ȳ dλ, luminance = 683 Y). Undo the division.
        return times, np.load(out) * CIE_Y_INTEGRAL


if __name__ == "__main__":
    problem = setup()
    if problem:
        print("Mitsuba unavailable:", problem)
        sys.exit(1)
    r = subprocess.run([str(_venv_python()), "-c", "import mitsuba; print(mitsuba.__version__, mitsuba.variants())"],
                       capture_output=True, text=True, env=_env(1))
    print("Mitsuba", r.stdout.strip() or r.stderr.strip())
    print("LLVM:", _llvm_library())
