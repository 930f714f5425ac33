"""The emitters record: analytic lights, emissive triangles and the world, and the
distribution next-event estimation picks them from, as the path kernel reads them."""
from __future__ import annotations

from typing import NamedTuple

import numpy as np

from .. import constants as C
from ..io import presets
from ..scene import SceneError


class EmitterRecord(NamedTuple):
    """L analytic lights, the emitter table of E entries (emissive triangles in leaf order,
    then the world image if it emits, then the L lights) and the world.

    light_kind: int32 (L,) LIGHT_* tag of each light.
    light_geo: float64 (L, LG_SIZE) each light's geometry (layout in core/lights/kernel.py).
    light_prof: float64 (≥ 1,) the photometric profiles of the lights that have one,
        concatenated (offsets in light_geo column LG_PROF; ``profile_table``).
    light_spec: int32 (L,) row of the spectrum table of each light's spectrum shape.
    light_scale: float64 (L,) factor turning that shape into the light's spectral radiance
        (or intensity, or illuminance, for delta lights).
    light_two_sided, light_visible: int32 (L,) 1: an area light emits on both sides; the
        light is seen by camera rays.
    emit_cdf: float64 (E + 1,) the cumulative distribution of the emitter table, in
        proportion to luminous flux (one 0 when nothing emits: the kernel then skips NEE).
    emit_prob: float64 (E,) each emitter's probability; analytic light li is entry
        E - L + li.
    emit_tri: int32 (E,) the triangle (leaf order) of each entry, -1 for the others.
    emit_light: int32 (E,) the light of each entry, -2 the world image, -1 a triangle.
    world_spec: int, row of the spectrum table of the world's constant radiance (-1 none);
        world_scale: float, the factor turning it into spectral radiance.
    world_img: float32 (H, W, 3) the equirectangular world image (linear Rec.709), whose
        texel rgb weighs the three emission basis rows world_row.. of the spectrum table;
        a (1, 1, 3) dummy without one.
    world_dist: float64 the image's 2D sampling distribution (core/sampling build_distribution_2d).
    world_par: float64 (4,) cos and sin of the image's rotation, its scale, and 1 when the
        image is used (0: none).
    world_row: int, the first emission basis row (``world_emission_basis``).
    world_emit: int, the image's entry in the emitter table (-1: not in it).
    """

    light_kind: np.ndarray
    light_geo: np.ndarray
    light_prof: np.ndarray
    light_spec: np.ndarray
    light_scale: np.ndarray
    light_two_sided: np.ndarray
    light_visible: np.ndarray
    emit_cdf: np.ndarray
    emit_prob: np.ndarray
    emit_tri: np.ndarray
    emit_light: np.ndarray
    world_spec: int
    world_scale: float
    world_img: np.ndarray
    world_dist: np.ndarray
    world_par: np.ndarray
    world_row: int
    world_emit: int


def pack(scene, spec, cmf, bvh, tri_mat, mat_emis, mat_emis_two, scene_radius):
    """(record, tri_emitter, spec): ``scene``'s emitters. ``spec`` the
    spectrum table (the scene's rows), returned with the world image's emission basis rows
    appended when it has one; bvh, tri_mat (leaf order) and the materials' emission rows
    and sides find the emissive triangles; tri_emitter (int32 (T,)) is each triangle's entry
    in the emitter table (-1 none)."""
    light_kind, light_geo, light_spec, light_scale, light_two, light_vis, light_power, prof_parts = \
        analytic_lights(scene, spec, cmf, scene_radius)
    em_tris, power_tri = emissive_triangles(scene, bvh, tri_mat, mat_emis, mat_emis_two)
    # the world image: one more emitter, between the triangles and the analytic lights
    world_img, world_dist, world_par, world_basis, power_world = world_image(scene.world, cmf, scene_radius)
    world_row = spec.shape[0]
    if world_basis is not None:
        spec = np.concatenate([spec, world_basis.astype(np.float32)])
    cdf, prob, emit_tri, emit_light, world_emit, tri_emitter = distribution(
        em_tris, power_tri, power_world, light_power, tri_mat.size)
    world_spec, world_scale = world_constant(scene, spec, cmf)
    light_prof = np.ascontiguousarray(np.concatenate(prof_parts) if prof_parts else np.zeros(1))
    rec = EmitterRecord(light_kind, light_geo, light_prof, light_spec, light_scale, light_two, light_vis, cdf,
                        np.ascontiguousarray(prob), emit_tri, emit_light, int(world_spec), float(world_scale),
                        world_img, world_dist, world_par, int(world_row), int(world_emit))
    return rec, tri_emitter, spec


