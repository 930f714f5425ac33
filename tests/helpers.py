"""Small scene builders shared by the core tests."""
import math
import struct
import subprocess
import sys
import textwrap
import zlib

import numpy as np

from spectral_gi.core import constants as C
from spectral_gi.core.film import develop
from spectral_gi.core.integrators.render import render
from spectral_gi.core.scene import Camera, Light, Material, Mesh, RenderSettings, Scene, SpectrumTable
from spectral_gi.core.spectra import uplift


def flat_reflectance(rho, n=C.N_COEFFS_DEFAULT):
    return uplift.reflectance_from_samples([C.LAMBDA_MIN, C.LAMBDA_MAX], [rho, rho], n)


def flat_emission(n=C.N_COEFFS_DEFAULT):
    return uplift.emission_from_samples([C.LAMBDA_MIN, C.LAMBDA_MAX], [1.0, 1.0], n)


def look_at(eye, target, up=(0.0, 0.0, 1.0)):
    eye = np.asarray(eye, float)
    f = np.asarray(target, float) - eye
    f /= np.linalg.norm(f)
    r = np.cross(f, up)
    if np.linalg.norm(r) < 1e-9:
        r = np.cross(f, (0.0, 1.0, 0.0))
    r /= np.linalg.norm(r)
    u = np.cross(r, f)
    m = np.eye(4)
    m[:3, 0], m[:3, 1], m[:3, 2], m[:3, 3] = r, u, -f, eye
    return m


def box_mesh(name, lo, hi, material):
    """An axis-aligned box as 12 triangles (normals point outwards)."""
    lo = np.asarray(lo, float)
    hi = np.asarray(hi, float)
    c = np.array([[lo[0], lo[1], lo[2]], [hi[0], lo[1], lo[2]], [hi[0], hi[1], lo[2]], [lo[0], hi[1], lo[2]],
                  [lo[0], lo[1], hi[2]], [hi[0], lo[1], hi[2]], [hi[0], hi[1], hi[2]], [lo[0], hi[1], hi[2]]])
    quads = [(0, 3, 2, 1), (4, 5, 6, 7), (0, 1, 5, 4), (2, 3, 7, 6), (1, 2, 6, 5), (0, 4, 7, 3)]
    tris = []
    for a, b, cc, d in quads:
        tris += [(a, b, cc), (a, cc, d)]
    tris = np.array(tris, np.int32)
    return Mesh(name, c.astype(np.float32), tris, np.full(len(tris), material, np.int32))


def furnace_scene(rho=0.5, luminance=100.0, width=8, height=8, spp=64, max_depth=256):
    """Camera inside a closed box whose walls all emit L_e and reflect rho: L = L_e / (1 - rho)."""
    spectra = SpectrumTable.empty()
    r = spectra.add("grey", flat_reflectance(rho), C.SPECTRUM_BOUNDED)
    e = spectra.add("flat", flat_emission(), C.SPECTRUM_UNBOUNDED)
    mat = Material("wall", reflectance=r, emission=e, emission_luminance=luminance)
    mesh = box_mesh("box", (-1, -1, -1), (1, 1, 1), 0)
    cam = Camera(look_at((0, 0, 0), (1, 0.2, 0.1)), width=width, height=height, lens_mm=20.0)
    return Scene(meshes=[mesh], spectra=spectra, materials=[mat], camera=cam,
                 settings=RenderSettings(spp=spp, max_depth=max_depth, rr_depth=3, seed=7))


def disk_over_plane_scene(radius=0.5, height=1.0, rho=0.8, luminance=1000.0, kind=C.LIGHT_ELLIPSE,
                          spp=256, res=9):
    """A Lambertian plane z=0 under a coaxial downward disk light; the camera looks straight down.

    At the plane's centre E = π L R² / (h² + R²), so the radiance is ρ L R² / (h² + R²).
    """
    spectra = SpectrumTable.empty()
    r = spectra.add("grey", flat_reflectance(rho), C.SPECTRUM_BOUNDED)
    e = spectra.add("flat", flat_emission(), C.SPECTRUM_UNBOUNDED)
    s = 50.0
    plane = Mesh("plane", np.array([[-s, -s, 0], [s, -s, 0], [s, s, 0], [-s, s, 0]], np.float32),
                 np.array([[0, 1, 2], [0, 2, 3]], np.int32), np.zeros(2, np.int32))
    # emit downwards: cross(u, v) = -z
    light = Light("disk", kind, (0.0, 0.0, height), (0.0, radius, 0.0), (radius, 0.0, 0.0), e, luminance)
    cam = Camera(look_at((0, 0, 0.5 * height), (0, 0, 0), up=(0, 1, 0)), width=res, height=res, lens_mm=2000.0)
    return Scene(meshes=[plane], spectra=spectra, materials=[Material("plane", reflectance=r)], lights=[light],
                 camera=cam, settings=RenderSettings(spp=spp, max_depth=0, seed=3))


