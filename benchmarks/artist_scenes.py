"""Three scenes built in bpy as an artist would, rendered by Spectral GI and by Cycles side by side.

    python benchmarks/artist_scenes.py [--quick] [--spp 32] [--ref-spp 512] [--size 320x180]
                                       [--only product,interior,procedural] [--out docs/images]
                                       [--save-scenes DIR]

* **product**: a product shot: a glossy red plastic bottle, a brushed-metal cap, a glass
  sphere and a white box on a curved white backdrop (a cyclorama), a key, a fill and a rim
  area light and a dim grey world. Principled BSDF throughout.
* **interior**: a room with a window in one wall, lit by a sun and a blue sky through it; a
  bookshelf whose books are geometry-nodes instances (Instance on Points), a bevelled
  Bézier curve (a pipe along the wall) and an extruded text object on the floor.
* **procedural**: a floor with a Noise Texture through a Color Ramp, a Voronoi sphere, a cube
  of Principled Volume (smoke), a metaball and a sphere with particle hair.

Each scene is exported by the add-on (``addon.export.export_scene``, what F12 renders) and
rendered by the core at ``--spp`` samples; Cycles renders it at the same samples and the
same settings as the *Compare with Cycles* operator (``addon.operators.compare``: adaptive
sampling, denoising, clamping and filter glossy off, every bounce limit = max bounces), then
with a time limit equal to the engine's render time (equal time), then at ``--ref-spp`` as the
reference. The script writes ``artist_<scene>_side_by_side.png`` (left Spectral GI, right
Cycles, equal samples) and ``artist_<scene>_dE.png`` (ΔE00 false colour) into ``--out``,
prints per scene the mean-luminance ratio, ΔE00 mean / p95 between the two images at equal
samples, the relative RMSE of luminance of each against the reference at equal samples and
at equal time, the ΔE00 p95 and the colour-only ΔE00 mean (each pixel scaled to the
reference's luminance: coloured noise) of each against the reference, and the export
warning (what was substituted or left out), and records them in
``benchmarks/results/artist_scenes.json``.

``--save-scenes DIR`` also saves each exported core scene as ``DIR/<scene>.json`` (core
``save_scene``), for benchmarks that run without Blender (``adaptive_bench.py``).
"""
import argparse
import json
import math
import os
import sys
import time

import results  # benchmarks/results.py: the JSON record of this run (benchmarks/ is on sys.path)

import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
SCENES = ("product", "interior", "procedural")


# ----------------------------------------------------------------------------- bpy helpers

def principled(bpy, name, colour, roughness=0.5, metallic=0.0, transmission=0.0, ior=1.5):
    mat = bpy.data.materials.new(name)
    bsdf = mat.node_tree.nodes["Principled BSDF"]
    bsdf.inputs["Base Color"].default_value = (*colour, 1.0)
    bsdf.inputs["Roughness"].default_value = roughness
    bsdf.inputs["Metallic"].default_value = metallic
    bsdf.inputs["Transmission Weight"].default_value = transmission
    bsdf.inputs["IOR"].default_value = ior
    return mat


def mesh_object(bpy, scene, name, verts, faces, material, location=(0.0, 0.0, 0.0), smooth=False):
    me = bpy.data.meshes.new(name)
    me.from_pydata(verts, [], faces)
    if smooth:
        me.shade_smooth()
    me.materials.append(material)
    obj = bpy.data.objects.new(name, me)
    obj.location = location
    scene.collection.objects.link(obj)
    return obj


def primitive(bpy, op, material, smooth=True, **kw):
    getattr(bpy.ops.mesh, op)(**kw)
    obj = bpy.context.object
    obj.data.materials.append(material)
    if smooth:
        bpy.ops.object.shade_smooth()
    return obj


def area_light(bpy, scene, name, energy, size, location, rotation, colour=(1.0, 1.0, 1.0)):
    light = bpy.data.lights.new(name, "AREA")
    light.energy, light.size, light.color = energy, size, colour
    obj = bpy.data.objects.new(name, light)
    obj.location, obj.rotation_euler = location, tuple(math.radians(a) for a in rotation)
    scene.collection.objects.link(obj)
    return obj


