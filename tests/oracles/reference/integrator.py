"""The reference estimator: BSDF sampling only, wavefront style in NumPy.

Per path: a camera ray (:mod:`.camera`), then at every vertex the emitted radiance of what
the ray meets (emissive triangles on their emitting side, analytic area lights in front of
the first surface), then one BSDF sample (``core.bsdfs.batch.sample``: direction and weight
f |cos θ| / pdf) that continues the path. No light sampling and no MIS: every emitter is
found by chance and counted with weight 1, which is unbiased for any emitter with area.

Depth (the scene contract's ``max_depth``, counted as the product documents it, as Cycles'
Max Bounces): the camera ray's first hit is vertex 0; a path scatters at vertices
0 .. max_depth and so has at most max_depth + 1 bounces; the emission met at vertex
max_depth + 1 (and by the rays leaving vertex max_depth) is the last that counts.
max_depth = 0 is therefore direct light: emitters seen directly plus one reflection.

Russian roulette (the reference's own, not the scene's ``rr_depth``): after ``rr_start``
scatterings a path survives with probability q = clip(max_λ β, 0.05, 1) and its weight β
is divided by q.

Wavelengths: each batch draws ``groups`` independent stratified sets of ``wavelengths``
wavelengths (:mod:`.spectral`); a path carries one set (chosen by its pixel and sample
number), and the BSDF batch kernel, which takes one spectrum per call, is called once per
material and set. The groups keep the spectral error of the batch's pixels from being one
common error.

Errors: a render is ``batches`` independent batches, each with spp / batches samples per
pixel and its own random stream (numpy's PCG64 seeded by (seed, batch)). The per-pixel
means of the batches are independent and identically distributed, so their spread gives
the standard error of the pixel's mean (and that of the whole image's mean) without
assuming independence within a batch.
"""
import contextlib
import time
from dataclasses import dataclass

import numba
import numpy as np

from spectral_gi import core
from spectral_gi.core import constants as C
from spectral_gi.core.bsdfs import batch as bsdf

from .camera import CameraModel
from .geometry import AreaLights, Triangles
from .spectral import WavelengthSampler, cmf, decode, radiance_scale

RR_MIN = 0.05
_DIELECTRICS = (C.MAT_DIELECTRIC, C.MAT_GGX_DIELECTRIC)
_UNSUPPORTED_MODELS = (C.MAT_MIX, C.MAT_ADD, C.MAT_NULL)


@dataclass
class ReferenceImage:
    luminance: np.ndarray  # (H, W) mean luminance, cd/m²
    stderr: np.ndarray  # (H, W) standard error of that mean
    XYZ: np.ndarray  # (H, W, 3) mean CIE 1931 XYZ, Y = 1 ↔ 683 cd/m²
    batch_luminance: np.ndarray  # (B, H, W) each batch's per-pixel mean luminance
    spp: int
    seconds: float

    @property
    def variance(self):
        """Variance of each pixel's mean luminance, (cd/m²)²."""
        return self.stderr ** 2

    @property
    def image_mean(self):
        return float(self.luminance.mean())

    @property
    def image_mean_stderr(self):
        """Standard error of the whole image's mean luminance (from the batches' image means)."""
        m = self.batch_luminance.reshape(self.batch_luminance.shape[0], -1).mean(axis=1)
        return float(m.std(ddof=1) / np.sqrt(m.size))


def _check_supported(scene):
    s = scene.settings
    for i, mesh in enumerate(scene.meshes):
        if mesh.normals is not None:
            raise NotImplementedError(f"reference: meshes[{i}].normals (shading normals)")
        if mesh.sensor or mesh.holdout:
            raise NotImplementedError(f"reference: meshes[{i}] is a sensor or a holdout")
    for i, m in enumerate(scene.materials):
        if m.model in _UNSUPPORTED_MODELS:
            raise NotImplementedError(f"reference: materials[{i}].model {m.model}")
        if m.holdout or m.interior >= 0 or m.base_colour_texture >= 0 or m.roughness_texture >= 0 \
                or m.normal_texture >= 0:
            raise NotImplementedError(f"reference: materials[{i}] has a holdout, a medium or a texture")
        if m.model in _DIELECTRICS and m.eta_table >= 0:
            raise NotImplementedError(f"reference: materials[{i}] is dispersive")
    if scene.media or scene.world.image is not None or s.film_transparent:
        raise NotImplementedError("reference: media, a world image or a transparent film")