def read_png_rgb8(path):
    """Read back a PNG written by the product's PNG writer (8-bit RGB, filter 0 only). For tests."""
    data = open(path, "rb").read()
    assert data[:8] == b"\x89PNG\r\n\x1a\n"
    pos = 8
    idat = b""
    w = h = 0
    while pos < len(data):
        (n,) = struct.unpack(">I", data[pos:pos + 4])
        tag = data[pos + 4:pos + 8]
        body = data[pos + 8:pos + 8 + n]
        if tag == b"IHDR":
            w, h = struct.unpack(">II", body[:8])
        elif tag == b"IDAT":
            idat += body
        pos += 12 + n
    raw = np.frombuffer(zlib.decompress(idat), np.uint8).reshape(h, 1 + 3 * w)
    return raw[:, 1:].reshape(h, w, 3)


# a white plane under analytic lights, seen from straight above (lights and photometric profiles)
RHO = 0.8
CAM_H = 3.0


def plane_scene(lights, res=12, half_view=0.8, spp=32, max_depth=0, seed=1):
    """A white Lambert plane z = 0 (ρ = 0.8) and a camera at height 3 looking straight down
    whose view covers [-half_view, half_view]² of the plane."""
    spectra = SpectrumTable.empty()
    r = spectra.add("grey", flat_reflectance(RHO), C.SPECTRUM_BOUNDED)
    e = spectra.add("flat", flat_emission(), C.SPECTRUM_UNBOUNDED)
    s = 50.0
    plane = Mesh("plane", np.array([[-s, -s, 0], [s, -s, 0], [s, s, 0], [-s, s, 0]], np.float32),
                 np.array([[0, 1, 2], [0, 2, 3]], np.int32), np.zeros(2, np.int32))
    lens = 18.0 * CAM_H / half_view  # half of the 36 mm sensor over the lens = half_view / height
    cam = Camera(look_at((0, 0, CAM_H), (0, 0, 0), up=(0, 1, 0)), width=res, height=res, lens_mm=lens)
    for li in lights:
        li.spectrum = e
    return Scene(meshes=[plane], spectra=spectra, materials=[Material("plane", reflectance=r)], lights=list(lights),
                 camera=cam, settings=RenderSettings(spp=spp, max_depth=max_depth, seed=seed, filter=C.FILTER_BOX,
                                                 filter_width=1.0))


def ground_points(sc, sub=6):
    """(H, W, sub², 3) points of the plane seen through a sub × sub grid in every pixel."""
    cam = sc.camera
    w, h = cam.width, cam.height
    half = 0.5 * cam.sensor_width_mm / cam.lens_mm
    o = (np.arange(sub) + 0.5) / sub
    px = (np.arange(w)[:, None] + o[None, :]).reshape(-1)
    py = (np.arange(h)[:, None] + o[None, :]).reshape(-1)
    sx = (px / w * 2 - 1) * half
    sy = (1 - py / h * 2) * half
    m = cam.to_world
    d = (m[:3, 0][None, None] * sx[None, :, None] + m[:3, 1][None, None] * sy[:, None, None] - m[:3, 2])
    t = m[2, 3] / -d[..., 2]
    p = m[:3, 3] + t[..., None] * d  # (h·sub, w·sub, 3)
    return p.reshape(h, sub, w, sub, 3).transpose(0, 2, 1, 3, 4).reshape(h, w, sub * sub, 3)


def render_lum(sc):
    return develop(render(sc)[0].sums)


def check_luminance(d, expected, rel):
    """Every pixel's luminance within ``rel`` of the image's peak expectation, plus 4.5 standard errors."""
    err = np.abs(d.luminance - expected)
    assert np.all(err <= rel * expected.max() + 4.5 * np.sqrt(d.variance)), \
        (err.max(), expected.max(), np.unravel_index(err.argmax(), err.shape))


def smoothstep(x):
    x = np.clip(x, 0, 1)
    return x * x * (3 - 2 * x)


def blender_spot_mask(t, spot_size, blend):
    """Cycles' spot attenuation: 0 at or below cos(spot_size/2), then a smoothstep over
    (1 - cos½)·blend of the cosine (intern/cycles scene/light.cpp, kernel/light/spot.h)."""
    ch = math.cos(spot_size / 2)
    if blend == 0:
        return (t > ch).astype(float)
    return np.where(t > ch, smoothstep((t - ch) / ((1 - ch) * blend)), 0.0)


