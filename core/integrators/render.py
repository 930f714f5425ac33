"""Render a scene: prepare arrays, build the BVH, run passes of the path tracer.

``render(scene, progress=, should_cancel=, on_pass=)`` is what the CLI and the
Blender add-on call. Progress and cancellation cross as plain callables. The path
kernel is serial and releases the GIL; a pool of Python threads runs blocks of rows.
The few parallel (prange) kernels that remain, the batch tools in ``accel``, are
launched under one process-wide lock: numba's threading layers abort the process when
two threads launch parallel kernels at once, which would take Blender down with them.
"""
from __future__ import annotations

import gc
import os
import time
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass

import numpy as np

from .. import constants as C
from ..io import presets
from . import warmup
from ..geometry.accel import build as build_bvh
from ..film import Film
from ..scene import Material, Scene, SceneError, validate
from ..spectra import moments
from .warmup import kernels_compiled


# Target wall time of one pass, so progress and cancel stay live (architecture: 0.1–0.5 s).
PASS_SECONDS = 0.3


@dataclass
class Prepared:
    """Everything a render kernel reads, as contiguous arrays."""

    scene: Scene
    bvh: object
    tri_mat: np.ndarray
    tri_emitter: np.ndarray
    mat_model: np.ndarray
    mat_p: np.ndarray
    mat_ra: np.ndarray
    mat_rb: np.ndarray
    mat_eta: np.ndarray
    mat_kappa: np.ndarray
    mat_ior: np.ndarray
    ior_tab: np.ndarray
    mat_emis: np.ndarray
    mat_emis_scale: np.ndarray
    mat_emis_two: np.ndarray
    spec: np.ndarray
    cmf: np.ndarray
    light_kind: np.ndarray
    light_geo: np.ndarray
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
    cam: np.ndarray
    filt: np.ndarray
    tri_nrm: np.ndarray
    spec_alb: np.ndarray
    scene_scale: float
    build_seconds: float
    mat_medium: np.ndarray = None  # int32 (K,): interior medium of each material, -1 none
    med_tab: np.ndarray = None  # float64 (2 M, N_LAMBDA): σa, σs rows (1/m); (0, N_LAMBDA) without media
    med_g: np.ndarray = None  # float64 (M,): Henyey–Greenstein g
    cam_medium: int = -1  # the medium around the camera
    light_prof: np.ndarray = None  # float64: photometric profiles, concatenated (core/kernels/lights.py)
    tri_flag: np.ndarray = None  # int8 (T,) leaf order: 1 sensor, 2 holdout; (0,) when no triangle has a flag
    sensor_mat: int = -1  # ≥ 0: measuring mode, the index of the white two-sided Lambert sensors take
    film_transparent: int = 0  # camera rays that miss leave the pixel transparent
    # image textures (core/textures.py, core/kernels/textures.py)
    tri_tex: np.ndarray = None  # float32 (T, 10) leaf-order corner UVs + tangent frame; (0, 10) untextured
    tex_data: np.ndarray = None  # float32 (N,) all texels
    tex_info: np.ndarray = None  # int64 (K, 6) offset, width, height, channels, interpolation, extension
    mat_tex: np.ndarray = None  # int32 (K, 3) base colour, roughness, normal texture per material (-1 none)
    mat_nstr: np.ndarray = None  # float64 (K,) normal-map strength per material
    tex_row: int = -1  # first of the three reflectance basis rows in ``spec`` (-1: none)


def cmf_table(observer="1931"):
    """CIE colour-matching functions on the renderer's grid: float32 (N_LAMBDA, 3) for the
    CIE 1931 observer; for another observer (N_LAMBDA, 4): its x̄, ȳ, z̄ and V(λ) (the 1931
    ȳ), which photometry keeps using (see core/film.py and the path kernel)."""
    from ..film import check_observer

    observer = check_observer(observer)
    grid = moments.grid()
    wl, xyz = presets.cmfs(observer)
    cols = [np.interp(grid, wl, xyz[:, k], left=0, right=0) for k in range(3)]
    if observer != "1931":
        wl1, xyz1 = presets.cmfs("1931")
        cols.append(np.interp(grid, wl1, xyz1[:, 1], left=0, right=0))
    return np.ascontiguousarray(np.stack(cols, axis=1), np.float32)


def v_lambda(cmf):
    """The V(λ) column of a cmf_table: column 3 if present, else ȳ (CIE 1931)."""
    return cmf[:, 3] if cmf.shape[1] > 3 else cmf[:, 1]


