"""The final gather (core/integrators/radiosity/gather.py): the kernel's camera and gather
rays against brute-force tracing (tests/oracles/radiosity.py), a closed emitting room whose
image is known in closed form, and the Cornell box against the path tracer (slow)."""
import math
import sys
from pathlib import Path

import numpy as np
import pytest

from spectral_gi import core
from spectral_gi.core import constants as C
from spectral_gi.core.camera import record as camera_record
from spectral_gi.core.integrators.radiosity import kernel as K
from spectral_gi.core.integrators.radiosity import meshing, solve
from spectral_gi.core.scene import Camera, Material, Mesh, RenderSettings, Scene, SpectrumTable

sys.path.insert(0, str(Path(__file__).resolve().parents[2]))
from helpers import box_mesh, flat_emission, flat_reflectance  # noqa: E402
from oracles.radiosity import first_patches  # noqa: E402


def look_from(pos, target):
    """A camera-to-world matrix at ``pos`` looking at ``target`` (+Z up)."""
    f = np.asarray(target, float) - pos
    f /= np.linalg.norm(f)
    r = np.cross(f, [0, 0, 1.0])
    r /= np.linalg.norm(r)
    u = np.cross(r, f)
    m = np.eye(4)
    m[:3, 0], m[:3, 1], m[:3, 2], m[:3, 3] = r, u, -f, pos
    return m


def glowing_room(rho=0.6, luminance=10.0, width=12, height=10):
    """A closed unit cube whose every face emits luminance L (one-sided, inwards) and reflects ρ,
    seen from inside: the radiance everywhere is L_e / (1 − ρ) (the furnace)."""
    sp = SpectrumTable.empty()
    r = sp.add("grey", flat_reflectance(rho), C.SPECTRUM_BOUNDED)
    e = sp.add("flat", flat_emission(), C.SPECTRUM_UNBOUNDED)
    box = box_mesh("room", (0, 0, 0), (1.0, 1.0, 1.0), 0)
    idx = np.ascontiguousarray(box.indices[:, ::-1])  # inwards
    mesh = Mesh("room", box.positions, idx, np.zeros(len(idx), np.int32))
    cam = Camera(look_from(np.array([0.2, 0.25, 0.4]), [0.8, 0.7, 0.55]), width=width, height=height, lens_mm=18.0)
    return Scene(meshes=[mesh], spectra=sp, camera=cam,
                 materials=[Material("glow", reflectance=r, emission=e, emission_luminance=luminance,
                                     two_sided=False)],
                 settings=RenderSettings(spp=2, seed=3))


