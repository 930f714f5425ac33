"""The procedural textures against Cycles, pixel for pixel.

Each case renders, with Cycles (bpy), a plane filling an orthographic camera whose
Emission shader is fed by one texture node driven by the plane's Object coordinates
(moved by a constant offset, so no coordinate sits on a lattice plane), at 64 x 64, one
sample, a box filter 0.01 pixel wide (each camera ray passes within 0.005 pixel of the
pixel's centre). The same texture is evaluated by ``core.shading.procedural`` at the
pixel centres, and the mean and 99th percentile of the absolute difference (relative to
the pattern's mean where that exceeds 1) must be small: a wrong hash or gradient set
moves the mean by 1e-2 or more, a 1 % error in a noise output scale by about 1e-3.
Continuous patterns differ only by the sub-pixel jitter and single precision (mean
about 3e-5 to 2e-4); patterns with edges (cells, bricks, checkers) may differ at the few
pixels an edge crosses.
"""
import math
import os
import sys
import tempfile

import numpy as np
import pytest

if "bpy" not in sys.modules:
    # Before bpy is imported: keep Blender's user configuration out of the developer's home.
    os.environ.setdefault("BLENDER_USER_RESOURCES", tempfile.mkdtemp(prefix="spectral-gi-blender-user-"))

from spectral_gi.core.shading import procedural as P  # noqa: E402

RES = 64
OFFSET = (0.1234, 0.2345, 0.3456)
W = 0.7
SMOOTH = (3e-4, 1.5e-3)  # mean and 99th percentile of |Cycles - ours| for continuous patterns
EDGES = (2e-3, 1e-2)  # for patterns with edges

pytestmark = [pytest.mark.slow]


@pytest.fixture(scope="module")
def bpy():
    try:
        import bpy as _bpy
    except ImportError as exc:
        pytest.skip(f"bpy (Blender as a Python module) is not importable: {exc}")
    return _bpy


def _node_graph(bpy, nt, case):
    """Texture Coordinate (Object) -> + OFFSET [-> x8 -> floor] [-> (x, z, y)] -> the texture [-> abs]
    -> Emission."""
    tc = nt.nodes.new("ShaderNodeTexCoord")
    add = nt.nodes.new("ShaderNodeVectorMath")
    add.operation = "ADD"
    add.inputs[1].default_value = case.get("offset", OFFSET)
    nt.links.new(tc.outputs["Object"], add.inputs[0])
    vec = add.outputs[0]
    if case.get("snap"):
        mul = nt.nodes.new("ShaderNodeVectorMath")
        mul.operation = "MULTIPLY"
        mul.inputs[1].default_value = (8.0, 8.0, 8.0)
        flo = nt.nodes.new("ShaderNodeVectorMath")
        flo.operation = "FLOOR"
        nt.links.new(vec, mul.inputs[0])
        nt.links.new(mul.outputs[0], flo.inputs[0])
        vec = flo.outputs[0]
    if case.get("swap_yz"):
        sep = nt.nodes.new("ShaderNodeSeparateXYZ")
        com = nt.nodes.new("ShaderNodeCombineXYZ")
        nt.links.new(vec, sep.inputs[0])
        for a, b in (("X", "X"), ("Y", "Z"), ("Z", "Y")):
            nt.links.new(sep.outputs[a], com.inputs[b])
        vec = com.outputs[0]
    tex = nt.nodes.new(case["node"])
    for k, v in case.get("props", {}).items():
        setattr(tex, k, v)
    inputs = {s.name: s for s in tex.inputs}
    for k, v in dict(case.get("inputs", {}), W=W).items():
        if k in inputs:
            inputs[k].default_value = v
    if case.get("w_from_x"):
        sep = nt.nodes.new("ShaderNodeSeparateXYZ")
        nt.links.new(vec, sep.inputs[0])
        nt.links.new(sep.outputs["X"], inputs["W"])
    else:
        nt.links.new(vec, inputs["Vector"])
    src = {s.name: s for s in tex.outputs}[case["output"]]
    if case.get("absolute"):
        ab = nt.nodes.new("ShaderNodeMath")
        ab.operation = "ABSOLUTE"
        nt.links.new(src, ab.inputs[0])
        src = ab.outputs[0]
    em = nt.nodes.new("ShaderNodeEmission")
    out = nt.nodes.new("ShaderNodeOutputMaterial")
    nt.links.new(src, em.inputs["Color"])
    nt.links.new(em.outputs[0], out.inputs["Surface"])