def analytic_lights(scene, spec, cmf, scene_radius):
    """The analytic lights' tables (row layout and units: core/lights/kernel.py): (kind,
    geo, spectrum row, scale, two-sided, visible, luminous flux in lm, profile tables)."""
    from ..photometry.units import luminance_scale
    from . import kernel as LG

    n_l = len(scene.lights)
    light_kind = np.zeros(n_l, np.int32)
    light_geo = np.zeros((n_l, LG.LG_SIZE))
    light_spec = np.zeros(n_l, np.int32)
    light_scale = np.zeros(n_l)
    light_two = np.zeros(n_l, np.int32)
    light_vis = np.zeros(n_l, np.int32)
    light_power = np.zeros(n_l)
    light_geo[:, LG.LG_PROF] = -1.0
    prof_parts = []
    prof_len = 0
    for i, li in enumerate(scene.lights):
        what = f"lights[{i}] ({li.name!r})"
        kind = int(li.kind)
        light_kind[i] = kind
        light_geo[i, LG.LG_POS:LG.LG_POS + 3] = li.position
        light_spec[i] = li.spectrum
        light_two[i] = 1 if li.two_sided else 0
        light_vis[i] = 1 if li.visible else 0
        shape = spec[li.spectrum]
        if kind in (C.LIGHT_RECT, C.LIGHT_ELLIPSE):
            u = np.asarray(li.axis_u, np.float64)
            v = np.asarray(li.axis_v, np.float64)
            n = np.cross(u, v)
            rect_area = 4.0 * np.linalg.norm(n)
            area = rect_area if kind == C.LIGHT_RECT else rect_area * np.pi / 4.0
            light_geo[i, LG.LG_U:LG.LG_U + 3] = u
            light_geo[i, LG.LG_V:LG.LG_V + 3] = v
            light_geo[i, LG.LG_N:LG.LG_N + 3] = n / np.linalg.norm(n)
            light_geo[i, LG.LG_AREA] = area
            light_scale[i] = luminance_scale(shape, cmf, li.luminance, what)
            light_power[i] = np.pi * li.luminance * area * (2.0 if li.two_sided else 1.0)  # lm
        elif kind in (C.LIGHT_POINT, C.LIGHT_SPOT):
            r = float(li.radius)
            inten = float(li.intensity)
            light_geo[i, LG.LG_RADIUS] = r
            # a sphere of radius r with radiance I / (π r²) has intensity I in every direction
            light_scale[i] = luminance_scale(shape, cmf, inten / (np.pi * r * r) if r > 0 else inten, what)
            if kind == C.LIGHT_POINT:
                light_power[i] = 4.0 * np.pi * inten
            else:
                d = np.asarray(li.direction, np.float64)
                light_geo[i, LG.LG_N:LG.LG_N + 3] = d / np.linalg.norm(d)
                ch = float(np.cos(0.5 * li.spot_angle))
                blend = float(li.spot_blend)
                light_geo[i, LG.LG_COS_HALF] = ch
                light_geo[i, LG.LG_SMOOTH] = 1.0 / ((1.0 - ch) * blend) if blend > 0 and ch < 1 else 0.0
                # ∫ mask dω = 2π ∫_{cos½}^1 mask dt, and smoothstep over its ramp averages 1/2
                light_power[i] = 2.0 * np.pi * inten * (1.0 - ch) * (1.0 - 0.5 * blend)
            if li.profile >= 0:
                table, peak_cd, light_power[i] = profile_table(scene, li, what, light_geo[i], LG)
                light_scale[i] = luminance_scale(shape, cmf, peak_cd / (np.pi * r * r) if r > 0 else peak_cd, what)
                light_geo[i, LG.LG_PROF] = prof_len
                prof_parts.append(table)
                prof_len += table.size
        else:  # sun
            d = np.asarray(li.direction, np.float64)
            light_geo[i, LG.LG_N:LG.LG_N + 3] = -d / np.linalg.norm(d)  # towards the sun
            half = 0.5 * float(li.angle)
            k = 2.0 * np.sin(0.5 * half) ** 2  # 1 - cos(half), exact for tiny angles
            light_geo[i, LG.LG_SUN_K] = k
            e = float(li.illuminance)
            light_scale[i] = luminance_scale(shape, cmf, e / (np.pi * np.sin(half) ** 2) if k > 0 else e, what)
            # the flux the sun sends through the disc of the scene's bounding sphere
            light_power[i] = e * np.pi * scene_radius ** 2
    return light_kind, light_geo, light_spec, light_scale, light_two, light_vis, light_power, prof_parts


