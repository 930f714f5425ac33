"""Material grid: twelve spheres, one per BSDF model, rendered by this renderer and by Cycles.

    python benchmarks/material_grid.py [--spp 64] [--bounces 12] [--threads 2] [--out docs/images]

The scene is built in Blender (bpy): a 4×3 grid of spheres on a grey ground plane, lit by
one area light and a dim uniform world. Row by row: Lambert, Phong, Blinn–Phong, Ward
(isotropic); Ward (anisotropic), Lafortune, mirror, gold (measured η, κ); glass, rough
glass, Principled plastic, Principled metal.

This renderer gets the scene through the add-on's exporter: shader nodes where Blender
has them (Diffuse, Glossy, Glass, Principled), the material panel's model override for
the rest (Phong, Blinn–Phong, Ward, Lafortune, measured gold). Cycles renders the same
Blender scene (CPU, same samples and bounce limit; no adaptive sampling, denoising or
clamping) with each sphere's node tree: its nearest equivalent where it has the model
(gold as a Metallic BSDF with gold's η, κ at 630/532/465 nm, marked †), a stand-in
otherwise (a diffuse + glossy mix, marked * "no Cycles equivalent"). Both images are linear Rec.709
encoded to sRGB with the same exposure and labelled; the script writes
``material_grid.png`` (this renderer) and ``material_grid_cycles.png`` and prints the
timings.
"""
import argparse
import io
import math
import os
import sys
import tempfile
import time

import results  # benchmarks/results.py: the JSON record of this run (benchmarks/ is on sys.path)

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import cornell_vs_cycles as cvc  # noqa: E402  (one definition of Cycles' benchmark settings)

SIZE = (320, 240)
GRID = [  # (label, Cycles label: None when Cycles has the model, key)
    ("Lambert", None, "lambert"),
    ("Phong", "Phong*", "phong"),
    ("Blinn-Phong", "Blinn-Phong*", "blinn"),
    ("Ward", "Ward*", "ward_iso"),
    ("Ward aniso", "Ward aniso*", "ward_aniso"),
    ("Lafortune", "Lafortune*", "lafortune"),
    ("Mirror", None, "mirror"),
    ("Gold", "Gold†", "gold"),
    ("Glass", None, "glass"),
    ("Rough glass", None, "rough_glass"),
    ("Plastic", None, "plastic"),
    ("Metal", None, "metal"),
]
CYCLES_NOTE = "* no Cycles equivalent (diffuse + glossy stand-in)   † RGB η, κ"
OURS_NOTE = "Gold: measured η(λ), κ(λ)   Plastic, Metal: Principled BSDF"
SPACING = 1.05
RADIUS = 0.42


# ----------------------------------------------------------------------------- the Blender scene

def _tree(mat):
    tree = mat.node_tree
    tree.nodes.clear()
    out = tree.nodes.new("ShaderNodeOutputMaterial")
    return tree, out


def _single(bpy, name, idname, **inputs):
    mat = bpy.data.materials.new(name)
    tree, out = _tree(mat)
    node = tree.nodes.new(idname)
    for k, v in inputs.items():
        node.inputs[k].default_value = v
    tree.links.new(node.outputs[0], out.inputs["Surface"])
    return mat, node


def _stand_in(bpy, name, diffuse, roughness, anisotropy=0.0, gloss=0.5):
    """Cycles' stand-in for a diffuse + glossy model it lacks: Mix(diffuse, glossy)."""
    mat = bpy.data.materials.new(name)
    tree, out = _tree(mat)
    d = tree.nodes.new("ShaderNodeBsdfDiffuse")
    d.inputs["Color"].default_value = (*diffuse, 1.0)
    g = tree.nodes.new("ShaderNodeBsdfGlossy")
    g.inputs["Color"].default_value = (1.0, 1.0, 1.0, 1.0)
    g.inputs["Roughness"].default_value = roughness
    g.inputs["Anisotropy"].default_value = anisotropy
    mix = tree.nodes.new("ShaderNodeMixShader")
    mix.inputs["Factor"].default_value = gloss
    tree.links.new(d.outputs[0], mix.inputs[1])
    tree.links.new(g.outputs[0], mix.inputs[2])
    tree.links.new(mix.outputs[0], out.inputs["Surface"])
    return mat