def test_camera_and_gather_rays_against_brute_force_tracing():
    """OP_CAMERA's hits: the ray from the pinhole to each reported hit point reaches that
    patch first, at those barycentric coordinates (oracle), within the pixel's filter
    footprint; OP_GATHER's: the same from the gathering point, every ray in its hemisphere."""
    sc = core.cornell_box(width=10, height=8, spp=1)
    p = meshing.build_patches(sc, max_edge=0.25)
    pat = solve.patch_record(p.corners, p.geometry, p.tri_patch, p.occluders)
    cam = camera_record.pack(sc)
    w, h, spp = 10, 8, 3
    pix = np.arange(w * h, dtype=np.int32)
    q = solve._query(np.zeros((pix.size, 1, 3)), np.zeros((pix.size, 3)), pix, np.array([w, h], np.int32),
                     cam=cam.cam, filt=cam.filt)
    out = solve.run_op(K.OP_CAMERA, pat, q, solve._no_lights(), 3 * spp, spp, 5, 1e-6, 2).reshape(-1, 3)
    j = out[:, 0].astype(int)
    assert np.mean(j >= 0) > 0.9
    ok = j >= 0
    c = p.corners[j[ok]]
    x = c[:, 0] + out[ok, 1:2] * (c[:, 1] - c[:, 0]) + out[ok, 2:3] * (c[:, 2] - c[:, 0])
    o = np.asarray(sc.camera.to_world)[:3, 3]
    d = x - o
    dist = np.linalg.norm(d, axis=1)
    ref = first_patches(p, np.tile(o, (len(x), 1)), d / dist[:, None])
    np.testing.assert_array_equal(ref[:, 0].astype(int), j[ok])
    np.testing.assert_allclose(ref[:, 1:], out[ok, 1:], atol=2e-4)  # float32 corners and output
    # each hit is seen through its pixel (within the filter's width of its centre)
    m = np.asarray(sc.camera.to_world)[:3, :3]
    cs = d @ m  # camera space
    half_w = 0.5 * sc.camera.sensor_width_mm / sc.camera.lens_mm
    half_h = half_w * h / w
    sx = (-cs[:, 0] / cs[:, 2] / half_w + 1) / 2 * w
    sy = (1 - (-cs[:, 1] / cs[:, 2]) / half_h) / 2 * h
    px = np.repeat(pix, spp)[ok]
    fw = sc.settings.filter_width
    assert np.all(np.abs(sx - (px % w + 0.5)) <= 0.5 * fw + 1e-6)
    assert np.all(np.abs(sy - (px // w + 0.5)) <= 0.5 * fw + 1e-6)
    # gather rays from the first hits
    g = 6
    nrm = p.normal[j[ok]]
    qg = solve._query(x[:, None], nrm, np.arange(len(x), dtype=np.int32))
    og = solve.run_op(K.OP_GATHER, pat, qg, solve._no_lights(), 3 * g, g, 7, 1e-6, 2).reshape(-1, 3)
    jg = og[:, 0].astype(int)
    okg = jg >= 0
    src = np.repeat(x, g, axis=0)[okg]
    cg = p.corners[jg[okg]]
    xg = cg[:, 0] + og[okg, 1:2] * (cg[:, 1] - cg[:, 0]) + og[okg, 2:3] * (cg[:, 2] - cg[:, 0])
    dg = xg - src
    assert np.all(np.sum(dg * np.repeat(nrm, g, axis=0)[okg], axis=1) > 0)
    ref = first_patches(p, src + 1e-6 * np.repeat(nrm, g, axis=0)[okg], dg / np.linalg.norm(dg, axis=1)[:, None])
    np.testing.assert_array_equal(ref[:, 0].astype(int), jg[okg])
    np.testing.assert_allclose(ref[:, 1:], og[okg, 1:], atol=2e-4)


def test_gather_rays_follow_the_form_factors_item_58():
    """OP_GATHER's rays are cosine-distributed: the share from a point that reaches each
    patch is its point-to-patch form factor (binomial counts within 4.5 σ)."""
    sc = glowing_room()
    p = meshing.build_patches(sc, max_edge=0.5, sides="front")
    pat = solve.patch_record(p.corners, p.geometry, p.tri_patch)
    x = np.array([[0.3, 0.6, 0.0]])
    nrm = np.array([[0, 0, 1.0]])
    g = 20000
    og = solve.run_op(K.OP_GATHER, pat, solve._query(x[:, None], nrm, np.zeros(1, np.int32)), solve._no_lights(),
                      3 * g, g, 1, 1e-6, 1).reshape(-1, 3)
    hits = og[:, 0].astype(int)
    assert np.all(hits >= 0)
    F = np.array([core.form_factor_point_polygon(x[0], nrm[0], t) for t in p.corners])
    cnt = np.bincount(hits, minlength=p.n)
    sd = np.sqrt(g * F * (1 - F))
    assert np.all(np.abs(cnt - g * F) <= 4.5 * sd + 1e-9)


def test_a_glowing_room_renders_its_closed_form():
    """Every face of a closed cube emits L_e and reflects ρ = 0.6: the radiance is
    L_e / (1 − ρ) everywhere, and so is every pixel of the final gather (direct from every
    emitting patch, reflected from the gather rays), to 0.5 %."""
    sc = glowing_room()
    film, stats, sol = core.render_radiosity(sc, max_edge=0.5, method="gauss-seidel", tol=1e-8, n_vis=0,
                                             gather=16, n_shadow=4)
    assert stats.spp == 2 and not stats.cancelled
    dev = film.develop()
    np.testing.assert_allclose(dev.luminance, 10.0 / (1 - 0.6), rtol=0.005)
    assert np.all(film.sums[..., 3] == 2)
    # passes: every sample hits; the depth is a distance inside the cube; the normals are the walls'
    # (a pixel across an edge averages two perpendicular ones: length ≥ 1/√2)
    assert np.all(film.aov[..., 7] == 2)
    assert np.all((dev.depth > 0.1) & (dev.depth < math.sqrt(3)))
    assert np.all(np.linalg.norm(dev.normal, axis=-1) > 0.7)


def test_same_image_for_any_thread_count_and_cancel():
    sc = glowing_room(width=6, height=5)
    sol = core.radiosity(sc, max_edge=0.5, n_vis=1)
    a, _, _ = core.final_gather(sol, sc, gather=4, threads=1)
    b, _, _ = core.final_gather(sol, sc, gather=4, threads=2)
    np.testing.assert_array_equal(a.sums, b.sums)
    film, _, cancelled = core.final_gather(sol, sc, gather=4, should_cancel=lambda: True)
    assert cancelled and film.spp == 0
    with pytest.raises(core.SceneError, match="spp"):
        core.final_gather(sol, sc, spp=0)


def cornell_regions(h, w):
    """Pixel boxes of the Cornell box's camera view: floor, ceiling, the red (left) and green
    (right) walls and the back wall, clear of the blocks and the lamp."""
    def box(y0, y1, x0, x1):
        return slice(int(y0 * h), int(y1 * h)), slice(int(x0 * w), int(x1 * w))
    return {"floor": box(0.88, 1.0, 0.3, 0.7), "ceiling": box(0.0, 0.08, 0.1, 0.3),
            "left wall": box(0.3, 0.7, 0.0, 0.08), "right wall": box(0.3, 0.7, 0.92, 1.0),
            "back wall": box(0.3, 0.42, 0.35, 0.65)}


@pytest.mark.slow
def test_cornell_final_gather_against_the_path_tracer():
    """The diffuse Cornell box: the final-gather image (the lighting analysis' default solve,
    16 samples a pixel, 64 gather rays) against the path tracer (512 samples a pixel): mean
    luminance within 1.5 % over the pixels away from the lamp, within 3 % over the whole
    image (half of the image's mean is the lamp's few pixels, and the pixels along its edge
    take it through the pixel filter's tails, a heavy-tailed estimate at 16 samples), and
    the mean over each region (floor, ceiling, walls) within 3 %."""
    res = 48
    pt_film, _ = core.render(core.cornell_box(width=res, height=res, spp=512))
    pt = pt_film.develop().luminance
    fg_film, _, _ = core.render_radiosity(core.cornell_box(width=res, height=res, spp=16), gather=64)
    fg = fg_film.develop().luminance
    lamp = (pt > 10 * np.median(pt)) | (fg > 10 * np.median(fg))
    near = lamp.copy()  # and the pixels next to it
    for ax in (0, 1):
        for sh in (-1, 1):
            near |= np.roll(lamp, sh, axis=ax)
    assert 0 < near.sum() < 0.05 * near.size
    assert fg[~near].mean() == pytest.approx(pt[~near].mean(), rel=0.015)
    assert fg.mean() == pytest.approx(pt.mean(), rel=0.03)
    for name, (a, b) in cornell_regions(res, res).items():
        assert fg[a, b].mean() == pytest.approx(pt[a, b].mean(), rel=0.03), name