def camera_vector(cam, settings=None):
    """Pack a Camera into the float64[CAM_SIZE] the kernel reads (Blender's sensor-fit rules;
    layout in core/kernels/camera.py)."""
    from ..camera import kernel as K

    w, h = float(cam.width), float(cam.height)
    fit = cam.sensor_fit
    if fit == C.FIT_AUTO:
        fit = C.FIT_HORIZONTAL if w >= h else C.FIT_VERTICAL
        size = cam.sensor_width_mm  # AUTO: sensor width applies to the larger dimension
    else:
        size = cam.sensor_width_mm if fit == C.FIT_HORIZONTAL else cam.sensor_height_mm
    if cam.projection == C.CAM_ORTHOGRAPHIC:
        half = 0.5 * cam.ortho_scale  # metres along the fitted axis (AUTO: the larger side)
    else:
        half = 0.5 * size / cam.lens_mm
    if fit == C.FIT_HORIZONTAL:
        half_w, half_h = half, half * h / w
    else:
        half_w, half_h = half * w / h, half
    extent = 2.0 * max(half_w, half_h)  # Blender's shift is in units of the larger dimension
    m = np.asarray(cam.to_world, dtype=np.float64)
    rot = m[:3, :3] / np.linalg.norm(m[:3, :3], axis=0)[None, :]
    v = np.zeros(K.CAM_SIZE)
    v[0:9] = rot.reshape(-1)
    v[9:12] = m[:3, 3]
    v[K.CAM_HALF_W] = half_w
    v[K.CAM_HALF_H] = half_h
    v[K.CAM_OFF_X] = cam.shift_x * extent
    v[K.CAM_OFF_Y] = cam.shift_y * extent
    v[K.CAM_PROJ] = cam.projection
    # thin lens: aperture radius = focal length / (2 f-number), in metres (as Cycles)
    v[K.CAM_LENS_R] = 0.001 * cam.lens_mm / (2.0 * cam.fstop) if cam.fstop > 0 else 0.0
    v[K.CAM_FOCUS] = cam.focus_distance
    v[K.CAM_FILTER_W] = settings.filter_width if settings is not None else 1.0
    return v


def filter_distribution(settings):
    """The pixel filter's 1D distribution (box of 1 px when ``settings`` is None)."""
    from ..camera.kernel import filter_table

    if settings is None:
        return filter_table(C.FILTER_BOX, 1.0)
    return filter_table(int(settings.filter), float(settings.filter_width))


def _luminance_scale(shape_row, cmf, luminance, what):
    """Factor turning a spectrum shape into spectral radiance W/(m² sr nm) of ``luminance`` cd/m²."""
    y = float(np.sum(shape_row.astype(np.float64) * v_lambda(cmf)) * C.LAMBDA_STEP)
    if luminance == 0.0:
        return 0.0
    if not y > 0.0:
        raise SceneError(f"{what}: its spectrum has no visible power, so a luminance cannot be set")
    return luminance / (C.K_M * y)


def material_row(m, index=0):
    """The float64[16] parameter row of a material (its ``params``, or its model's defaults)."""
    from ..bsdfs.params import make_params

    row = np.zeros(C.MATERIAL_PARAMS)
    if m.params is not None:
        p = np.asarray(m.params, dtype=np.float64).reshape(-1)
        row[:p.size] = p
        return row
    if m.model == C.MAT_NULL:
        return row
    if m.model in (C.MAT_MIX, C.MAT_ADD):
        raise SceneError(f"materials[{index}] ({m.name!r}).params: a mix needs its parameters")
    try:
        return np.asarray(make_params(m.model), dtype=np.float64)
    except (TypeError, ValueError) as e:
        raise SceneError(f"materials[{index}] ({m.name!r}).params: model {m.model} needs parameters ({e})") \
            from None


def media_tables(scene: Scene, spec):
    """(mat_medium, med_tab, med_g) for the kernel: the coefficient rows σa = density × shape
    (1 where the shape is -1) and σs likewise, per medium, on the 1 nm grid.

    Without media and null surfaces med_tab has no rows and the kernel skips all media code.
    """
    n_mat = max(1, len(scene.materials))
    mat_medium = np.full(n_mat, -1, np.int32)
    for i, m in enumerate(scene.materials):
        mat_medium[i] = m.interior
    has_null = any(m.model == C.MAT_NULL for m in scene.materials)
    if not scene.media and not has_null:
        return mat_medium, np.zeros((0, C.N_LAMBDA)), np.zeros(1)
    n = max(1, len(scene.media))
    tab = np.zeros((2 * n, C.N_LAMBDA))
    g = np.zeros(n)
    for k, md in enumerate(scene.media):
        for r, (idx, dens) in enumerate(((md.absorption, md.absorption_density),
                                         (md.scattering, md.scattering_density))):
            shape = spec[idx].astype(np.float64) if idx >= 0 else np.ones(C.N_LAMBDA)
            tab[2 * k + r] = dens * np.maximum(shape, 0.0)
        g[k] = md.anisotropy
    return mat_medium, np.ascontiguousarray(tab), g