def world_colour(bpy, scene, colour, strength):
    world = bpy.data.worlds.new("World")
    bg = next(n for n in world.node_tree.nodes if n.type == "BACKGROUND")
    bg.inputs["Color"].default_value = (*colour, 1.0)
    bg.inputs["Strength"].default_value = strength
    scene.world = world


def camera(bpy, scene, location, rotation, lens):
    cam = bpy.data.cameras.new("Camera")
    cam.lens = lens
    obj = bpy.data.objects.new("Camera", cam)
    obj.location, obj.rotation_euler = location, tuple(math.radians(a) for a in rotation)
    scene.collection.objects.link(obj)
    scene.camera = obj


def new_scene(bpy, width, height, spp, bounces):
    from spectral_gi.addon import registration

    registration.register()
    bpy.ops.wm.read_homefile(use_empty=True)
    scene = bpy.context.scene
    r = scene.render
    r.resolution_x, r.resolution_y, r.resolution_percentage = width, height, 100
    st = scene.spectral_gi
    st.samples, st.max_bounces, st.seed = spp, bounces, 1
    return scene


# ----------------------------------------------------------------------------- the scenes

def product_scene(bpy, width, height, spp):
    """A product on a cyclorama under three area lights."""
    scene = new_scene(bpy, width, height, spp, 8)
    backdrop = principled(bpy, "Backdrop", (0.8, 0.8, 0.8), roughness=0.6)
    # the cyclorama: a floor that curves up into a back wall (a quarter circle of radius 1.5)
    n, w, r0, y0 = 16, 6.0, 1.5, 1.0
    prof = [(-4.0, 0.0)] + [(y0 + r0 * math.sin(a), r0 - r0 * math.cos(a))
                            for a in np.linspace(0.0, math.pi / 2, n)] + [(y0 + r0, 5.0)]
    verts = [(x, y, z) for (y, z) in prof for x in (-w / 2, w / 2)]
    faces = [(2 * i, 2 * i + 1, 2 * i + 3, 2 * i + 2) for i in range(len(prof) - 1)]
    mesh_object(bpy, scene, "Cyclorama", verts, faces, backdrop, smooth=True)
    red = principled(bpy, "Red plastic", (0.7, 0.03, 0.02), roughness=0.15)
    metal = principled(bpy, "Brushed metal", (0.9, 0.9, 0.92), roughness=0.25, metallic=1.0)
    glass = principled(bpy, "Glass", (1.0, 1.0, 1.0), roughness=0.0, transmission=1.0, ior=1.45)
    white = principled(bpy, "Box", (0.85, 0.85, 0.8), roughness=0.4)
    primitive(bpy, "primitive_cylinder_add", red, vertices=48, radius=0.35, depth=1.2, location=(0.0, 0.6, 0.6))
    primitive(bpy, "primitive_cylinder_add", metal, vertices=48, radius=0.2, depth=0.25, location=(0.0, 0.6, 1.325))
    primitive(bpy, "primitive_uv_sphere_add", glass, segments=48, ring_count=24, radius=0.3,
              location=(0.75, 0.1, 0.3))
    box = primitive(bpy, "primitive_cube_add", white, smooth=False, size=0.6, location=(-0.85, 0.4, 0.3))
    box.rotation_euler = (0.0, 0.0, math.radians(30))
    area_light(bpy, scene, "Key", 90.0, 1.2, (-2.2, -1.8, 2.6), (55, 0, -50))
    area_light(bpy, scene, "Fill", 20.0, 2.0, (2.6, -1.5, 1.5), (70, 0, 60), colour=(0.85, 0.9, 1.0))
    area_light(bpy, scene, "Rim", 50.0, 0.8, (0.5, 2.0, 2.8), (-40, 0, 170))
    world_colour(bpy, scene, (0.5, 0.5, 0.5), 0.1)
    camera(bpy, scene, (0.0, -4.2, 1.3), (84, 0, 0), 45.0)
    return scene