def _principled(bpy, name, rgb, **inputs):
    mat = bpy.data.materials.new(name)
    node = next(n for n in mat.node_tree.nodes if n.type == "BSDF_PRINCIPLED")
    node.inputs["Base Color"].default_value = (*rgb, 1.0)
    for k, v in inputs.items():
        node.inputs[k].default_value = v
    return mat


def make_materials(bpy):
    from spectral_gi import core

    blue = (0.10, 0.22, 0.55)
    red = (0.55, 0.08, 0.06)
    green = (0.12, 0.40, 0.12)
    mats = {}
    mats["lambert"], _ = _single(bpy, "Lambert", "ShaderNodeBsdfDiffuse", Color=(0.6, 0.6, 0.6, 1.0))

    def override(key, name, model, diffuse, cyc_roughness, cyc_aniso=0.0, **settings):
        mat = _stand_in(bpy, name, diffuse, cyc_roughness, cyc_aniso)
        st = mat.spectral_gi
        st.model = model
        st.spectrum = "NODE"
        st.specular_color = (0.5, 0.5, 0.5)
        for k, v in settings.items():
            setattr(st, k, v)
        mats[key] = mat

    override("phong", "Phong", "PHONG", red, 0.25, exponent=60.0)
    override("blinn", "Blinn-Phong", "BLINN_PHONG", blue, 0.2, exponent=200.0)
    override("ward_iso", "Ward", "WARD", green, 0.39, alpha_x=0.15, alpha_y=0.15)
    override("ward_aniso", "Ward aniso", "WARD", blue, 0.3, 0.7, alpha_x=0.05, alpha_y=0.3)
    override("lafortune", "Lafortune", "LAFORTUNE", red, 0.5, lobe_count=2,
             lobe_1=(-1.0, -1.0, 1.0, 30.0), lobe_2=(0.8, 0.8, 0.8, 10.0))
    mats["mirror"], _ = _single(bpy, "Mirror", "ShaderNodeBsdfGlossy", Color=(0.9, 0.9, 0.9, 1.0), Roughness=0.0)
    # gold: measured η, κ for this renderer; Cycles' Metallic BSDF with η, κ at its RGB wavelengths
    gold, node = _single(bpy, "Gold", "ShaderNodeBsdfMetallic", Roughness=0.15)
    node.fresnel_type = "PHYSICAL_CONDUCTOR"
    eta, kappa = core.metal_preset("Au")
    wl = core.wavelength_grid()
    rgb_nm = (630.0, 532.0, 465.0)
    node.inputs["IOR"].default_value = tuple(float(np.interp(x, wl, eta)) for x in rgb_nm)
    node.inputs["Extinction"].default_value = tuple(float(np.interp(x, wl, kappa)) for x in rgb_nm)
    st = gold.spectral_gi
    st.model, st.spectrum, st.metal_preset = "CONDUCTOR", "PRESET", "Au"
    st.alpha_x = st.alpha_y = 0.15 ** 2
    mats["gold"] = gold
    mats["glass"], _ = _single(bpy, "Glass", "ShaderNodeBsdfGlass", IOR=1.5, Roughness=0.0)
    mats["rough_glass"], _ = _single(bpy, "Rough glass", "ShaderNodeBsdfGlass", IOR=1.5, Roughness=0.3)
    mats["plastic"] = _principled(bpy, "Plastic", (0.05, 0.25, 0.6), Roughness=0.25)
    mats["metal"] = _principled(bpy, "Metal", (0.95, 0.64, 0.54), Metallic=1.0, Roughness=0.3)
    return mats