def camera_medium(scene: Scene, v0, v1, v2, tri_mat_orig, mat_medium):
    """The medium around the camera: along a few fixed directions, the nearest surface
    whose material has an interior medium; seen from its back side, the camera is inside.
    (One level of nesting, as the kernel tracks.) The majority of the directions decides,
    so a ray through an edge cannot."""
    from ..geometry.accel import build, closest

    bound = np.nonzero(mat_medium[tri_mat_orig] >= 0)[0] if tri_mat_orig.size else np.zeros(0, np.int64)
    if bound.size == 0:
        return -1
    eye = np.asarray(scene.camera.to_world, np.float64)[:3, 3]
    dirs = np.array([[0.2673, 0.5345, 0.8018], [-0.7071, 0.3015, -0.6396], [0.4364, -0.8729, 0.2182]])
    dirs /= np.linalg.norm(dirs, axis=1)[:, None]
    a, b, c = v0[bound], v1[bound], v2[bound]
    t, hit = closest(build(a.astype(np.float32), b.astype(np.float32), c.astype(np.float32)),
                     np.repeat(eye[None], 3, 0), dirs)
    votes = []
    for k in range(3):
        if hit[k] < 0:
            votes.append(-1)
            continue
        j = bound[hit[k]]
        n = np.cross(v1[j] - v0[j], v2[j] - v0[j])
        votes.append(int(mat_medium[tri_mat_orig[j]]) if np.dot(n, dirs[k]) > 0 else -1)
    return max(set(votes), key=votes.count)


def world_emission_basis(cmf=None):
    """(3, N_LAMBDA) spectral radiance per unit of linear Rec.709 r, g and b of a world image.

    The Mallett–Yuksel (2019) basis, the reflectance uplift core.spectra.uplift uses
    (r·B_r + g·B_g + b·B_b, non-negative, flat for white), times CIE D65, tabulated on the
    renderer's 1 nm grid and scaled so that white (1, 1, 1) has film Y = 1, i.e. 683 cd/m²,
    Blender's RGB 1. The uplift is linear in the colour, so a texel's spectrum is its rgb
    times these rows: the same as uplifting rgb/max and scaling by max, with no per-texel
    coefficients (memory: the image itself). Returns (basis, Y of each row).
    """
    if cmf is None:
        cmf = cmf_table()
    wl, basis = presets.mallett2019_basis()
    dwl, d65 = presets.illuminant("D65")
    grid = moments.grid()
    rows = np.stack([np.interp(grid, wl, basis[:, k]) for k in range(3)]) * np.interp(grid, dwl, d65)[None, :]
    y = rows.astype(np.float64) @ v_lambda(cmf).astype(np.float64) * C.LAMBDA_STEP
    rows /= y.sum()
    return rows, y / y.sum()


def _world_image(world, cmf, scene_radius):
    """Kernel arrays of the world image: (img, distribution, par, basis rows or None, flux in lm)."""
    from ..sampling import build_distribution_2d

    img = world.image
    if img is None or not world.image_scale > 0 or not float(np.max(img)) > 0:
        return np.zeros((1, 1, 3), np.float32), np.zeros(8), np.zeros(4), None, 0.0
    img = np.ascontiguousarray(img, np.float32)
    h, w = img.shape[:2]
    basis, y = world_emission_basis(cmf)
    lum = C.K_M * float(world.image_scale) * (img.astype(np.float64) @ y)  # cd/m² per texel
    theta = np.pi * (np.arange(h) + 0.5) / h
    dist = build_distribution_2d(lum * np.sin(theta)[:, None])
    # ∫ L dω over the sphere, per texel 2π/w · (cos θ0 − cos θ1)
    edges = np.cos(np.pi * np.arange(h + 1) / h)
    flux_density = float(np.sum(lum * ((edges[:-1] - edges[1:]) * 2 * np.pi / w)[:, None]))
    par = np.array([np.cos(world.rotation), np.sin(world.rotation), float(world.image_scale), 1.0])
    return img, dist, par, basis, flux_density * np.pi * scene_radius ** 2