def _window_wall(x0, x1, z0, z1, wx0, wx1, wz0, wz1, y):
    """A wall in the plane y with a rectangular hole [wx0, wx1] × [wz0, wz1]: eight quads."""
    xs, zs = (x0, wx0, wx1, x1), (z0, wz0, wz1, z1)
    verts = [(x, y, z) for z in zs for x in xs]
    faces = []
    for j in range(3):
        for i in range(3):
            if (i, j) == (1, 1):
                continue
            a = 4 * j + i
            faces.append((a, a + 1, a + 5, a + 4))
    return verts, faces


def _instances_tree(bpy, book):
    """A geometry-nodes tree: a line of points on the shelf, each instancing a scaled cube, set material."""
    tree = bpy.data.node_groups.new("Books", "GeometryNodeTree")
    tree.interface.new_socket("Geometry", in_out="INPUT", socket_type="NodeSocketGeometry")
    tree.interface.new_socket("Geometry", in_out="OUTPUT", socket_type="NodeSocketGeometry")
    nodes, links = tree.nodes, tree.links
    gin, gout = nodes.new("NodeGroupInput"), nodes.new("NodeGroupOutput")
    line = nodes.new("GeometryNodeMeshLine")
    line.inputs["Count"].default_value = 14
    line.inputs["Offset"].default_value = (0.11, 0.0, 0.0)
    pts = nodes.new("GeometryNodeMeshToPoints")
    cube = nodes.new("GeometryNodeMeshCube")
    cube.inputs["Size"].default_value = (0.08, 0.25, 0.32)
    inst = nodes.new("GeometryNodeInstanceOnPoints")
    rot = nodes.new("FunctionNodeRandomValue")
    rot.data_type = "FLOAT"
    rot.inputs["Min"].default_value = 0.85
    rot.inputs["Max"].default_value = 1.15
    setm = nodes.new("GeometryNodeSetMaterial")
    setm.inputs["Material"].default_value = book
    join = nodes.new("GeometryNodeJoinGeometry")
    real = nodes.new("GeometryNodeRealizeInstances")
    links.new(line.outputs["Mesh"], pts.inputs["Mesh"])
    links.new(pts.outputs["Points"], inst.inputs["Points"])
    links.new(cube.outputs["Mesh"], inst.inputs["Instance"])
    links.new(rot.outputs["Value"], inst.inputs["Scale"])
    links.new(inst.outputs["Instances"], setm.inputs["Geometry"])
    links.new(gin.outputs["Geometry"], join.inputs["Geometry"])
    links.new(setm.outputs["Geometry"], join.inputs["Geometry"])
    links.new(join.outputs["Geometry"], gout.inputs["Geometry"])
    nodes.remove(real)  # the books stay instances (the exporter reads them as such)
    return tree