# A .blend of a grey diffuse floor, an area light above it and a camera looking down, built in a
# background Blender (the bpy module) with the add-on registered. ``light_setup`` and ``extra`` are
# Python run in that Blender before the file is saved: ``material`` (its node ``tree`` ``t``, the Diffuse
# node ``d``), ``light`` and ``scene`` are in scope; ``sys.argv[1]`` is the file, later arguments are free.
_FLOOR_BLEND = """
import math, sys
import bpy
from spectral_gi.addon import registration
registration.register()
bpy.ops.wm.read_homefile(use_empty=True)
scene = bpy.context.scene
def link(o):
    scene.collection.objects.link(o)
    return o
material = m = bpy.data.materials.new("Grey")
t = m.node_tree
t.nodes.clear()
out, d = t.nodes.new("ShaderNodeOutputMaterial"), t.nodes.new("ShaderNodeBsdfDiffuse")
d.inputs["Color"].default_value = (0.5, 0.5, 0.5, 1.0)
t.links.new(d.outputs[0], out.inputs["Surface"])
me = bpy.data.meshes.new("Floor")
me.from_pydata([(-3, -3, 0), (3, -3, 0), (3, 3, 0), (-3, 3, 0)], [], [(0, 1, 2, 3)])
me.materials.append(m)
link(bpy.data.objects.new("Floor", me))
light = bpy.data.lights.new("Key", "AREA")
light.energy, light.size = 200.0, 1.0
link(bpy.data.objects.new("Key", light)).location = (0, 0, 3)
cam = link(bpy.data.objects.new("Cam", bpy.data.cameras.new("Cam")))
cam.location, cam.rotation_euler = (0, -6, 3), (math.radians(60), 0, 0)
scene.camera = cam
scene.render.resolution_x, scene.render.resolution_y, scene.render.resolution_percentage = {width}, {height}, 100
scene.spectral_gi.samples = 2
"""


def make_floor_blend(path, extra="", *args, width=12, height=8, timeout=600):
    """Write the floor scene above to ``path`` (a background Blender run); ``extra`` is run before saving."""
    script = (_FLOOR_BLEND.format(width=int(width), height=int(height)) + textwrap.dedent(extra)
              + "\nbpy.ops.wm.save_as_mainfile(filepath=sys.argv[1])\n")
    made = subprocess.run([sys.executable, "-c", script, str(path), *map(str, args)], capture_output=True,
                          text=True, timeout=timeout)
    assert made.returncode == 0 and path.is_file(), made.stderr[-2000:]
    return path


def recording_layout(props, labels=None, operators=None):
    """A stand-in for a panel's ``UILayout``: records the names of the properties drawn (failing on one its
    owner lacks), and where lists are given the label texts and operator ids."""
    from unittest import mock

    lay = mock.MagicMock()
    for name in ("row", "column", "box", "split", "grid_flow"):
        getattr(lay, name).return_value = lay

    def prop(owner, name, **kw):
        assert hasattr(owner, name), (owner, name)
        props.append(name)

    lay.prop.side_effect = prop
    if labels is not None:
        lay.label.side_effect = lambda text="", **kw: labels.append(text)
    if operators is not None:
        lay.operator.side_effect = lambda idname, **kw: operators.append(idname) or mock.MagicMock()
    return lay


def floor_cube_scene(b, w=16, h=16, spp=4):
    """The add-on tests' small engine scene through builder ``b``: a grey floor, a red cube under an area
    light, seen from the front. Returns the light and the red material."""
    grey = b.shader("Grey", "ShaderNodeBsdfDiffuse", Color=(0.6, 0.6, 0.6, 1.0))
    red = b.shader("Red", "ShaderNodeBsdfDiffuse", Color=(0.7, 0.1, 0.1, 1.0))
    b.plane("Floor", size=6.0, material=grey)
    b.cube("Cube", size=1.0, location=(0, 0, 0.5), material=red)
    key = b.light("Key", "AREA", location=(0, 0, 3), energy=200.0, size=1.0)
    b.camera(location=(0, -6, 2), rotation=(math.radians(75), 0, 0), lens=30.0)
    b.resolution(w, h)
    s = b.scene.spectral_gi
    s.samples, s.max_bounces, s.seed = spp, 8, 3
    b.scene.render.engine = "SPECTRAL_GI"
    return key, red