def render_cycles(bpy, case, path):
    """The Cycles render of ``case``: (RES, RES, 3) linear RGB, row 0 at the bottom."""
    bpy.ops.wm.read_homefile(use_empty=True)
    sc = bpy.context.scene
    sc.render.engine = "CYCLES"
    sc.cycles.device = "CPU"
    sc.cycles.samples = 1
    sc.cycles.use_adaptive_sampling = False
    sc.cycles.use_denoising = False
    sc.cycles.pixel_filter_type = "BOX"
    sc.cycles.filter_width = 0.01
    sc.render.threads_mode = "FIXED"
    sc.render.threads = 1
    sc.render.resolution_x = sc.render.resolution_y = RES
    sc.render.resolution_percentage = 100
    sc.render.image_settings.file_format = "OPEN_EXR"
    sc.render.image_settings.color_depth = "32"
    me = bpy.data.meshes.new("plane")
    me.from_pydata([(-1, -1, 0), (1, -1, 0), (1, 1, 0), (-1, 1, 0)], [], [(0, 1, 2, 3)])
    ob = bpy.data.objects.new("plane", me)
    sc.collection.objects.link(ob)
    mat = bpy.data.materials.new("texture")
    mat.node_tree.nodes.clear()
    _node_graph(bpy, mat.node_tree, case)
    ob.data.materials.append(mat)
    cd = bpy.data.cameras.new("camera")
    cd.type = "ORTHO"
    cd.ortho_scale = 2.0
    cam = bpy.data.objects.new("camera", cd)
    cam.location = (0.0, 0.0, 5.0)
    sc.collection.objects.link(cam)
    sc.camera = cam
    sc.render.filepath = str(path)
    bpy.ops.render.render(write_still=True)
    img = bpy.data.images.load(str(path))
    px = np.array(img.pixels[:], dtype=np.float64).reshape(RES, RES, 4)[..., :3]
    bpy.data.images.remove(img)
    return px


def evaluate(case):
    """``case``'s texture evaluated here at the pixel centres, (RES, RES, 3)."""
    c = -1.0 + (np.arange(RES) + 0.5) * 2.0 / RES
    off = np.float32(case.get("offset", OFFSET))  # Blender stores the offset, and adds it, in single precision
    out = np.zeros((RES, RES, 3))
    for j in range(RES):
        for i in range(RES):
            p = tuple(float(v) for v in (np.float32(c[i]) + off[0], np.float32(c[j]) + off[1], off[2]))
            if case.get("snap"):
                p = tuple(math.floor(v * 8.0) for v in p)
            if case.get("swap_yz"):
                p = (p[0], p[2], p[1])
            w = p[0] if case.get("w_from_x") else W
            v = case["ours"](p[0], p[1], p[2], w)
            v = np.abs(v) if case.get("absolute") else v
            out[j, i] = v if np.ndim(v) else (v, v, v)
    return out


def _noise(dims, ntype, scale=5.0, detail=2.0, rough=0.5, lac=2.0, offset=0.0, gain=1.0, dist=0.0, norm=1, k=0):
    props = {"noise_dimensions": f"{dims}D", "noise_type": ntype, "normalize": bool(norm)}
    inputs = {"Scale": scale, "Detail": detail, "Roughness": rough, "Lacunarity": lac, "Offset": offset,
              "Gain": gain, "Distortion": dist}
    t = P.NOISE_TYPES[ntype]

    def ours(x, y, z, w):
        r = P.noise_texture(x, y, z, w, dims, t, scale, detail, rough, lac, offset, gain, dist, norm, k == 1)
        return r[0] if k == 0 else r[1:]
    return dict(node="ShaderNodeTexNoise", props=props, inputs=inputs, output="Color" if k else "Factor",
                ours=ours, w_from_x=dims == 1)


def _voronoi(dims, feature, metric="EUCLIDEAN", output="Distance", scale=5.0, detail=0.0, rough=0.5, lac=2.0,
             smooth=1.0, expo=0.5, rand=1.0, norm=0):
    props = {"voronoi_dimensions": f"{dims}D", "feature": feature, "distance": metric, "normalize": bool(norm)}
    inputs = {"Scale": scale, "Detail": detail, "Roughness": rough, "Lacunarity": lac, "Smoothness": smooth,
              "Exponent": expo, "Randomness": rand}
    f, m = P.VORONOI_FEATURES[feature], P.VORONOI_METRICS[metric]
    pick = {"Distance": 0, "Color": slice(1, 4), "Position": slice(4, 7), "W": 7, "Radius": 8}[output]

    def ours(x, y, z, w):
        return P.voronoi_texture(x, y, z, w, dims, f, m, scale, detail, rough, lac, smooth, expo, rand, norm)[pick]
    return dict(node="ShaderNodeTexVoronoi", props=props, inputs=inputs, output=output, ours=ours,
                w_from_x=dims == 1)