def interior_scene(bpy, width, height, spp):
    """A room lit through a window; geometry-nodes books, a bevelled curve and a text object."""
    scene = new_scene(bpy, width, height, spp, 8)
    wall = principled(bpy, "Wall", (0.75, 0.72, 0.65), roughness=0.8)
    floor = principled(bpy, "Floor", (0.45, 0.3, 0.18), roughness=0.4)
    wood = principled(bpy, "Shelf", (0.3, 0.18, 0.1), roughness=0.5)
    book = principled(bpy, "Book", (0.15, 0.3, 0.55), roughness=0.6)
    pipe = principled(bpy, "Pipe", (0.8, 0.5, 0.3), roughness=0.3, metallic=1.0)
    letters = principled(bpy, "Letters", (0.9, 0.8, 0.1), roughness=0.4)
    X, Y, Z = 2.0, 2.5, 2.6  # the room spans x ∈ [-X, X], y ∈ [-Y, Y], z ∈ [0, Z]
    mesh_object(bpy, scene, "Floor", [(-X, -Y, 0), (X, -Y, 0), (X, Y, 0), (-X, Y, 0)], [(0, 1, 2, 3)], floor)
    mesh_object(bpy, scene, "Ceiling", [(-X, -Y, Z), (-X, Y, Z), (X, Y, Z), (X, -Y, Z)], [(0, 1, 2, 3)], wall)
    mesh_object(bpy, scene, "Back wall", [(-X, Y, 0), (X, Y, 0), (X, Y, Z), (-X, Y, Z)], [(0, 1, 2, 3)], wall)
    mesh_object(bpy, scene, "Front wall", [(-X, -Y, 0), (-X, -Y, Z), (X, -Y, Z), (X, -Y, 0)], [(0, 1, 2, 3)], wall)
    mesh_object(bpy, scene, "Right wall", [(X, -Y, 0), (X, -Y, Z), (X, Y, Z), (X, Y, 0)], [(0, 1, 2, 3)], wall)
    # the left wall (x = -X) has the window: built in the plane y = 0, then turned into x = -X
    v, f = _window_wall(-Y, Y, 0.0, Z, -0.9, 0.9, 0.8, 2.1, 0.0)
    mesh_object(bpy, scene, "Window wall", [(-X, x, z) for (x, _y, z) in v], f, wall)
    # the shelf on the back wall, its books instanced on points by geometry nodes
    sh = mesh_object(bpy, scene, "Shelf", [(x, y, z) for x in (-0.2, 1.6) for y in (Y - 0.35, Y) for z in (0.9, 0.95)],
                     [(0, 1, 3, 2), (4, 6, 7, 5), (0, 4, 5, 1), (2, 3, 7, 6), (0, 2, 6, 4), (1, 5, 7, 3)], wood)
    mod = sh.modifiers.new("Books", "NODES")
    mod.node_group = _instances_tree(bpy, book)
    mod.node_group.nodes["Mesh Line"].inputs["Start Location"].default_value = (-0.1, Y - 0.175, 1.11)
    # a bevelled Bézier curve: a copper pipe along the right wall
    cu = bpy.data.curves.new("Pipe", "CURVE")
    cu.dimensions, cu.bevel_depth, cu.bevel_resolution = "3D", 0.04, 4
    sp = cu.splines.new("BEZIER")
    sp.bezier_points.add(2)
    for p, co in zip(sp.bezier_points, ((X - 0.1, -1.5, 0.05), (X - 0.1, 0.0, 1.2), (X - 0.1, 1.8, 2.4))):
        p.co = co
        p.handle_left_type = p.handle_right_type = "AUTO"
    po = bpy.data.objects.new("Pipe", cu)
    po.data.materials.append(pipe)
    scene.collection.objects.link(po)
    # an extruded text object on the floor
    tc = bpy.data.curves.new("Sign", "FONT")
    tc.body, tc.extrude, tc.size, tc.align_x = "HELLO", 0.06, 0.45, "CENTER"
    to = bpy.data.objects.new("Sign", tc)
    to.location, to.rotation_euler = (0.3, 0.4, 0.0), (math.radians(90), 0.0, math.radians(-10))
    to.data.materials.append(letters)
    scene.collection.objects.link(to)
    sun = bpy.data.lights.new("Sun", "SUN")
    sun.energy, sun.angle = 10.0, math.radians(1.0)
    so = bpy.data.objects.new("Sun", sun)
    so.rotation_euler = (math.radians(55), 0.0, math.radians(-70))  # from the window's side, down into the room
    scene.collection.objects.link(so)
    world_colour(bpy, scene, (0.45, 0.6, 0.9), 1.0)
    camera(bpy, scene, (1.6, -2.2, 1.5), (80, 0, 35), 20.0)
    return scene


def _procedural_material(bpy, name, texture, ramp):
    """A Principled material whose Base Color is ``texture`` (a node idname) through a Color Ramp."""
    mat = bpy.data.materials.new(name)
    nt = mat.node_tree
    bsdf = nt.nodes["Principled BSDF"]
    bsdf.inputs["Roughness"].default_value = 0.5
    tex = nt.nodes.new(texture)
    tex.inputs["Scale"].default_value = 4.0
    cr = nt.nodes.new("ShaderNodeValToRGB")
    cr.color_ramp.elements[0].color = (*ramp[0], 1.0)
    cr.color_ramp.elements[1].color = (*ramp[1], 1.0)
    out = tex.outputs["Fac"] if "Fac" in tex.outputs else tex.outputs["Distance"]
    nt.links.new(out, cr.inputs["Fac"])
    nt.links.new(cr.outputs["Color"], bsdf.inputs["Base Color"])
    return mat