def _shading_normals(scene, bvh):
    """float32 (T, 9): each triangle's three vertex normals in leaf order (the geometric
    normal for meshes without normals), or (0, 9) when no mesh has normals."""
    if not any(m.normals is not None for m in scene.meshes):
        return np.zeros((0, 9), np.float32)
    parts = []
    for mesh in scene.meshes:
        idx = mesh.indices
        if mesh.normals is not None:
            parts.append(mesh.normals.astype(np.float64)[idx].reshape(-1, 9))
        else:
            p = mesh.positions.astype(np.float64)
            ng = np.cross(p[idx[:, 1]] - p[idx[:, 0]], p[idx[:, 2]] - p[idx[:, 0]])
            ln = np.linalg.norm(ng, axis=1, keepdims=True)
            ng = np.divide(ng, ln, out=np.zeros_like(ng), where=ln > 0)
            parts.append(np.tile(ng, 3))
    return np.ascontiguousarray(np.concatenate(parts)[bvh.prims], np.float32)


def _scene_radius(v0, v1, v2):
    """Radius of a sphere around every triangle (1 m for an empty scene)."""
    if not v0.size:
        return 1.0
    pts = np.concatenate([v0, v1, v2])
    lo, hi = pts.min(axis=0), pts.max(axis=0)
    return max(0.5 * float(np.linalg.norm(hi - lo)), 1e-3)