class _Materials:
    """Per material: the BSDF row and the spectral lookups the batch kernel needs."""

    def __init__(self, scene):
        self.scene = scene
        self.rows = []
        self.emission_scale = []
        for m in scene.materials:
            row = np.asarray(m.params, np.float64) if m.params is not None else np.asarray(core.make_params(m.model))
            full = np.zeros(C.MATERIAL_PARAMS)
            full[:row.size] = row
            self.rows.append(full)
            emits = m.emission >= 0 and m.emission_luminance > 0.0
            self.emission_scale.append(radiance_scale(scene.spectra, m.emission, m.emission_luminance)
                                       if emits else 0.0)

    def spectra(self, lam):
        """Per material (ra, rb, eta, kappa, emitted radiance or None), each shaped as the
        wavelengths ``lam``."""
        sc = self.scene
        shape = lam.shape
        lam = lam.reshape(-1)
        ior = sc.ior_tables
        grid = C.LAMBDA_MIN + C.LAMBDA_STEP * np.arange(C.N_LAMBDA)
        out = []
        for m, scale in zip(sc.materials, self.emission_scale):
            ra = decode(sc.spectra, m.reflectance, lam) if m.reflectance >= 0 else np.zeros(lam.size)
            rb = decode(sc.spectra, m.specular, lam) if m.specular >= 0 else np.ones(lam.size)
            eta = np.interp(lam, grid, ior.values[m.eta_table]) if m.eta_table >= 0 else np.full(lam.size, m.ior)
            kappa = np.interp(lam, grid, ior.values[m.kappa_table]) if m.kappa_table >= 0 else np.zeros(lam.size)
            le = scale * decode(sc.spectra, m.emission, lam) if scale > 0.0 else None
            out.append(tuple(None if x is None else x.reshape(shape) for x in (ra, rb, eta, kappa, le)))
        return out


def _frame(n):
    """Tangent, bitangent of the orthonormal frame around unit normals n (N, 3) (Duff et al.
    2017, "Building an orthonormal basis, revisited": the product's convention, which only
    anisotropic models can tell apart from any other)."""
    sgn = np.where(n[:, 2] >= 0.0, 1.0, -1.0)
    a = -1.0 / (sgn + n[:, 2])
    b = n[:, 0] * n[:, 1] * a
    t = np.stack([1.0 + sgn * n[:, 0] ** 2 * a, sgn * b, -sgn * n[:, 0]], axis=1)
    c = np.stack([b, sgn + n[:, 1] ** 2 * a, -n[:, 1]], axis=1)
    return t, c


@contextlib.contextmanager
def _one_numba_thread():
    """The BSDF batch kernel is a parallel kernel; the reference calls it many times on small
    batches, where starting its threads costs far more than the work (tens of ms per call on
    a loaded machine), so it runs on one thread meanwhile."""
    old = numba.get_num_threads()
    numba.set_num_threads(1)
    try:
        yield
    finally:
        numba.set_num_threads(old)


def render_reference(scene, spp=None, seed=0, batches=64, wavelengths=8, groups=8, rr_start=5):
    """Render ``scene`` with the reference estimator: a :class:`ReferenceImage`.

    spp (default: the scene's) must be a multiple of ``batches``. Raises NotImplementedError
    for what the reference does not model (shading normals, textures, media, mixes, null and
    dispersive materials, holdouts, sensors, point/spot/sun lights, world images)."""
    with _one_numba_thread():
        return _render(scene, spp, seed, batches, wavelengths, groups, rr_start)


