"""The "Compare with Cycles" images of docs/validation/cycles.md, made by the operator's own code path.

    python benchmarks/readme_compare.py [--spp 128] [--size 160x120] [--out docs/images]

Builds a small scene in Blender (bpy): a grey floor, an orange back wall, a blue diffuse
cube and a Principled plastic sphere under one area light and a dim sky. Then it runs
``addon.operators.compare.ComparisonRun`` — the state machine the *Compare with Cycles*
button steps from its timer (Spectral GI on a worker thread, then Cycles), here with
Cycles rendered on the spot because Blender-as-a-module has no event loop — and writes

* ``compare_side_by_side.png``: the operator's image "Spectral GI vs Cycles" (left:
  spectral-gi, right: Cycles), sRGB-encoded;
* ``compare_dE.png``: its image "Spectral GI ΔE00" (false colour and legend);
* ``compare_report.json``: the operator's report (numbers, settings, timings).
"""
import argparse
import io
import json
import math
import os
import shutil
import sys
import tempfile
import time

import results  # benchmarks/results.py: the JSON record of this run (benchmarks/ is on sys.path)

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))


def _material(bpy, name, idname, **inputs):
    mat = bpy.data.materials.new(name)
    tree = mat.node_tree
    tree.nodes.clear()
    out = tree.nodes.new("ShaderNodeOutputMaterial")
    node = tree.nodes.new(idname)
    for k, v in inputs.items():
        node.inputs[k].default_value = v
    tree.links.new(node.outputs[0], out.inputs["Surface"])
    return mat


def _mesh(bpy, scene, name, verts, faces, material, location=(0.0, 0.0, 0.0)):
    me = bpy.data.meshes.new(name)
    me.from_pydata(verts, [], faces)
    me.materials.append(material)
    obj = bpy.data.objects.new(name, me)
    obj.location = location
    scene.collection.objects.link(obj)
    return obj


def build_scene(bpy, width, height, spp, bounces):
    from spectral_gi.addon import registration

    registration.register()
    bpy.ops.wm.read_homefile(use_empty=True)
    scene = bpy.context.scene
    grey = _material(bpy, "Grey", "ShaderNodeBsdfDiffuse", Color=(0.5, 0.5, 0.5, 1.0))
    orange = _material(bpy, "Orange", "ShaderNodeBsdfDiffuse", Color=(0.8, 0.35, 0.08, 1.0))
    blue = _material(bpy, "Blue", "ShaderNodeBsdfDiffuse", Color=(0.08, 0.2, 0.7, 1.0))
    plastic = _material(bpy, "Plastic", "ShaderNodeBsdfPrincipled", **{"Base Color": (0.7, 0.7, 0.1, 1.0),
                                                                        "Roughness": 0.3})
    s = 4.0
    _mesh(bpy, scene, "Floor", [(-s, -s, 0), (s, -s, 0), (s, s, 0), (-s, s, 0)], [(0, 1, 2, 3)], grey)
    _mesh(bpy, scene, "Wall", [(-s, 1.5, 0), (s, 1.5, 0), (s, 1.5, 3), (-s, 1.5, 3)], [(0, 1, 2, 3)], orange)
    h = 0.45
    cube_v = [(x, y, z) for x in (-h, h) for y in (-h, h) for z in (0.0, 2 * h)]
    cube_f = [(0, 1, 3, 2), (4, 6, 7, 5), (0, 4, 5, 1), (2, 3, 7, 6), (0, 2, 6, 4), (1, 5, 7, 3)]
    cube = _mesh(bpy, scene, "Cube", cube_v, cube_f, blue, location=(-0.8, 0.3, 0.0))
    cube.rotation_euler = (0.0, 0.0, math.radians(25))
    bpy.ops.mesh.primitive_uv_sphere_add(segments=48, ring_count=24, radius=0.5, location=(0.75, -0.1, 0.5))
    sphere = bpy.context.object
    sphere.data.materials.append(plastic)
    bpy.ops.object.shade_smooth()
    light = bpy.data.lights.new("Key", "AREA")
    light.energy, light.size = 150.0, 1.5
    lo = bpy.data.objects.new("Key", light)
    lo.location = (-0.5, -1.0, 3.0)
    lo.rotation_euler = (math.radians(15), 0.0, 0.0)
    scene.collection.objects.link(lo)
    world = bpy.data.worlds.new("Sky")
    bg = next(n for n in world.node_tree.nodes if n.type == "BACKGROUND")
    bg.inputs["Color"].default_value = (0.5, 0.6, 0.8, 1.0)
    bg.inputs["Strength"].default_value = 0.2
    scene.world = world
    cam = bpy.data.cameras.new("Camera")
    cam.lens = 32.0
    co = bpy.data.objects.new("Camera", cam)
    co.location, co.rotation_euler = (0.0, -4.6, 1.6), (math.radians(80), 0.0, 0.0)
    scene.collection.objects.link(co)
    scene.camera = co
    r = scene.render
    r.resolution_x, r.resolution_y, r.resolution_percentage = width, height, 100
    st = scene.spectral_gi
    st.samples, st.max_bounces, st.seed = spp, bounces, 1
    return scene