def _wave(wtype, bands="X", rings="X", profile="SIN", scale=1.5, dist=0.0, detail=2.0, dscale=1.0, drough=0.5,
          phase=0.0):
    props = {"wave_type": wtype, "bands_direction": bands, "rings_direction": rings, "wave_profile": profile}
    inputs = {"Scale": scale, "Distortion": dist, "Detail": detail, "Detail Scale": dscale,
              "Detail Roughness": drough, "Phase Offset": phase}
    tags = (P.WAVE_TYPES[wtype], P.WAVE_BANDS_DIRECTIONS[bands], P.WAVE_RINGS_DIRECTIONS[rings],
            P.WAVE_PROFILES[profile])

    def ours(x, y, z, w):
        return P.wave_texture(x, y, z, *tags, scale, dist, detail, dscale, drough, phase)
    return dict(node="ShaderNodeTexWave", props=props, inputs=inputs, output="Factor", ours=ours)


def _magic(depth, scale=2.0, dist=1.0):
    def ours(x, y, z, w):
        return P.magic_texture(x, y, z, depth, scale, dist)[:3]
    return dict(node="ShaderNodeTexMagic", props={"turbulence_depth": depth},
                inputs={"Scale": scale, "Distortion": dist}, output="Color", ours=ours)


C1, C2, CM = (0.8, 0.2, 0.1, 1.0), (0.1, 0.3, 0.9, 1.0), (0.05, 0.6, 0.05, 1.0)


def _checker(scale=5.0):
    def ours(x, y, z, w):
        return P.checker_texture(x, y, z, scale, *C1[:3], *C2[:3])[:3]
    return dict(node="ShaderNodeTexChecker", inputs={"Scale": scale, "Color1": C1, "Color2": C2},
                output="Color", ours=ours)


def _brick(output, scale=5.0, size=0.02, smooth=0.1, bias=0.0, width=0.5, height=0.25, offset=0.5, ofreq=2,
           squash=1.0, sfreq=2):
    props = {"offset": offset, "offset_frequency": ofreq, "squash": squash, "squash_frequency": sfreq}
    inputs = {"Scale": scale, "Mortar Size": size, "Mortar Smooth": smooth, "Bias": bias, "Brick Width": width,
              "Row Height": height, "Color1": C1, "Color2": C2, "Mortar": CM}

    def ours(x, y, z, w):
        tint, fac = P.brick_texture(x, y, z, scale, size, smooth, bias, width, height, offset, ofreq, squash, sfreq)
        return fac if output == "Factor" else P.brick_color(tint, fac, *C1[:3], *C2[:3], *CM[:3])
    return dict(node="ShaderNodeTexBrick", props=props, inputs=inputs, output=output, ours=ours)


def _gradient(gtype):
    t = P.GRADIENT_TYPES[gtype]
    # the gradient runs over [0, 1]: the plane's [-1, 1] square is moved to [-0.2, 1.8] x [-0.6, 1.4]
    return dict(node="ShaderNodeTexGradient", props={"gradient_type": gtype}, output="Factor",
                offset=(0.8, 0.4, 0.1), ours=lambda x, y, z, w: P.gradient_texture(x, y, z, t))


def _white(dims, output):
    def ours(x, y, z, w):
        r = P.white_noise_texture(x, y, z, w, dims)
        return r[0] if output == "Value" else r[1:]
    return dict(node="ShaderNodeTexWhiteNoise", props={"noise_dimensions": f"{dims}D"}, output=output,
                ours=ours, snap=True, w_from_x=dims == 1)