def procedural_scene(bpy, width, height, spp):
    """Procedural materials, a volume, a metaball and particle hair."""
    scene = new_scene(bpy, width, height, spp, 8)
    noise = _procedural_material(bpy, "Noise floor", "ShaderNodeTexNoise", ((0.1, 0.25, 0.08), (0.6, 0.55, 0.3)))
    voronoi = _procedural_material(bpy, "Voronoi", "ShaderNodeTexVoronoi", ((0.05, 0.05, 0.3), (0.9, 0.6, 0.2)))
    s = 5.0
    mesh_object(bpy, scene, "Floor", [(-s, -s, 0), (s, -s, 0), (s, s, 0), (-s, s, 0)], [(0, 1, 2, 3)], noise)
    primitive(bpy, "primitive_uv_sphere_add", voronoi, segments=48, ring_count=24, radius=0.5,
              location=(-1.1, 0.3, 0.5))
    # a cube of smoke: Principled Volume on the volume output, no surface
    smoke = bpy.data.materials.new("Smoke")
    nt = smoke.node_tree
    nt.nodes.remove(nt.nodes["Principled BSDF"])
    vol = nt.nodes.new("ShaderNodeVolumePrincipled")
    vol.inputs["Density"].default_value = 1.5
    vol.inputs["Color"].default_value = (0.8, 0.8, 0.85, 1.0)
    nt.links.new(vol.outputs["Volume"], nt.nodes["Material Output"].inputs["Volume"])
    primitive(bpy, "primitive_cube_add", smoke, smooth=False, size=0.8, location=(0.1, 0.9, 0.4))
    # a metaball of three elements
    mb = bpy.data.metaballs.new("Blob")
    mb.resolution = mb.render_resolution = 0.08
    for co, rad in (((0.0, 0.0, 0.0), 0.35), ((0.3, 0.1, 0.2), 0.28), ((-0.15, 0.2, 0.35), 0.22)):
        el = mb.elements.new()
        el.co, el.radius = co, rad
    mo = bpy.data.objects.new("Blob", mb)
    mo.location = (1.2, 0.0, 0.4)
    mo.data.materials.append(principled(bpy, "Blob", (0.8, 0.2, 0.5), roughness=0.3))
    scene.collection.objects.link(mo)
    # a sphere with particle hair
    fur = principled(bpy, "Fur", (0.5, 0.35, 0.2), roughness=0.6)
    head = primitive(bpy, "primitive_uv_sphere_add", fur, segments=32, ring_count=16, radius=0.35,
                     location=(0.0, -0.6, 0.35))
    head.modifiers.new("Hair", "PARTICLE_SYSTEM")
    ps = head.particle_systems[0].settings
    ps.type, ps.count, ps.hair_length = "HAIR", 400, 0.25
    area_light(bpy, scene, "Key", 250.0, 1.5, (-2.0, -2.0, 3.0), (45, 0, -45))
    world_colour(bpy, scene, (0.6, 0.7, 0.9), 0.5)
    camera(bpy, scene, (0.0, -4.5, 2.0), (70, 0, 0), 35.0)
    return scene


BUILDERS = {"product": product_scene, "interior": interior_scene, "procedural": procedural_scene}


# ----------------------------------------------------------------------------- rendering

def render_engine(bpy, scene, spp, time_limit=0.0):
    """Export and render with Spectral GI: (linear Rec.709 image, spp, seconds, export warning, core scene)."""
    from spectral_gi.addon.export import export_scene
    from spectral_gi.core import render

    exported = export_scene(bpy.context.evaluated_depsgraph_get(), scene)
    core_scene = exported.scene
    core_scene.settings.spp = int(spp)
    core_scene.settings.time_limit = float(time_limit)
    film, stats = render(core_scene, threads=os.cpu_count())
    return film.develop().rgb, film.spp, stats.seconds, exported.warning or "", core_scene


