"""Where spectral-gi and Cycles disagree by physics, rendered by both (the worked example of docs/validation/cycles.md).

    python benchmarks/cycles_physics.py [--spp 64] [--out docs/images] [--only patches,prism]

1. **Narrow-band light (metamerism).** The 24 ColorChecker patches (N. Ohta's measured
   reflectances) lit straight from above by a sun, first with CIE D65, then with the
   triband fluorescent CIE FL11. Spectral GI gets the measured spectra (material panel:
   Lambert, preset reflectance; light panel: CIE illuminant); Cycles gets what a Cycles
   user would type: each patch's colour under D65 and the light's RGB colour (luminance
   1). Cycles then multiplies RGB by RGB, which is not the colour of the product of the
   spectra: under D65 both agree, under FL11 they do not. Each patch is also predicted
   from the spectra with colour-science (the ground truth) and from the RGB product.
2. **Dispersion.** A sphere of SCHOTT N-SF11 (a dense flint, Abbe number 25.7) in front
   of white emitting bars. Spectral GI refracts every wavelength by its own index
   (Sellmeier); Cycles' Glass BSDF has one IOR (N-SF11's n_d at 587.6 nm), so the bars
   seen through the sphere get coloured fringes in one image only.

Both go through the *Compare with Cycles* code (``ComparisonRun``, as
``readme_compare.py``), and the script writes ``physics_<scene>_side_by_side.png`` and
``physics_<scene>_dE.png`` into ``--out`` and prints the figures (ΔE00, luminance ratio).
"""
import argparse
import math
import os
import shutil
import sys
import tempfile

import results  # benchmarks/results.py: the JSON record of this run (benchmarks/ is on sys.path)

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import readme_compare as rc  # noqa: E402  (the operator's code path, images and PNG helpers)

PATCH_GRID = (6, 4)
PATCH_PITCH = 1.0
PATCH_SIZE = 0.9
GLASS = "N-SF11"


# ----------------------------------------------------------------------------- spectra (colour-science truth)

def _cs():
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        import colour
    return colour


def light_sd(name):
    colour = _cs()
    return colour.SDS_ILLUMINANTS[name]


def _integrate(values_fn, sd_light):
    """∫ f(λ) S(λ) cmf(λ) dλ on 360–830 nm at 1 nm (CIE 1931 2°)."""
    colour = _cs()
    shape = colour.SpectralShape(360, 830, 1)
    cmf = colour.MSDS_CMFS["CIE 1931 2 Degree Standard Observer"].copy().align(shape).values
    wl = np.arange(360, 831, 1.0)
    s = sd_light.copy().align(shape).values
    f = values_fn(wl)
    return (f * s)[:, None] * cmf, (s[:, None] * cmf)


def patch_truth(light_name):
    """(24, 3) XYZ of the patches under the light, on Blender's scale for a sun of strength π W/m²
    (Y of a perfect white = 1), and the XYZ of that white (the light's colour)."""
    colour = _cs()
    sds = colour.SDS_COLOURCHECKERS["ColorChecker N Ohta"]
    sd_l = light_sd(light_name)
    out = []
    white = None
    for name in list(sds.keys()):
        sd = sds[name]

        def rho(wl, sd=sd):
            return np.interp(wl, sd.wavelengths, sd.values)

        num, den = _integrate(rho, sd_l)
        white = den.sum(0)
        out.append(num.sum(0) / white[1])
    return np.array(out), white / white[1], list(sds.keys())


def light_rgb(light_name):
    """The light's linear Rec.709 colour with luminance 1 (what a Cycles user sets as the light colour)."""
    from spectral_gi.core.colour import XYZ_to_sRGB_linear

    _, white, _ = patch_truth(light_name)
    return np.maximum(XYZ_to_sRGB_linear(white), 0.0)


def delta_e(XYZ_a, XYZ_b, white_XYZ):
    """ΔE00 between XYZ colours, in L*a*b* against the light's white (an eye adapted to the light)."""
    from spectral_gi.core.colour import XYZ_to_Lab, delta_E_CIE2000

    xy = white_XYZ[:2] / white_XYZ.sum()
    return delta_E_CIE2000(XYZ_to_Lab(XYZ_a, xy), XYZ_to_Lab(XYZ_b, xy))


# ----------------------------------------------------------------------------- scenes