def emissive_triangles(scene, bvh, tri_mat, mat_emis, mat_emis_two):
    """(leaf indices int32, luminous flux in lm) of the emissive triangles: π L A per side."""
    e1 = bvh.e1.astype(np.float64)
    e2 = bvh.e2.astype(np.float64)
    tri_area = 0.5 * np.linalg.norm(np.cross(e1, e2), axis=1)
    emissive = (mat_emis[tri_mat] >= 0) & (tri_area > 0) if tri_mat.size else np.zeros(0, bool)
    em_tris = np.nonzero(emissive)[0].astype(np.int32)
    lum = np.array([m.emission_luminance for m in scene.materials] or [0.0])
    power_tri = np.pi * lum[tri_mat[em_tris]] * tri_area[em_tris] * (1.0 + mat_emis_two[tri_mat[em_tris]])
    return em_tris, power_tri


def distribution(em_tris, power_tri, power_world, power_light, n_tris):
    """The emitter distribution, proportional to luminous flux: (cdf, prob, emit_tri,
    emit_light, world_emit, tri_emitter) over the emissive triangles, the world image (if
    power_world > 0) and the analytic lights, in this order."""
    n_l = power_light.size
    n_world = 1 if power_world > 0 else 0
    power = np.concatenate([power_tri, [power_world] * n_world, power_light])
    emit_tri = np.concatenate([em_tris, np.full(n_world + n_l, -1, np.int32)])
    emit_light = np.concatenate([np.full(em_tris.size, -1, np.int32), np.full(n_world, -2, np.int32),
                                 np.arange(n_l, dtype=np.int32)])
    world_emit = int(em_tris.size) if n_world else -1
    # lights with zero power stay in the table (their index is fixed) with zero probability
    total = power.sum()
    if total > 0:
        prob = power / total
    else:
        prob = np.zeros_like(power)
    cdf = np.concatenate([[0.0], np.cumsum(prob)])
    if total > 0:
        cdf[-1] = 1.0
    else:
        # no emitters with power: an empty distribution (the kernel then skips NEE)
        prob = np.zeros(0)
        cdf = np.zeros(1)
        emit_tri = np.zeros(0, np.int32)
        emit_light = np.zeros(0, np.int32)
        world_emit = -1
    tri_emitter = np.full(n_tris, -1, np.int32)
    if total > 0:
        tri_emitter[em_tris] = np.arange(em_tris.size, dtype=np.int32)
    return cdf, prob, emit_tri, emit_light, world_emit, tri_emitter


def world_constant(scene, spec, cmf):
    """(world_spec, world_scale) of the world's constant radiance (-1, 0: none)."""
    from ..photometry.units import luminance_scale

    world_spec = int(scene.world.background)
    world_scale = 0.0
    if world_spec >= 0:
        world_scale = luminance_scale(spec[world_spec], cmf, scene.world.luminance, "world")
        if world_scale == 0.0:
            world_spec = -1
    return world_spec, world_scale


def world_emission_basis(cmf=None):
    """(3, N_LAMBDA) spectral radiance per unit of linear Rec.709 r, g and b of a world image.

    The Mallett–Yuksel (2019) basis, the reflectance uplift core.spectra.uplift uses
    (r·B_r + g·B_g + b·B_b, non-negative, flat for white), times CIE D65, tabulated on the
    renderer's 1 nm grid and scaled so that white (1, 1, 1) has film Y = 1, i.e. 683 cd/m²,
    Blender's RGB 1. The uplift is linear in the colour, so a texel's spectrum is its rgb
    times these rows: the same as uplifting rgb/max and scaling by max, with no per-texel
    coefficients (memory: the image itself). Returns (basis, Y of each row).
    """
    from ..film.record import cmf_table, v_lambda
    from ..spectra import moments

    if cmf is None:
        cmf = cmf_table()
    wl, basis = presets.mallett2019_basis()
    dwl, d65 = presets.illuminant("D65")
    grid = moments.grid()
    rows = np.stack([np.interp(grid, wl, basis[:, k]) for k in range(3)]) * np.interp(grid, dwl, d65)[None, :]
    y = rows.astype(np.float64) @ v_lambda(cmf).astype(np.float64) * C.LAMBDA_STEP
    rows /= y.sum()
    return rows, y / y.sum()