def _profile_table(scene, li, what, geo_row, LG):
    """A profiled point/spot light: (kernel table, candela at the profile's peak, flux in lm).

    Fills the light's frame into ``geo_row`` (LG_N nadir = its direction, LG_U / LG_V its
    local +X / +Y) and returns the table laid out as core/kernels/lights.py reads it.
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


def _triangle_flags(scene, bvh, tri_mat_orig, measure):
    """int8 (T,) flags in leaf order (1: sensor, 2: holdout from the mesh or its material),
    or (0,) when nothing is flagged (the kernel then skips the test)."""
    parts = []
    hold_mat = np.array([bool(m.holdout) for m in scene.materials] or [False])
    for mesh in scene.meshes:
        n = mesh.indices.shape[0]
        parts.append(np.full(n, (1 if mesh.sensor else 0) | (2 if mesh.holdout else 0), np.int8))
    flags = np.concatenate(parts) if parts else np.zeros(0, np.int8)
    if flags.size:
        flags |= np.where(hold_mat[tri_mat_orig], 2, 0).astype(np.int8)
    if measure and not np.any(flags & 1):
        raise SceneError("meshes: an illuminance render needs at least one mesh with sensor = True")
    if not np.any(flags):
        return np.zeros(0, np.int8)
    return np.ascontiguousarray(flags[bvh.prims], np.int8)


def prepare(scene: Scene, measure=False) -> Prepared:
    """The kernel's arrays for ``scene``. measure=True prepares the illuminance render of
    its sensor meshes (core/sensors.py): one more material, a white (ρ = 1) two-sided
    Lambert, that the camera ray's first hit on a sensor takes instead of its own."""
    validate(scene)
    t0 = time.perf_counter()
    cmf = cmf_table(scene.settings.observer)
    spec = moments.tabulate(scene.spectra.coeffs, scene.spectra.kind) if len(scene.spectra) else \
        np.zeros((1, C.N_LAMBDA), np.float32)

    # concatenate meshes
    v0s, v1s, v2s, mats = [], [], [], []
    for mesh in scene.meshes:
        p = mesh.positions.astype(np.float64)
        idx = mesh.indices
        v0s.append(p[idx[:, 0]])
        v1s.append(p[idx[:, 1]])
        v2s.append(p[idx[:, 2]])
        mats.append(mesh.material)
    if v0s:
        v0 = np.concatenate(v0s)
        v1 = np.concatenate(v1s)
        v2 = np.concatenate(v2s)
        tri_mat_orig = np.concatenate(mats).astype(np.int32)
    else:
        v0 = v1 = v2 = np.zeros((0, 3))
        tri_mat_orig = np.zeros(0, np.int32)
    bvh = build_bvh(v0, v1, v2)
    tri_mat = np.ascontiguousarray(tri_mat_orig[bvh.prims], np.int32)

    n_mat = max(1, len(scene.materials))
    mat_model = np.zeros(n_mat, np.int32)
    mat_p = np.zeros((n_mat, C.MATERIAL_PARAMS))
    mat_ra = np.full(n_mat, -1, np.int32)
    mat_rb = np.full(n_mat, -1, np.int32)
    mat_eta = np.full(n_mat, -1, np.int32)
    mat_kappa = np.full(n_mat, -1, np.int32)
    mat_ior = np.full(n_mat, 1.5)
    mat_emis = np.full(n_mat, -1, np.int32)
    mat_emis_scale = np.zeros(n_mat)
    mat_emis_two = np.ones(n_mat, np.int32)
    for i, m in enumerate(scene.materials):
        mat_model[i] = m.model
        mat_p[i] = material_row(m, i)
        mat_ra[i] = m.reflectance
        mat_rb[i] = m.specular
        mat_eta[i] = m.eta_table
        mat_kappa[i] = m.kappa_table
        mat_ior[i] = m.ior
        mat_emis_two[i] = 1 if m.two_sided else 0
        if m.holdout:  # deeper than the camera ray, Cycles' Holdout shader is black and absorbing
            mat_model[i] = C.MAT_LAMBERT
            mat_p[i] = material_row(Material("holdout"))
            mat_ra[i] = -1
            continue
        if m.emission >= 0 and m.emission_luminance > 0.0:
            mat_emis[i] = m.emission
            mat_emis_scale[i] = _luminance_scale(spec[m.emission], cmf, m.emission_luminance,
                                                 f"materials ({m.name!r}).emission")

    # analytic lights (row layout and units: core/kernels/lights.py)
    from ..lights import kernel as LG

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
    scene_radius = _scene_radius(v0, v1, v2)
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
            light_scale[i] = _luminance_scale(shape, cmf, li.luminance, what)
            light_power[i] = np.pi * li.luminance * area * (2.0 if li.two_sided else 1.0)  # lm
        elif kind in (C.LIGHT_POINT, C.LIGHT_SPOT):
            r = float(li.radius)
            inten = float(li.intensity)
            light_geo[i, LG.LG_RADIUS] = r
            # a sphere of radius r with radiance I / (π r²) has intensity I in every direction
            light_scale[i] = _luminance_scale(shape, cmf, inten / (np.pi * r * r) if r > 0 else inten, what)
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
                table, peak_cd, light_power[i] = _profile_table(scene, li, what, light_geo[i], LG)
                light_scale[i] = _luminance_scale(shape, cmf, peak_cd / (np.pi * r * r) if r > 0 else peak_cd, what)
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
            light_scale[i] = _luminance_scale(shape, cmf, e / (np.pi * np.sin(half) ** 2) if k > 0 else e, what)
            # the flux the sun sends through the disc of the scene's bounding sphere
            light_power[i] = e * np.pi * scene_radius ** 2

    # emitter distribution, proportional to luminous flux (lm): π L A per side for
    # emissive triangles and area lights, see above for point, spot and sun lights
    e1 = bvh.e1.astype(np.float64)
    e2 = bvh.e2.astype(np.float64)
    tri_area = 0.5 * np.linalg.norm(np.cross(e1, e2), axis=1)
    emissive = (mat_emis[tri_mat] >= 0) & (tri_area > 0) if tri_mat.size else np.zeros(0, bool)
    em_tris = np.nonzero(emissive)[0].astype(np.int32)
    lum = np.array([m.emission_luminance for m in scene.materials] or [0.0])
    power_tri = np.pi * lum[tri_mat[em_tris]] * tri_area[em_tris] * (1.0 + mat_emis_two[tri_mat[em_tris]])
    power_light = light_power
    # the world image: one more emitter, between the triangles and the analytic lights
    world_img, world_dist, world_par, world_basis, power_world = _world_image(scene.world, cmf, scene_radius)
    world_row = spec.shape[0]
    if world_basis is not None:
        spec = np.concatenate([spec, world_basis.astype(np.float32)])
    # image textures: the reflectance basis rows a base colour texel's rgb weighs
    from .. import textures as TX

    tri_tex = TX.triangle_frames(scene, bvh.prims)
    tex_data, tex_info = TX.pack(scene.textures)
    mat_tex, mat_nstr = TX.material_tables(scene)
    tex_row = -1
    if np.any(mat_tex[:, 0] >= 0):
        tex_row = spec.shape[0]
        spec = np.concatenate([spec, TX.reflectance_basis().astype(np.float32)])
    sensor_mat = -1
    if measure:  # the sensors' white two-sided Lambert: one more material, ρ = 1 (one more spectrum row)
        sensor_mat = n_mat
        mat_model = np.append(mat_model, np.int32(C.MAT_LAMBERT))
        mat_p = np.concatenate([mat_p, material_row(Material("sensor"))[None, :]])
        mat_ra = np.append(mat_ra, np.int32(spec.shape[0]))
        mat_rb = np.append(mat_rb, np.int32(-1))
        mat_eta = np.append(mat_eta, np.int32(-1))
        mat_kappa = np.append(mat_kappa, np.int32(-1))
        mat_ior = np.append(mat_ior, 1.5)
        mat_emis = np.append(mat_emis, np.int32(-1))
        mat_emis_scale = np.append(mat_emis_scale, 0.0)
        mat_emis_two = np.append(mat_emis_two, np.int32(1))
        spec = np.concatenate([spec, np.ones((1, C.N_LAMBDA), np.float32)])
        mat_tex = np.concatenate([mat_tex, np.full((1, 3), -1, np.int32)])  # the sensor: untextured
        mat_nstr = np.append(mat_nstr, 1.0)
    # the albedo AOV's colour: XYZ of every spectrum row under CIE D65 of Y = 1
    dwl, d65 = presets.illuminant("D65")
    d65 = np.interp(moments.grid(), dwl, d65)
    cmf64 = cmf[:, :3].astype(np.float64)  # the observer's x̄, ȳ, z̄
    d65 /= float(d65 @ cmf64[:, 1] * C.LAMBDA_STEP)
    spec_alb = np.ascontiguousarray((spec.astype(np.float64) * d65[None, :]) @ cmf64 * C.LAMBDA_STEP)
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
    tri_emitter = np.full(tri_mat.size, -1, np.int32)
    if total > 0:
        tri_emitter[em_tris] = np.arange(em_tris.size, dtype=np.int32)
    # The kernel finds an analytic light's emitter index as n_emit - n_lights + li.

    world_spec = int(scene.world.background)
    world_scale = 0.0
    if world_spec >= 0:
        world_scale = _luminance_scale(spec[world_spec], cmf, scene.world.luminance, "world")
        if world_scale == 0.0:
            world_spec = -1

    light_prof = np.ascontiguousarray(np.concatenate(prof_parts) if prof_parts else np.zeros(1))
    pts = [np.abs(v0).max(initial=0), np.abs(v1).max(initial=0), np.abs(v2).max(initial=0)]
    not_sun = light_kind != C.LIGHT_SUN
    if np.any(not_sun):
        pts.append(np.abs(light_geo[not_sun, :3]).max() + light_geo[not_sun, 13].max())
    scene_scale = max(1.0, float(max(pts)))
    ior_tab = scene.ior_tables.values if len(scene.ior_tables) else np.ones((1, C.N_LAMBDA), np.float32)
    mat_medium, med_tab, med_g = media_tables(scene, spec)
    if measure:
        mat_medium = np.append(mat_medium, np.int32(-1))
    tri_flag = _triangle_flags(scene, bvh, tri_mat_orig, measure)
    cam_medium = camera_medium(scene, v0, v1, v2, tri_mat_orig, mat_medium) if med_tab.shape[0] else -1
    return Prepared(scene, bvh, tri_mat, tri_emitter, mat_model, mat_p, mat_ra, mat_rb, mat_eta, mat_kappa,
                    mat_ior, np.ascontiguousarray(ior_tab, np.float32), mat_emis, mat_emis_scale,
                    mat_emis_two, np.ascontiguousarray(spec, np.float32), cmf, light_kind, light_geo, light_spec,
                    light_scale, light_two, light_vis, cdf, np.ascontiguousarray(prob), emit_tri, emit_light,
                    world_spec, world_scale, world_img, world_dist, world_par, int(world_row), world_emit,
                    camera_vector(scene.camera, scene.settings), filter_distribution(scene.settings),
                    _shading_normals(scene, bvh), spec_alb, scene_scale,
                    time.perf_counter() - t0, mat_medium, med_tab, med_g, cam_medium, light_prof, tri_flag,
                    sensor_mat, int(bool(scene.settings.film_transparent)),
                    tri_tex, tex_data, tex_info, mat_tex, mat_nstr, tex_row)