def build_scene(bpy, size=SIZE):
    from spectral_gi.addon import registration

    registration.register()
    bpy.ops.wm.read_homefile(use_empty=True)
    scene = bpy.context.scene
    mats = make_materials(bpy)
    ground, _ = _single(bpy, "Ground", "ShaderNodeBsdfDiffuse", Color=(0.35, 0.35, 0.35, 1.0))
    bpy.ops.mesh.primitive_plane_add(size=20.0, location=(0.0, 0.0, 0.0))
    bpy.context.object.data.materials.append(ground)
    spheres = []
    for i, (_, _, key) in enumerate(GRID):
        row, col = divmod(i, 4)  # the first row at the back (top of the image)
        loc = ((col - 1.5) * SPACING, (1.0 - row) * SPACING * 1.45, RADIUS)
        bpy.ops.mesh.primitive_uv_sphere_add(segments=64, ring_count=32, radius=RADIUS, location=loc)
        obj = bpy.context.object
        obj.name = key
        obj.data.materials.append(mats[key])
        spheres.append(obj)
    light = bpy.data.lights.new("Key", "AREA")
    light.energy = 400.0
    light.size = 3.0
    lo = bpy.data.objects.new("Key", light)
    lo.location = (-1.0, -1.5, 4.5)
    lo.rotation_euler = (math.radians(20), math.radians(-10), 0.0)
    scene.collection.objects.link(lo)
    world = bpy.data.worlds.new("Dim")
    bg = next(n for n in world.node_tree.nodes if n.type == "BACKGROUND")
    bg.inputs["Color"].default_value = (0.6, 0.7, 0.9, 1.0)
    bg.inputs["Strength"].default_value = 0.15
    scene.world = world
    cam = bpy.data.cameras.new("Camera")
    cam.lens = 52.0
    co = bpy.data.objects.new("Camera", cam)
    co.location = (0.0, -6.2, 7.0)
    co.rotation_euler = (math.radians(41), 0.0, 0.0)
    scene.collection.objects.link(co)
    scene.camera = co
    scene.render.resolution_x, scene.render.resolution_y = size
    scene.render.resolution_percentage = 100
    return scene, spheres


def label_positions(bpy, scene, spheres):
    """Pixel (x, y) just below each sphere's image (rows top to bottom)."""
    from bpy_extras.object_utils import world_to_camera_view
    from mathutils import Vector

    bpy.context.view_layer.update()  # objects made through bpy.data have no matrix_world before this
    w, h = scene.render.resolution_x, scene.render.resolution_y
    out = []
    for obj in spheres:
        p = obj.location
        c = world_to_camera_view(scene, scene.camera, Vector((p.x, p.y - 0.6 * RADIUS, 0.0)))
        out.append((c.x * w, (1.0 - c.y) * h))
    return out


# ----------------------------------------------------------------------------- rendering

def render_ours(bpy, spp, bounces, threads):
    from spectral_gi import core
    from spectral_gi.addon.export import export_scene

    t0 = time.perf_counter()
    warm = export_scene(bpy.context.evaluated_depsgraph_get()).scene
    warm.camera.width = warm.camera.height = 8
    warm.settings.spp = 1
    core.render(warm, threads=threads)
    t_warm = time.perf_counter() - t0
    t0 = time.perf_counter()
    res = export_scene(bpy.context.evaluated_depsgraph_get())
    sc = res.scene
    sc.settings.spp = spp
    sc.settings.max_depth = bounces
    film, stats = core.render(sc, threads=threads)
    t = time.perf_counter() - t0
    return film.develop().rgb, t, t_warm, stats, res.warning


def render_cycles(bpy, scene, spp, bounces, threads, path):
    """Cycles at the Cornell benchmark's matched settings: (linear Rec.709 image, seconds)."""
    t = cvc.render_cycles(scene, spp, bounces, threads, path)
    return cvc.read_rgb(path), t


# ----------------------------------------------------------------------------- labelled images

def _font(size):
    from PIL import ImageFont

    for name in ("DejaVuSansCondensed.ttf", "DejaVuSans.ttf"):
        try:
            return ImageFont.truetype(name, size)
        except OSError:
            pass
    try:
        return ImageFont.load_default(size=size)
    except TypeError:  # Pillow < 10.1: one bitmap size
        return ImageFont.load_default()