def patches_scene(bpy, light_name, width, height, spp):
    from spectral_gi import core
    from spectral_gi.addon import registration

    registration.register()
    bpy.ops.wm.read_homefile(use_empty=True)
    scene = bpy.context.scene
    names = core.reflectance_preset_names()
    cols, rows = PATCH_GRID
    h = PATCH_SIZE / 2
    for i, name in enumerate(names):
        row, col = divmod(i, cols)
        rgb = np.clip(core.reflectance_to_rgb(core.reflectance_preset(name)), 0.0, 1.0)
        mat = rc._material(bpy, f"Patch {i + 1}", "ShaderNodeBsdfDiffuse", Color=(*rgb, 1.0))
        st = mat.spectral_gi
        st.model, st.spectrum, st.reflectance_preset = "LAMBERT", "PRESET", name
        x = (col - (cols - 1) / 2) * PATCH_PITCH
        y = ((rows - 1) / 2 - row) * PATCH_PITCH
        rc._mesh(bpy, scene, f"Patch {i + 1}", [(-h, -h, 0), (h, -h, 0), (h, h, 0), (-h, h, 0)], [(0, 1, 2, 3)],
                 mat, location=(x, y, 0.0))
    sun = bpy.data.lights.new("Sun", "SUN")
    sun.energy = math.pi  # W/m²: a white patch has Y = 1 on Blender's scale
    sun.angle = 0.01
    sun.color = tuple(light_rgb(light_name))  # Cycles reads this; Spectral GI reads the spectrum below
    sun.spectral_gi.spectrum = "ILLUMINANT"
    sun.spectral_gi.illuminant = light_name
    so = bpy.data.objects.new("Sun", sun)
    so.location = (0.0, 0.0, 5.0)
    scene.collection.objects.link(so)
    cam = bpy.data.cameras.new("Camera")
    cam.type, cam.ortho_scale = "ORTHO", cols * PATCH_PITCH + 0.1
    co = bpy.data.objects.new("Camera", cam)
    co.location = (0.0, 0.0, 5.0)
    scene.collection.objects.link(co)
    scene.camera = co
    r = scene.render
    r.resolution_x, r.resolution_y, r.resolution_percentage = width, height, 100
    st = scene.spectral_gi
    st.samples, st.max_bounces, st.seed = spp, 2, 1
    return scene


def prism_scene(bpy, width, height, spp):
    from spectral_gi import core
    from spectral_gi.addon import registration

    registration.register()
    bpy.ops.wm.read_homefile(use_empty=True)
    scene = bpy.context.scene
    wl = core.wavelength_grid()
    n_d = float(np.interp(587.56, wl, core.glass_preset(GLASS)))
    glass = rc._material(bpy, "Glass", "ShaderNodeBsdfGlass", IOR=n_d, Roughness=0.0,
                         Color=(1.0, 1.0, 1.0, 1.0))
    st = glass.spectral_gi
    st.model, st.spectrum, st.glass_preset = "GLASS", "PRESET", GLASS
    st.alpha_x = st.alpha_y = 0.0  # smooth, as the Glass node (the panel's default roughness is 0.1)
    bpy.ops.mesh.primitive_uv_sphere_add(segments=96, ring_count=48, radius=0.9, location=(0.0, 0.0, 0.0))
    sphere = bpy.context.object
    sphere.data.materials.append(glass)
    bpy.ops.object.shade_smooth()
    white = rc._material(bpy, "Bar", "ShaderNodeEmission", Color=(1.0, 1.0, 1.0, 1.0), Strength=1.0)
    bw, pitch = 0.14, 0.42
    for i in range(-6, 7):
        x = i * pitch
        rc._mesh(bpy, scene, f"Bar {i}", [(x - bw / 2, 3.0, -2.0), (x + bw / 2, 3.0, -2.0),
                                           (x + bw / 2, 3.0, 2.0), (x - bw / 2, 3.0, 2.0)],
                 [(0, 1, 2, 3)], white)  # facing the camera
    cam = bpy.data.cameras.new("Camera")
    cam.lens = 65.0
    co = bpy.data.objects.new("Camera", cam)
    co.location, co.rotation_euler = (0.0, -5.0, 0.0), (math.radians(90), 0.0, 0.0)
    scene.collection.objects.link(co)
    scene.camera = co
    r = scene.render
    r.resolution_x, r.resolution_y, r.resolution_percentage = width, height, 100
    st = scene.spectral_gi
    st.samples, st.max_bounces, st.seed = spp, 12, 1
    return scene, n_d


# ----------------------------------------------------------------------------- analysis

def halves(bpy, report):
    from spectral_gi.addon.operators import compare

    sbs = rc.image_array(bpy, compare.SIDE_BY_SIDE_IMAGE)
    w = report["width"]
    return sbs[:, :w], sbs[:, w + 2:]


def patch_means(rgb):
    """(24, 3) mean linear RGB of each patch's central half."""
    h, w = rgb.shape[:2]
    cols, rows = PATCH_GRID
    view_w = cols * PATCH_PITCH + 0.1
    px = w / view_w  # pixels per metre (orthographic)
    out = []
    for i in range(cols * rows):
        row, col = divmod(i, cols)
        cx = w / 2 + (col - (cols - 1) / 2) * PATCH_PITCH * px
        cy = h / 2 + (row - (rows - 1) / 2) * PATCH_PITCH * px
        r = PATCH_SIZE * px / 4
        out.append(rgb[int(cy - r):int(cy + r), int(cx - r):int(cx + r)].reshape(-1, 3).mean(0))
    return np.array(out)