def _rows(prep, film, y0, y1, s0, s1):
    from .path import render_rows, scratch

    st = prep.scene.settings
    b = prep.bvh
    render_rows(film.sums, int(y0), int(y1), int(s0), int(s1), int(st.seed), int(st.max_depth), int(st.rr_depth),
                float(prep.scene_scale), prep.cam, prep.filt,
                b.nodes, b.tris, b.v0, b.e1, b.e2, prep.tri_mat, prep.tri_emitter,
                prep.mat_model, prep.mat_p, prep.mat_ra, prep.mat_rb, prep.mat_eta, prep.mat_kappa, prep.mat_ior,
                prep.ior_tab, prep.mat_emis, prep.mat_emis_scale, prep.mat_emis_two, prep.spec, prep.cmf,
                prep.light_kind, prep.light_geo, prep.light_prof, prep.light_spec, prep.light_scale,
                prep.light_two_sided,
                prep.light_visible, prep.emit_cdf, prep.emit_prob, prep.emit_tri, prep.emit_light,
                int(prep.world_spec), float(prep.world_scale), prep.world_img, prep.world_dist, prep.world_par,
                prep.world_row, prep.world_emit, film.spectral, film.aov, prep.tri_nrm, prep.spec_alb, int(st.sampler),
                int(st.spp), prep.mat_medium, prep.med_tab, prep.med_g, int(prep.cam_medium),
                int(bool(st.next_event)), prep.tri_flag, int(prep.sensor_mat), int(prep.film_transparent),
                prep.tri_tex, prep.tex_data, prep.tex_info, prep.mat_tex, prep.mat_nstr, int(prep.tex_row),
                float(st.tri_solid_angle_min), float(st.tri_solid_angle_max), *scratch(prep.mat_p.shape[1]))