def labelled_png(rgb, title, labels, positions, exposure, note=""):
    """PNG bytes of a linear image encoded to sRGB, with a title and a label under each sphere."""
    from PIL import Image, ImageDraw

    from spectral_gi.core.io.png import to_srgb8

    img = Image.fromarray(to_srgb8(rgb, exposure))
    draw = ImageDraw.Draw(img)
    font, big = _font(9), _font(12)

    def text(xy, s, f, anchor):
        draw.text(xy, s, font=f, fill=(255, 255, 255), anchor=anchor, stroke_width=1, stroke_fill=(0, 0, 0))

    text((4, 3), title, big, "la")
    if note:
        text((img.width // 2, img.height - 3), note, font, "md")
    for s, (x, y) in zip(labels, positions):
        text((x, y + 1), s, font, "ma")
    buf = io.BytesIO()
    img.save(buf, format="PNG")
    return buf.getvalue()


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--spp", type=int, default=64)
    ap.add_argument("--bounces", type=int, default=12)
    ap.add_argument("--threads", type=int, default=min(2, os.cpu_count() or 1))
    ap.add_argument("--exposure", type=float, default=0.0, help="stops, applied to both images")
    ap.add_argument("--out", default=os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "docs",
                                                  "images"))
    args = ap.parse_args(argv)

    import bpy

    from spectral_gi.core.io.atomic import write_bytes

    scene, spheres = build_scene(bpy)
    positions = label_positions(bpy, scene, spheres)
    ours, t_ours, t_warm, stats, warning = render_ours(bpy, args.spp, args.bounces, args.threads)
    tmp = tempfile.mkdtemp(prefix="sgi-grid-")
    cyc, t_cyc = render_cycles(bpy, scene, args.spp, args.bounces, args.threads, os.path.join(tmp, "cycles.exr"))

    os.makedirs(args.out, exist_ok=True)
    ours_labels = [g[0] for g in GRID]
    cyc_labels = [g[1] or g[0] for g in GRID]
    w, h = SIZE
    write_bytes(os.path.join(args.out, "material_grid.png"),
                labelled_png(ours, f"spectral-gi  {args.spp} spp", ours_labels, positions, args.exposure,
                             OURS_NOTE))
    write_bytes(os.path.join(args.out, "material_grid_cycles.png"),
                labelled_png(cyc, f"Cycles  {args.spp} spp", cyc_labels, positions, args.exposure,
                             CYCLES_NOTE))

    px = w * h * args.spp
    print(f"Material grid {w}x{h}, {args.spp} spp, max bounces {args.bounces}, {args.threads} threads")
    print(f"  spectral-gi : {t_ours:7.2f} s  {px / t_ours / 1e6:6.3f} M samples/s  (render {stats.seconds:.2f} s; "
          f"warm-up/compile {t_warm:.1f} s)")
    print(f"  Cycles      : {t_cyc:7.2f} s  {px / t_cyc / 1e6:6.3f} M samples/s")
    print(f"  time ratio Cycles / spectral-gi: {t_cyc / t_ours:.2f}x")
    lum = np.array([0.2126, 0.7152, 0.0722])
    print(f"  mean luminance spectral-gi / Cycles: {float((ours @ lum).mean() / (cyc @ lum).mean()):.4f}")
    if warning:
        print(f"  export warning: {warning}")
    print(f"  wrote {os.path.join(args.out, 'material_grid.png')} and material_grid_cycles.png")
    ratio = float((ours @ lum).mean() / (cyc @ lum).mean())
    results.write("material_grid", [results.table(
        f"Material grid {w}×{h}, {args.spp} spp, max bounces {args.bounces}, {args.threads} threads",
        ["renderer", "time (s)", "M samples/s", "mean luminance / Cycles'"],
        [["spectral-gi (export + render)", round(t_ours, 2), round(px / t_ours / 1e6, 3), round(ratio, 4)],
         ["Cycles", round(t_cyc, 2), round(px / t_cyc / 1e6, 3), 1.0]])],
        conditions={"spp": args.spp, "bounces": args.bounces, "threads": args.threads, "size": [w, h]})
    return 0


if __name__ == "__main__":
    sys.exit(main())
