"""The materials record: every material's model, parameters and spectra as the path kernel
reads them, with the spectrum table they index."""
from __future__ import annotations

from typing import NamedTuple

import numpy as np

from .. import constants as C


class MaterialRecord(NamedTuple):
    """K materials (at least one) and the S spectrum rows they, the lights, the world and the
    textures index.

    model: int32 (K,) MAT_* tag of each material; MAT_MIX / MAT_ADD pick one of the
        components params[1], params[2] per hit (Mix: with probability params[0]).
    params: float64 (K, MATERIAL_PARAMS) each material's parameter row for core.bsdfs.
    ra, rb: int32 (K,) rows of ``spec`` of the spectral inputs ρa and ρb (-1: 0 and 1).
    eta, kappa: int32 (K,) rows of ``ior_tab`` of η and κ (-1: the constant ``ior`` and 0).
    ior: float64 (K,) the constant index of refraction.
    ior_tab: float32 (R, N_LAMBDA) tabulated η and κ spectra (one row of 1 when there are none).
    emis: int32 (K,) row of ``spec`` of the emitted radiance's shape (-1: not emissive).
    emis_scale: float64 (K,) factor turning that shape into spectral radiance W/(m² sr nm).
    emis_two: int32 (K,) 1: emits (and, for a Lambert, scatters) on both sides.
    spec: float32 (S, N_LAMBDA) every spectrum of the render on the 1 nm grid: the scene's,
        then the world image's emission basis, the textures' reflectance basis and the
        sensors' ρ = 1, those present, in this order.
    spec_alb: float64 (S, 3) CIE XYZ of each row of ``spec`` under CIE D65 of Y = 1 (the
        albedo AOV's colour, precomputed so the pass carries no colour noise).
    """

    model: np.ndarray
    params: np.ndarray
    ra: np.ndarray
    rb: np.ndarray
    eta: np.ndarray
    kappa: np.ndarray
    ior: np.ndarray
    ior_tab: np.ndarray
    emis: np.ndarray
    emis_scale: np.ndarray
    emis_two: np.ndarray
    spec: np.ndarray
    spec_alb: np.ndarray


def spectrum_table(scene):
    """float32 (S, N_LAMBDA) the scene's spectra on the 1 nm grid (one row of zeros for none)."""
    from ..spectra import moments

    return moments.tabulate(scene.spectra.coeffs, scene.spectra.kind) if len(scene.spectra) else \
        np.zeros((1, C.N_LAMBDA), np.float32)


def pack(scene, spec, cmf) -> MaterialRecord:
    """The record of ``scene``'s materials; ``spec`` its spectrum table (``spectrum_table``),
    ``cmf`` the observer's table (core/film/record.py cmf_table). ``finish`` completes it
    once the render's spectrum table is whole."""
    from ..photometry.units import luminance_scale
    from ..scene import Material

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
            mat_emis_scale[i] = luminance_scale(spec[m.emission], cmf, m.emission_luminance,
                                                f"materials ({m.name!r}).emission")
    ior_tab = scene.ior_tables.values if len(scene.ior_tables) else np.ones((1, C.N_LAMBDA), np.float32)
    return MaterialRecord(mat_model, mat_p, mat_ra, mat_rb, mat_eta, mat_kappa, mat_ior,
                          np.ascontiguousarray(ior_tab, np.float32), mat_emis, mat_emis_scale, mat_emis_two,
                          spec, None)


def add_sensor(rec, spec):
    """``rec`` with one more material, the sensors' white (ρ = 1) two-sided Lambert, and
    ``spec`` with its spectrum row: (record, spec, the sensor material's index)."""
    from ..scene import Material

    sensor_mat = rec.model.shape[0]
    rec = rec._replace(
        model=np.append(rec.model, np.int32(C.MAT_LAMBERT)),
        params=np.concatenate([rec.params, material_row(Material("sensor"))[None, :]]),
        ra=np.append(rec.ra, np.int32(spec.shape[0])),
        rb=np.append(rec.rb, np.int32(-1)),
        eta=np.append(rec.eta, np.int32(-1)),
        kappa=np.append(rec.kappa, np.int32(-1)),
        ior=np.append(rec.ior, 1.5),
        emis=np.append(rec.emis, np.int32(-1)),
        emis_scale=np.append(rec.emis_scale, 0.0),
        emis_two=np.append(rec.emis_two, np.int32(1)))
    spec = np.concatenate([spec, np.ones((1, C.N_LAMBDA), np.float32)])
    return rec, spec, sensor_mat


def finish(rec, spec, cmf) -> MaterialRecord:
    """``rec`` with the render's whole spectrum table ``spec`` and its albedo colours."""
    from ..io import presets
    from ..spectra import moments

    # the albedo AOV's colour: XYZ of every spectrum row under CIE D65 of Y = 1
    dwl, d65 = presets.illuminant("D65")
    d65 = np.interp(moments.grid(), dwl, d65)
    cmf64 = cmf[:, :3].astype(np.float64)  # the observer's x̄, ȳ, z̄
    d65 /= float(d65 @ cmf64[:, 1] * C.LAMBDA_STEP)
    spec_alb = np.ascontiguousarray((spec.astype(np.float64) * d65[None, :]) @ cmf64 * C.LAMBDA_STEP)
    return rec._replace(spec=np.ascontiguousarray(spec, np.float32), spec_alb=spec_alb)


def material_row(m, index=0):
    """The float64[16] parameter row of a material (its ``params``, or its model's defaults)."""
    from ..scene import SceneError
    from .params import make_params

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