def _render(scene, spp, seed, batches, wavelengths, groups, rr_start):
    t0 = time.perf_counter()
    _check_supported(scene)
    spp = int(scene.settings.spp if spp is None else spp)
    if spp % batches:
        raise ValueError(f"reference: spp {spp} is not a multiple of batches {batches}")
    per = spp // batches
    cam = CameraModel(scene.camera, scene.settings)
    tris = Triangles(scene)
    lights = AreaLights(scene)
    mats = _Materials(scene)
    light_scale = [radiance_scale(scene.spectra, li.spectrum, li.luminance) for li in scene.lights]
    world = scene.world
    world_scale = radiance_scale(scene.spectra, world.background, world.luminance) \
        if world.background >= 0 and world.luminance > 0.0 else 0.0
    sampler = WavelengthSampler()
    max_depth = int(scene.settings.max_depth)
    h, w = cam.height, cam.width
    n_pix = h * w
    K, G = int(wavelengths), int(groups)

    pix = np.repeat(np.arange(n_pix), per)
    grp_all = (pix + np.tile(np.arange(per), n_pix)) % G  # each path's wavelength set
    lum_batches = np.zeros((batches, h, w))
    xyz_sum = np.zeros((n_pix, 3))

    for bi in range(batches):
        rng = np.random.default_rng([int(seed), bi])
        sets = [sampler.stratified(K, rng.random()) for _ in range(G)]
        lam = np.stack([s[0] for s in sets])  # (G, K)
        lam_w = np.stack([s[1] for s in sets])
        spectra = mats.spectra(lam)
        light_le = [sc * decode(scene.spectra, li.spectrum, lam.ravel()).reshape(G, K)
                    for sc, li in zip(light_scale, scene.lights)]
        world_le = world_scale * decode(scene.spectra, world.background, lam.ravel()).reshape(G, K) \
            if world_scale > 0.0 else None

        n = pix.size
        o, d = cam.rays(pix % w, pix // w, rng)
        rad = np.zeros((n, K))
        beta = np.ones((n, K))
        idx = np.arange(n)  # the live paths
        seen = np.any(d != 0.0, axis=1)  # a fisheye's pixels outside its circle see nothing
        if not seen.all():
            idx, o, d, beta = idx[seen], o[seen], d[seen], beta[seen]
        skip = np.full(idx.size, -1, np.int64)
        for depth in range(max_depth + 2):
            c = grp_all[idx]
            t, tri = tris.intersect(o, d, skip)
            for k, tl, front in lights.hits(o, d, t):
                li = scene.lights[k]
                if depth == 0 and not li.visible:
                    continue
                e = np.isfinite(tl) & (front | bool(li.two_sided))
                if np.any(e):
                    rad[idx[e]] += beta[e] * light_le[k][c[e]]
            miss = tri < 0
            if world_le is not None and np.any(miss):
                rad[idx[miss]] += beta[miss] * world_le[c[miss]]
            hit = ~miss
            idx, o, d, t, tri, beta, c = idx[hit], o[hit], d[hit], t[hit], tri[hit], beta[hit], c[hit]
            if idx.size == 0:
                break
            m = tris.material[tri]
            nrm = tris.normal[tri]
            cos_i = -np.einsum("ij,ij->i", d, nrm)
            for mi in np.unique(m):
                le = spectra[mi][4]
                if le is None:
                    continue
                sel = (m == mi) & ((cos_i > 0.0) | ((cos_i < 0.0) & bool(scene.materials[mi].two_sided)))
                if np.any(sel):
                    rad[idx[sel]] += beta[sel] * le[c[sel]]
            if depth == max_depth + 1:
                break
            # scatter: one BSDF sample per path, in the frame around the geometric normal
            p = o + t[:, None] * d
            tg, bt = _frame(nrm)
            wo = -np.stack([np.einsum("ij,ij->i", d, tg), np.einsum("ij,ij->i", d, bt), -cos_i], axis=1)
            u = rng.random((idx.size, 3))
            wi = np.zeros((idx.size, 3))
            weight = np.zeros((idx.size, K))
            ok = np.zeros(idx.size, bool)
            key = m * G + c
            for kk in np.unique(key):
                mi, g = divmod(int(kk), G)
                r = np.nonzero(key == kk)[0]
                ra, rb, eta, kappa, _ = spectra[mi]
                wi[r], weight[r], _pdf, fl = bsdf.sample(scene.materials[mi].model, mats.rows[mi], ra[g], rb[g],
                                                         eta[g], kappa[g], wo[r], u[r])
                ok[r] = fl != 0
            beta = beta * weight
            d = wi[:, 0:1] * tg + wi[:, 1:2] * bt + wi[:, 2:3] * nrm
            d /= np.linalg.norm(d, axis=1, keepdims=True)
            o = p
            skip = tri
            live = ok & np.any(beta > 0.0, axis=1)
            if depth + 1 >= rr_start:
                q = np.clip(beta.max(axis=1), RR_MIN, 1.0)
                live &= rng.random(idx.size) < q
                beta = beta / q[:, None]
            idx, o, d, beta, skip = idx[live], o[live], d[live], beta[live], skip[live]
            if idx.size == 0:
                break
        # each path's XYZ estimate: Σ_k L(λ_k) cmf(λ_k) / (K p(λ_k))
        cw = cmf(lam) * lam_w[..., None]  # (G, K, 3)
        xyz = np.einsum("nk,nkj->nj", rad, cw[grp_all])
        sums = np.stack([np.bincount(pix, weights=xyz[:, j], minlength=n_pix) for j in range(3)], axis=1)
        xyz_sum += sums
        lum_batches[bi] = (C.K_M * sums[:, 1] / per).reshape(h, w)

    lum = lum_batches.mean(axis=0)
    se = lum_batches.std(axis=0, ddof=1) / np.sqrt(batches)
    return ReferenceImage(luminance=lum, stderr=se, XYZ=(xyz_sum / spp).reshape(h, w, 3),
                          batch_luminance=lum_batches, spp=spp, seconds=time.perf_counter() - t0)