def image_array(bpy, name):
    """A Blender image's RGB as (H, W, 3), rows top-down."""
    img = bpy.data.images[name]
    w, h = img.size
    px = np.empty(w * h * 4, np.float32)
    img.pixels.foreach_get(px)
    return px.reshape(h, w, 4)[::-1, :, :3].astype(np.float64)


def png_bytes(rgb, labels=()):
    """sRGB PNG of a linear image, with white labels [(x, y, text)]."""
    from PIL import Image, ImageDraw, ImageFont

    from spectral_gi.core.io.png import to_srgb8

    img = Image.fromarray(to_srgb8(rgb, 0.0))
    if labels:
        draw = ImageDraw.Draw(img)
        font = ImageFont.load_default()
        for x, y, text in labels:
            draw.text((x, y), text, font=font, fill=(255, 255, 255), stroke_width=1, stroke_fill=(0, 0, 0))
    buf = io.BytesIO()
    img.save(buf, format="PNG", optimize=True)
    return buf.getvalue()


def run_comparison(bpy, scene, out_dir, json_path):
    """The operator's state machine, stepped to its end; returns the report."""
    from spectral_gi.addon.operators import compare

    run = compare.ComparisonRun(scene, bpy.context.evaluated_depsgraph_get(), out_dir=out_dir,
                                json_path=json_path, use_job=False, log=lambda t: print(t, flush=True))
    run.begin()
    while run.step() == compare.RUNNING:
        time.sleep(0.05)
    if run.state != compare.FINISHED:
        raise SystemExit(f"comparison ended {run.state}: {run.error}")
    return run.report


def write_images(bpy, report, out, prefix="compare", left="spectral-gi", right="Cycles"):
    """``<prefix>_side_by_side.png`` and ``<prefix>_dE.png`` from the operator's two images."""
    from spectral_gi.addon.operators import compare
    from spectral_gi.core.io.atomic import write_bytes

    sbs = image_array(bpy, compare.SIDE_BY_SIDE_IMAGE)
    w = report["width"]
    write_bytes(os.path.join(out, f"{prefix}_side_by_side.png"),
                png_bytes(sbs, [(3, 2, left), (w + 5, 2, right)]))
    write_bytes(os.path.join(out, f"{prefix}_dE.png"), png_bytes(image_array(bpy, compare.DELTA_E_IMAGE)))


def public_report(report):
    """The report without this machine's temporary paths."""
    doc = {k: v for k, v in report.items() if k not in ("images", "report_path", "blend_file")}
    return doc


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--spp", type=int, default=128)
    ap.add_argument("--bounces", type=int, default=8)
    ap.add_argument("--size", default="160x120", help="width x height of each image")
    ap.add_argument("--out", default=os.path.join(HERE, "..", "docs", "images"))
    args = ap.parse_args(argv)
    width, height = (int(v) for v in args.size.lower().split("x"))

    import bpy

    from spectral_gi.core.io.atomic import write_text

    scene = build_scene(bpy, width, height, args.spp, args.bounces)
    tmp = tempfile.mkdtemp(prefix="sgi-readme-compare-")
    try:
        report = run_comparison(bpy, scene, tmp, os.path.join(tmp, "report.json"))
        os.makedirs(args.out, exist_ok=True)
        write_images(bpy, report, args.out)
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
    doc = public_report(report)
    write_text(os.path.join(args.out, "compare_report.json"), json.dumps(doc, indent=1) + "\n")
    print(f"{width}x{height}, {report['samples']} spp, {report['max_bounces']} bounces: luminance ratio "
          f"{report['luminance_ratio']:.4f}, relative RMSE {report['relative_rmse']:.4f}, ΔE00 mean "
          f"{report['delta_e00_mean']:.2f}, p95 {report['delta_e00_p95']:.2f}; spectral-gi "
          f"{report['seconds_spectral_gi']:.1f} s, Cycles {report['seconds_cycles']:.1f} s")
    results.write("readme_compare", [results.table(
        f"Compare with Cycles on the diffuse + plastic scene, {width}×{height}, {report['samples']} spp, "
        f"{report['max_bounces']} bounces",
        ["luminance ratio", "relative RMSE", "ΔE00 mean", "ΔE00 p95", "spectral-gi (s)", "Cycles (s)"],
        [[round(report["luminance_ratio"], 4), round(report["relative_rmse"], 4),
          round(report["delta_e00_mean"], 2), round(report["delta_e00_p95"], 2),
          round(report["seconds_spectral_gi"], 1), round(report["seconds_cycles"], 1)]])],
        conditions={"size": [width, height], "spp": args.spp, "bounces": args.bounces})
    return 0


if __name__ == "__main__":
    sys.exit(main())