def run_patches(bpy, light_name, args, tmp):
    from spectral_gi.core.colour import sRGB_linear_to_XYZ

    w, h = args.patch_size
    scene = patches_scene(bpy, light_name, w, h, args.spp)
    report = rc.run_comparison(bpy, scene, tmp, os.path.join(tmp, f"patches_{light_name}.json"))
    rc.write_images(bpy, report, args.out, prefix=f"physics_patches_{light_name}",
                    left=f"spectral-gi, {light_name}", right=f"Cycles, {light_name} as RGB")
    ours, cyc = halves(bpy, report)
    truth, white, _names = patch_truth(light_name)
    from spectral_gi import core

    assert _names == list(core.reflectance_preset_names()), "patch order differs from colour-science's"

    rgb_product = np.array([np.clip(core.reflectance_to_rgb(core.reflectance_preset(n)), 0, 1)
                            for n in core.reflectance_preset_names()]) * light_rgb(light_name)
    xyz = {k: sRGB_linear_to_XYZ(v) for k, v in (("ours", patch_means(ours)), ("cycles", patch_means(cyc)),
                                                 ("rgb_product", rgb_product))}
    de = {"spectral-gi vs truth": delta_e(xyz["ours"], truth, white),
          "Cycles vs truth": delta_e(xyz["cycles"], truth, white),
          "RGB product vs truth": delta_e(xyz["rgb_product"], truth, white),
          "spectral-gi vs Cycles": delta_e(xyz["ours"], xyz["cycles"], white)}
    print(f"\nColorChecker under {light_name}: luminance ratio {report['luminance_ratio']:.4f}, image ΔE00 mean "
          f"{report['delta_e00_mean']:.2f} (D65 white)")
    for k, v in de.items():
        worst = int(np.argmax(v))
        print(f"  per patch ΔE00 (white of the light), {k:24s} mean {v.mean():5.2f}  max {v.max():5.2f} "
              f"(patch {worst + 1} {_names[worst]})")
    return report, de


def run_prism(bpy, args, tmp):
    w, h = args.prism_size
    scene, n_d = prism_scene(bpy, w, h, args.spp)
    report = rc.run_comparison(bpy, scene, tmp, os.path.join(tmp, "prism.json"))
    rc.write_images(bpy, report, args.out, prefix="physics_prism", left=f"spectral-gi, {GLASS}",
                    right=f"Cycles, IOR {n_d:.4f}")
    ours, cyc = halves(bpy, report)
    # chroma of each image: how far from grey the pixels are (the bars are white, the rest black)
    def chroma(rgb):
        m = rgb.mean(-1, keepdims=True)
        return float(np.abs(rgb - m).sum(-1).mean() / max(float(m.mean()), 1e-9))
    print(f"\nDispersion ({GLASS}, Cycles IOR n_d = {n_d:.4f}): luminance ratio {report['luminance_ratio']:.4f}, "
          f"ΔE00 mean {report['delta_e00_mean']:.2f}, p95 {report['delta_e00_p95']:.2f}, max "
          f"{report['delta_e00_max']:.1f}; relative chroma spectral-gi {chroma(ours):.3f}, Cycles {chroma(cyc):.3f}")
    return report


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--spp", type=int, default=64)
    ap.add_argument("--out", default=os.path.join(rc.HERE, "..", "docs", "images"))
    ap.add_argument("--only", default="patches,prism")
    args = ap.parse_args(argv)
    args.patch_size = (168, 112)
    args.prism_size = (200, 150)
    os.makedirs(args.out, exist_ok=True)

    import bpy

    tmp = tempfile.mkdtemp(prefix="sgi-physics-")
    rows = []
    try:
        if "patches" in args.only:
            for light in ("D65", "FL11"):
                report, de = run_patches(bpy, light, args, tmp)
                rows.append([f"ColorChecker under {light}", round(report["luminance_ratio"], 4),
                             round(report["delta_e00_mean"], 2)]
                            + [f"{v.mean():.2f} / {v.max():.2f}" for v in de.values()])
        if "prism" in args.only:
            report = run_prism(bpy, args, tmp)
            rows.append([f"{GLASS} sphere (dispersion)", round(report["luminance_ratio"], 4),
                         round(report["delta_e00_mean"], 2), "", "", "", ""])
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
    results.write("cycles_physics", [results.table(
        f"Where physics makes the renderers differ ({args.spp} spp); per patch ΔE00 mean / max relative to the "
        "light's white", ["scene", "luminance ratio", "image ΔE00 mean (D65 white)", "spectral-gi vs spectra",
                          "Cycles vs spectra", "RGB product vs spectra", "spectral-gi vs Cycles"], rows)],
        conditions={"spp": args.spp, "patch_size": list(args.patch_size), "prism_size": list(args.prism_size)})
    return 0


if __name__ == "__main__":
    sys.exit(main())