def thread_count(threads=None):
    """Worker threads for a render: ``threads`` if given (> 0), else one per core."""
    if threads is not None and int(threads) > 0:
        return int(threads)
    return max(1, os.cpu_count() or 1)


def run_pass(prep: Prepared, film: Film, s0: int, s1: int, pool=None):
    """Add samples [s0, s1) of every pixel to ``film``.

    With a ``concurrent.futures`` ``pool``, blocks of rows run on its threads (the kernel
    releases the GIL); without one, on the calling thread. The result is the same.
    """
    h = film.height
    if pool is None:
        _rows(prep, film, 0, h, s0, s1)
    else:
        workers = getattr(pool, "_max_workers", 1)
        block = max(1, h // (8 * workers))  # several blocks per thread balance the load
        futures = [pool.submit(_rows, prep, film, y, min(h, y + block), s0, s1) for y in range(0, h, block)]
        for f in futures:
            f.result()
    film.spp = s1


@dataclass
class RenderStats:
    spp: int
    seconds: float
    samples_per_second: float
    cancelled: bool
    build_seconds: float
    compile_seconds: float
    stop_reason: str = "spp"  # "spp" (all samples), "time_limit", "noise_target" or "cancelled"
    relative_error: float = float("nan")  # relative standard error of the image's mean luminance


def relative_error(film):
    """Relative standard error of the image's mean luminance, from the film's per-pixel
    sums of Y and Y² (pixels are independent): sqrt(Σ var(pixel mean)) / Σ pixel mean."""
    from ..film import photometric_y_sums

    sums = film.sums
    n = sums[..., 3]
    if n.size == 0 or n.min() < 2:
        return float("inf")
    mean = photometric_y_sums(sums) / n
    var = np.maximum(sums[..., 4] / n - mean * mean, 0.0) / (n - 1.0)
    total = float(mean.sum())
    se = float(np.sqrt(var.sum()))
    if total <= 0.0:
        return 0.0 if se == 0.0 else float("inf")
    return se / total


def render(scene: Scene, *, threads=None, progress=None, should_cancel=None, on_pass=None, status=None,
           spectral_bins=0, resume=None, measure=False):
    """Render ``scene`` to a :class:`Film`.

    progress(done_spp, total_spp, samples_per_second) after each pass;
    should_cancel() → True stops after the current pass (the film keeps what was done);
    on_pass(film) after each pass (for progressive display);
    status(text) for phase messages ("Compiling kernels (first run only)", ...);
    spectral_bins > 0 also records the spectral radiance in that many bins;
    resume: a Film of this scene (e.g. from Film.load) to continue from its spp up to the
    scene's; the result is bit-identical to rendering all samples at once (the Hammersley
    sampler excepted: its points depend on the total). The given film is not modified.
    The scene's settings.time_limit (s) and settings.noise_target (relative standard
    error of the mean luminance) stop the render early; RenderStats.stop_reason says why.
    measure=True renders the illuminance of the scene's sensor meshes instead (see
    core/sensors.py, which turns the film into lux).
    Returns (film, RenderStats).
    """
    say = status or (lambda text: None)
    n_threads = thread_count(threads)
    # a cold cache: a second process compiles part of the kernel's helpers meanwhile
    helper = warmup.start()
    try:
        return _render(scene, n_threads, say, helper, progress, should_cancel, on_pass, spectral_bins, resume,
                       measure)
    finally:
        warmup.finish(helper)


def _render(scene, n_threads, say, helper, progress, should_cancel, on_pass, spectral_bins, resume, measure):
    t_start = time.perf_counter()
    say("Preparing scene" if helper is None else "Compiling kernels (first run only): preparing scene")
    cold = not kernels_compiled()
    t_compile = 0.0
    # on a cold start, Python's cyclic garbage collector is paused from ``prepare`` (which
    # compiles the BVH builder) to the end of the kernel's compile: numba's compiler makes
    # millions of short-lived objects and the collector's sweeps took ~10 % of the compile time
    gc_was_on = gc.isenabled()
    if cold:
        gc.disable()
    try:
        prep = prepare(scene, measure=measure)
        cam = scene.camera
        if resume is not None:
            if (resume.width, resume.height) != (cam.width, cam.height):
                raise SceneError(f"resume: the film is {resume.width}x{resume.height}, the scene renders "
                                 f"{cam.width}x{cam.height}")
            if getattr(resume, "observer", "1931") != scene.settings.observer:
                raise SceneError(f"resume: the film was rendered with the CIE {resume.observer} observer, the "
                                 f"scene asks for {scene.settings.observer}")
            if resume.spp > scene.settings.spp:
                raise SceneError(f"resume: the film already has {resume.spp} spp, more than settings.spp = "
                                 f"{scene.settings.spp}")
            film = resume.copy()
        else:
            film = Film(cam.width, cam.height, spectral_bins, observer=scene.settings.observer)
        total = int(scene.settings.spp)
        if cold:
            say("Compiling kernels (first run only)")
            tc = time.perf_counter()
            # compile (or load from numba's cache) with a 1-sample pass on a scratch film
            if helper is not None:  # this process's share of the helpers, then the kernel
                warmup.compile_group(False)
                # the second process's share: given as long as this process has worked
                warmup.finish(helper, grace=time.perf_counter() - t_start)
            run_pass(prep, Film(1, 1, observer=scene.settings.observer), 0, 1)
            t_compile = time.perf_counter() - tc
    finally:
        if gc_was_on:
            gc.enable()
    say("Rendering")
    pool = ThreadPoolExecutor(max_workers=n_threads, thread_name_prefix="spectral-gi") if n_threads > 1 else None
    try:
        return _progressive(prep, film, pool, total, progress, should_cancel, on_pass, t_compile)
    finally:
        if pool is not None:
            pool.shutdown(wait=True)


def _progressive(prep, film, pool, total, progress, should_cancel, on_pass, t_compile):
    cam = prep.scene.camera
    st = prep.scene.settings
    t0 = time.perf_counter()
    start = done = int(film.spp)
    step = 1
    reason = "spp"
    while done < total:
        if should_cancel is not None and should_cancel():
            reason = "cancelled"
            break
        n = min(step, total - done)
        if st.time_limit > 0:  # aim the pass at what is left of the time
            left = st.time_limit - (time.perf_counter() - t0)
            if left <= 0:
                reason = "time_limit"
                break
        tp = time.perf_counter()
        run_pass(prep, film, done, done + n, pool)
        dt = time.perf_counter() - tp
        done += n
        elapsed = time.perf_counter() - t0
        rate = (done - start) * cam.width * cam.height / max(elapsed, 1e-9)
        if progress is not None:
            progress(done, total, rate)
        if on_pass is not None:
            on_pass(film)
        if done >= total:
            break
        if st.time_limit > 0 and elapsed >= st.time_limit:
            reason = "time_limit"
            break
        if st.noise_target > 0 and relative_error(film) <= st.noise_target:
            reason = "noise_target"
            break
        # adapt the pass length towards PASS_SECONDS (and within a time limit)
        if dt > 0:
            target = PASS_SECONDS
            if st.time_limit > 0:
                target = min(target, max(st.time_limit - elapsed, 0.0))
            step = int(max(1, min(step * 4, round(n * target / dt))))
    elapsed = time.perf_counter() - t0
    stats = RenderStats(done, elapsed, (done - start) * cam.width * cam.height / max(elapsed, 1e-9),
                        reason == "cancelled", prep.build_seconds, t_compile, reason, relative_error(film))
    return film, stats