def filtered_cell_means(f):
    """The mean over each texel of the bilinear interpolation of the (H, W) map ``f`` between
    texel centres, periodic on both axes (core/lights/kernel.py env_texel): on each axis the
    cell's mean is (f[i−1] + 6 f[i] + f[i+1]) / 8 (each half of the cell is a linear ramp to
    the neighbour's centre, whose mean weight is ¼ there)."""
    f = np.asarray(f, np.float64)
    g = 0.75 * f + 0.125 * (np.roll(f, 1, axis=1) + np.roll(f, -1, axis=1))
    return 0.75 * g + 0.125 * (np.roll(g, 1, axis=0) + np.roll(g, -1, axis=0))


def world_image(world, cmf, scene_radius):
    """Kernel arrays of the world image: (img, distribution, par, basis rows or None, flux in lm)."""
    from ..sampling import build_distribution_2d

    img = world.image
    if img is None or not world.image_scale > 0 or not float(np.max(img)) > 0:
        return np.zeros((1, 1, 3), np.float32), np.zeros(8), np.zeros(4), None, 0.0
    img = np.ascontiguousarray(img, np.float32)
    h, w = img.shape[:2]
    basis, y = world_emission_basis(cmf)
    # cd/m² of the bilinearly filtered map (core/lights/kernel.py env_texel) averaged over each texel
    lum = C.K_M * float(world.image_scale) * filtered_cell_means(img.astype(np.float64) @ y)
    theta = np.pi * (np.arange(h) + 0.5) / h
    dist = build_distribution_2d(lum * np.sin(theta)[:, None])
    # ∫ L dω over the sphere, per texel 2π/w · (cos θ0 − cos θ1)
    edges = np.cos(np.pi * np.arange(h + 1) / h)
    flux_density = float(np.sum(lum * ((edges[:-1] - edges[1:]) * 2 * np.pi / w)[:, None]))
    par = np.array([np.cos(world.rotation), np.sin(world.rotation), float(world.image_scale), 1.0])
    return img, dist, par, basis, flux_density * np.pi * scene_radius ** 2


def profile_table(scene, li, what, geo_row, LG):
    """A profiled point/spot light: (kernel table, candela at the profile's peak, flux in lm).

    Fills the light's frame into ``geo_row`` (LG_N nadir = its direction, LG_U / LG_V its
    local +X / +Y) and returns the table laid out as core/lights/kernel.py reads it.
    profile_mode "file" keeps the profile's candela, "peak" scales its maximum to
    ``intensity``, "flux" scales ∫ I · spot mask dω to ``flux`` lm.
    """
    from ..photometry.profiles import flux as profile_flux
    from ..photometry.units import spot_falloff

    pr = scene.profiles[li.profile]
    n = np.asarray(li.direction, np.float64)
    n = n / np.linalg.norm(n)
    u = np.asarray(li.axis_u, np.float64)
    u = u - (u @ n) * n
    u /= np.linalg.norm(u)
    v = np.cross(-n, u)  # local +Y = +Z × +X with +Z = −nadir
    geo_row[LG.LG_N:LG.LG_N + 3] = n
    geo_row[LG.LG_U:LG.LG_U + 3] = u
    geo_row[LG.LG_V:LG.LG_V + 3] = v
    peak = float(pr.candela.max()) if pr.candela.size else 0.0
    mask = None
    if li.kind == C.LIGHT_SPOT:
        mask = lambda mu: spot_falloff(mu, li.spot_angle, li.spot_blend)  # noqa: E731
    phi_file = profile_flux(pr, mask)  # lm of the profile as given (spot mask included)
    if li.profile_mode == "file":
        k = 1.0
    elif li.profile_mode == "peak":
        k = float(li.intensity) / peak if peak > 0 else 0.0
    else:
        if not phi_file > 0.0 and li.flux > 0.0:
            raise SceneError(f"{what}.profile: profile {pr.name!r} emits no light"
                             + (" inside the spot's cone" if mask is not None else "")
                             + ", so it cannot be scaled to a flux")
        k = float(li.flux) / phi_file if phi_file > 0 else 0.0
    norm = pr.candela / peak if peak > 0 else pr.candela
    table = np.concatenate([[pr.theta.size, pr.phi.size], np.radians(pr.theta), np.radians(pr.phi),
                            norm.reshape(-1)])
    return table, k * peak, k * phi_file