def render_cycles(scene, samples, max_bounces, time_limit=0.0):
    """Cycles at the Compare operator's matched settings (optionally a time limit): (image, seconds)."""
    from spectral_gi.addon.operators import compare

    s = scene.spectral_gi
    old = scene.cycles.time_limit
    scene.cycles.time_limit = float(time_limit)
    try:
        t0 = time.perf_counter()
        rgb = compare.render_cycles_rgb(scene, samples, max_bounces, s.pixel_filter, s.filter_width, 1)
        return rgb, time.perf_counter() - t0
    finally:
        scene.cycles.time_limit = old


def chroma_error(img, ref):
    """Mean ΔE00 of ``img`` against ``ref`` once each pixel of ``img`` is scaled to the
    reference's luminance: the error of colour alone (coloured noise), without that of brightness."""
    from spectral_gi.core.colour.compare import delta_e00_map, image_luminance

    y, yr = image_luminance(img), image_luminance(ref)
    scale = np.where(y > 0.0, yr / np.where(y > 0.0, y, 1.0), 1.0)
    return float(delta_e00_map(img * scale[..., None], ref, 683.0).mean())


def run_scene(bpy, name, args):
    from spectral_gi.core import compare_images, delta_e_image, side_by_side, write_png

    w, h = args.size
    scene = BUILDERS[name](bpy, w, h, args.spp)
    bounces = scene.spectral_gi.max_bounces
    # the kernels a scene needs (media, textures) compile once; a 1-sample render first keeps
    # that compile out of the timed render
    render_engine(bpy, scene, 1)
    ours, spp, t_ours, warning, core_scene = render_engine(bpy, scene, args.spp)
    if args.save_scenes:
        from spectral_gi.core import save_scene

        os.makedirs(args.save_scenes, exist_ok=True)
        save_scene(core_scene, os.path.join(args.save_scenes, f"{name}.json"))
    cyc, t_cyc = render_cycles(scene, args.spp, bounces)
    # equal time: Cycles given the engine's render time; the samples it reaches are read off its speed
    cyc_t, t_cyc_t = render_cycles(scene, 1 << 16, bounces, time_limit=t_ours)
    ref, t_ref = render_cycles(scene, args.ref_spp, bounces)
    rep, de = compare_images(ours, cyc)
    rr = {k: compare_images(img, ref)[0] for k, img in (("ours", ours), ("cycles", cyc), ("cycles_time", cyc_t))}
    if args.save_scenes:  # the images, for analyses of the noise (linear Rec.709, rows top-down)
        np.savez_compressed(os.path.join(args.save_scenes, f"{name}_images.npz"), engine=ours, cycles=cyc,
                            cycles_equal_time=cyc_t, reference=ref)
    cyc_spp_time = int(round(args.spp * t_cyc_t / max(t_cyc, 1e-9)))
    write_png(os.path.join(args.out, f"artist_{name}_side_by_side.png"), side_by_side(ours, cyc))
    write_png(os.path.join(args.out, f"artist_{name}_dE.png"), delta_e_image(de))
    row = {"scene": name, "size": [w, h], "spp": spp, "seconds_engine": t_ours, "seconds_cycles": t_cyc,
           "luminance_ratio": rep["luminance_ratio"], "de_mean": rep["delta_e00_mean"],
           "de_p95": rep["delta_e00_p95"], "luminance_ratio_vs_reference": rr["ours"]["luminance_ratio"],
           "rel_rmse_engine": rr["ours"]["relative_rmse"], "rel_rmse_cycles": rr["cycles"]["relative_rmse"],
           "rel_rmse_cycles_equal_time": rr["cycles_time"]["relative_rmse"], "cycles_seconds_equal_time": t_cyc_t,
           "de_p95_engine_vs_reference": rr["ours"]["delta_e00_p95"],
           "de_p95_cycles_vs_reference": rr["cycles"]["delta_e00_p95"],
           "chroma_de_engine": chroma_error(ours, ref), "chroma_de_cycles": chroma_error(cyc, ref),
           "cycles_spp_equal_time_estimate": cyc_spp_time, "ref_spp": args.ref_spp, "seconds_reference": t_ref,
           "warning": warning}
    print(f"\n[{name}] {w}x{h}, {spp} spp: engine {t_ours:.1f} s, Cycles {t_cyc:.1f} s; luminance ratio "
          f"{row['luminance_ratio']:.3f}, ΔE00 mean {row['de_mean']:.2f} p95 {row['de_p95']:.2f}; relative RMSE vs "
          f"Cycles {args.ref_spp} spp: engine {row['rel_rmse_engine']:.3f}, Cycles {row['rel_rmse_cycles']:.3f} "
          f"(equal samples), Cycles {row['rel_rmse_cycles_equal_time']:.3f} (equal time, ~{cyc_spp_time} spp); "
          f"ΔE00 p95 vs the reference: engine {row['de_p95_engine_vs_reference']:.2f}, Cycles "
          f"{row['de_p95_cycles_vs_reference']:.2f}; colour-only ΔE00 mean: engine {row['chroma_de_engine']:.2f}, "
          f"Cycles {row['chroma_de_cycles']:.2f}")
    print(f"[{name}] export warning: {warning or '(none)'}", flush=True)
    return row


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="160x90, 16 spp, reference 128 spp")
    ap.add_argument("--spp", type=int, default=None)
    ap.add_argument("--ref-spp", type=int, default=None)
    ap.add_argument("--size", default=None, help="width x height (default 320x180)")
    ap.add_argument("--only", default=",".join(SCENES))
    ap.add_argument("--out", default=os.path.join(HERE, "..", "docs", "images"))
    ap.add_argument("--save-scenes", default=None)
    ap.add_argument("--no-record", action="store_true", help="do not write benchmarks/results/artist_scenes.json")
    args = ap.parse_args(argv)
    args.spp = args.spp or (16 if args.quick else 32)
    args.ref_spp = args.ref_spp or (128 if args.quick else 512)
    args.size = tuple(int(v) for v in (args.size or ("160x90" if args.quick else "320x180")).lower().split("x"))
    names = [n.strip() for n in args.only.split(",") if n.strip()]
    for n in names:
        if n not in BUILDERS:
            ap.error(f"--only: unknown scene {n!r} (expected {', '.join(SCENES)})")
    os.makedirs(args.out, exist_ok=True)

    import bpy

    rows = [run_scene(bpy, n, args) for n in names]
    if not args.no_record:
        table = results.table(
            f"Artists' scenes, Spectral GI vs Cycles, {args.size[0]}×{args.size[1]}, {args.spp} spp (relative RMSE of "
            f"luminance against Cycles at {args.ref_spp} spp; equal time: Cycles given the engine's render time)",
            ["scene", "luminance ratio", "ΔE00 mean", "ΔE00 p95", "rel. RMSE engine", "rel. RMSE Cycles (equal spp)",
             "rel. RMSE Cycles (equal time)", "ΔE00 p95 vs ref.: engine / Cycles",
             "colour-only ΔE00 vs ref.: engine / Cycles", "engine (s)", "Cycles (s)", "export warning"],
            [[r["scene"], round(r["luminance_ratio"], 3), round(r["de_mean"], 2), round(r["de_p95"], 2),
              round(r["rel_rmse_engine"], 3), round(r["rel_rmse_cycles"], 3), round(r["rel_rmse_cycles_equal_time"], 3),
              f"{r['de_p95_engine_vs_reference']:.2f} / {r['de_p95_cycles_vs_reference']:.2f}",
              f"{r['chroma_de_engine']:.2f} / {r['chroma_de_cycles']:.2f}",
              round(r["seconds_engine"], 1), round(r["seconds_cycles"], 1), r["warning"] or "none"] for r in rows])
        results.write("artist_scenes", [table], conditions={"size": list(args.size), "spp": args.spp,
                                                             "ref_spp": args.ref_spp, "scenes": names,
                                                             "rows": json.loads(json.dumps(rows))})
    return 0


if __name__ == "__main__":
    sys.exit(main())