CASES = {
    "noise-3d-fbm": (_noise(3, "FBM"), SMOOTH),
    "noise-3d-fbm-colour-distorted": (_noise(3, "FBM", detail=3.5, rough=0.6, lac=2.5, dist=0.5, k=1), SMOOTH),
    "noise-2d-fbm-unnormalized": (dict(_noise(2, "FBM", detail=1.0, norm=0), absolute=True), SMOOTH),
    "noise-4d-fbm-colour": (_noise(4, "FBM", k=1), SMOOTH),
    "noise-1d-fbm": (_noise(1, "FBM", detail=4.0), SMOOTH),
    "noise-3d-multifractal": (dict(_noise(3, "MULTIFRACTAL", detail=2.5), absolute=True), SMOOTH),
    "noise-3d-hybrid": (dict(_noise(3, "HYBRID_MULTIFRACTAL", detail=3.0, offset=0.5, gain=1.5), absolute=True),
                        SMOOTH),
    "noise-3d-ridged": (dict(_noise(3, "RIDGED_MULTIFRACTAL", detail=3.0, offset=1.0, gain=2.0), absolute=True),
                        SMOOTH),
    "noise-3d-hetero": (dict(_noise(3, "HETERO_TERRAIN", detail=2.5, offset=0.3), absolute=True), SMOOTH),
    "noise-2d-fbm-large-coordinates": (dict(_noise(2, "FBM", scale=1.0, detail=0.0), offset=(1.5e6, 2.5e6, 0.3)),
                                       EDGES),
    # beyond 1e5 Cycles wraps the noise's coordinates; where the single-precision step is 1/128 the
    # pixel centres (multiples of 1/64 from the offset) are exact, not rounded by the rays' jitter
    "noise-3d-fbm-wrapped-coordinates": (dict(_noise(3, "FBM", scale=1.0, detail=1.0),
                                             offset=(120000.3, -110000.6, 105000.2)), SMOOTH),
    "voronoi-3d-f1-far-cells": (dict(_voronoi(3, "F1", output="Color"), offset=(3000.1, -2000.2, 500.3)), EDGES),
    "voronoi-3d-f1-distance": (_voronoi(3, "F1"), EDGES),
    "voronoi-3d-f1-colour": (_voronoi(3, "F1", output="Color"), EDGES),
    "voronoi-3d-f1-position": (_voronoi(3, "F1", output="Position"), EDGES),
    "voronoi-2d-f1-manhattan-colour": (_voronoi(2, "F1", "MANHATTAN", output="Color"), EDGES),
    "voronoi-3d-f2-chebychev": (_voronoi(3, "F2", "CHEBYCHEV"), EDGES),
    "voronoi-2d-f1-minkowski": (_voronoi(2, "F1", "MINKOWSKI", expo=1.5), EDGES),
    "voronoi-3d-smooth-f1": (_voronoi(3, "SMOOTH_F1"), SMOOTH),
    "voronoi-2d-smooth-f1-colour-fractal": (_voronoi(2, "SMOOTH_F1", output="Color", detail=1.5, norm=1), SMOOTH),
    "voronoi-3d-f1-fractal-normalized": (_voronoi(3, "F1", detail=2.5, rough=0.6, norm=1), EDGES),
    "voronoi-3d-distance-to-edge": (_voronoi(3, "DISTANCE_TO_EDGE"), EDGES),
    "voronoi-2d-distance-to-edge-fractal": (_voronoi(2, "DISTANCE_TO_EDGE", detail=2.0, norm=1), EDGES),
    "voronoi-3d-n-sphere-radius": (_voronoi(3, "N_SPHERE_RADIUS", output="Radius"), EDGES),
    "voronoi-4d-f1": (_voronoi(4, "F1", rand=0.8), EDGES),
    "voronoi-1d-f1-w": (_voronoi(1, "F1", output="W"), EDGES),
    "voronoi-1d-distance-to-edge": (_voronoi(1, "DISTANCE_TO_EDGE"), EDGES),
    "noise-4d-multifractal-colour": (_noise(4, "MULTIFRACTAL", detail=1.5, rough=0.7, k=1), SMOOTH),
    "noise-2d-hetero-distorted": (dict(_noise(2, "HETERO_TERRAIN", scale=2.0, detail=3.0, lac=3.0, offset=0.8,
                                              dist=1.0), absolute=True), SMOOTH),
    "noise-1d-ridged-colour": (_noise(1, "RIDGED_MULTIFRACTAL", detail=2.0, offset=0.9, gain=1.2, k=1), SMOOTH),
    "noise-1d-fbm-distorted-colour": (_noise(1, "FBM", detail=2.5, dist=0.7, k=1), SMOOTH),
    "noise-4d-hybrid-distorted": (dict(_noise(4, "HYBRID_MULTIFRACTAL", detail=2.0, offset=0.7, gain=0.8,
                                             dist=0.3), absolute=True), SMOOTH),
    "voronoi-4d-smooth-f1-colour": (_voronoi(4, "SMOOTH_F1", output="Color", smooth=0.6, rand=0.9), SMOOTH),
    "voronoi-4d-f2-minkowski-normalized": (_voronoi(4, "F2", "MINKOWSKI", expo=2.5, norm=1), EDGES),
    "voronoi-4d-distance-to-edge": (_voronoi(4, "DISTANCE_TO_EDGE", rand=0.7), EDGES),
    "voronoi-4d-n-sphere-radius": (_voronoi(4, "N_SPHERE_RADIUS", output="Radius"), EDGES),
    "voronoi-3d-minkowski-position": (_voronoi(3, "F1", "MINKOWSKI", output="Position", expo=0.8, rand=0.6),
                                      EDGES),
    "voronoi-3d-smooth-f1-position": (_voronoi(3, "SMOOTH_F1", output="Position", smooth=0.4), SMOOTH),
    "voronoi-2d-f2-colour-fractal": (_voronoi(2, "F2", output="Color", detail=2.0, rough=0.7, lac=2.5), EDGES),
    "voronoi-1d-f2": (_voronoi(1, "F2", rand=0.8), EDGES),
    "voronoi-1d-smooth-f1-colour": (_voronoi(1, "SMOOTH_F1", output="Color", detail=1.3), SMOOTH),
    "voronoi-1d-n-sphere-radius": (_voronoi(1, "N_SPHERE_RADIUS", output="Radius"), EDGES),
    "voronoi-3d-chebychev-normalized-fractal": (_voronoi(3, "F1", "CHEBYCHEV", detail=1.0, norm=1), EDGES),
    "wave-bands-x-sin-distorted": (_wave("BANDS", dist=2.0), SMOOTH),
    "wave-rings-spherical-saw": (_wave("RINGS", rings="SPHERICAL", profile="SAW"), EDGES),
    "wave-bands-diagonal-tri": (_wave("BANDS", bands="DIAGONAL", profile="TRI", phase=1.0), SMOOTH),
    "wave-rings-z-sin": (_wave("RINGS", rings="Z", dist=1.0, detail=1.5), SMOOTH),
    "wave-bands-y-saw-distorted": (_wave("BANDS", bands="Y", profile="SAW", dist=1.5, detail=3.0, dscale=2.0),
                                   EDGES),
    "wave-bands-z-sin": (dict(_wave("BANDS", bands="Z"), swap_yz=True), SMOOTH),
    "wave-rings-x-tri": (_wave("RINGS", rings="X", profile="TRI", drough=0.8, dist=0.5), SMOOTH),
    "wave-rings-y-sin": (_wave("RINGS", rings="Y", phase=2.0), SMOOTH),
    "magic-depth-2": (_magic(2), SMOOTH),
    "magic-depth-10": (_magic(10), SMOOTH),
    # each level doubles a difference at distortion 2: the sub-pixel jitter's 1e-4 grows to about 1e-3
    "magic-depth-5-distortion-2": (_magic(5, dist=2.0), EDGES),
    "checker": (_checker(), EDGES),
    "brick-colour": (_brick("Color"), EDGES),
    # the mortar's smooth ramp is 0.04 (scaled) wide here; narrower ramps are sharper than the
    # sub-pixel jitter of Cycles' camera rays
    "brick-mortar": (_brick("Factor", size=0.08, smooth=0.5, squash=0.7, bias=0.2), EDGES),
    "brick-colour-squashed": (_brick("Color", scale=3.0, size=0.08, smooth=0.5, width=0.7, height=0.3, offset=0.3,
                                     ofreq=3, squash=0.6, sfreq=2, bias=-0.3), EDGES),
    "white-noise-1d-colour": (_white(1, "Color"), EDGES),
    "white-noise-1d": (_white(1, "Value"), EDGES),
    "white-noise-2d-colour": (_white(2, "Color"), EDGES),
    "white-noise-3d": (_white(3, "Value"), EDGES),
    "white-noise-4d-colour": (_white(4, "Color"), EDGES),
    **{f"gradient-{g.lower()}": (_gradient(g), EDGES if g == "RADIAL" else SMOOTH) for g in P.GRADIENT_TYPES},
}


@pytest.mark.parametrize("name", list(CASES))
def test_texture_matches_cycles_pixel_for_pixel(bpy, tmp_path, name):
    case, (mean_tol, p99_tol) = CASES[name]
    cycles = render_cycles(bpy, case, tmp_path / "cycles.exr")
    ours = evaluate(case)
    d = np.abs(cycles - ours) / max(1.0, float(np.abs(cycles).mean()))  # relative for patterns above 1
    mean, p99 = float(d.mean()), float(np.percentile(d, 99))
    print(f"{name}: mean |diff| {mean:.2e}, p99 {p99:.2e}, max {d.max():.2e}, Cycles mean {cycles.mean():.4f}")
    assert np.ptp(ours) > 0.05, "the case shows no pattern"
    assert mean <= mean_tol and p99 <= p99_tol, (mean, p99)
