"""The office of the lighting-analysis docs: Blender scene to lighting report in one click.

    PYTHONPATH=<folder holding the spectral_gi checkout> python benchmarks/office_report.py [--out docs/images]

A 6 × 4 × 2.8 m room (floor reflectance 0.2, walls 0.5, ceiling 0.7, Lambertian) with four
downlights 2.7 m above the floor, each a point light with the shipped sample profile
*Cosine Downlight* (``presets/ies/cosine_downlight.ldt``: I = 1000 cd · cos θ, 1000π lm),
is built in Blender (bpy as a module, the add-on registered from this checkout). The script
adds the 0.75 m work plane over the room's floor with a 0.5 m band at the walls (as
*Lighting Report* does when there is none), sets MF = 0.8 and 256 samples per point, and
runs *Lighting Report*; it copies the report page to ``office_report.png`` (drawn at
100 dpi, so the page stays small) and prints the statistics.
"""
import argparse
import os
import tempfile

ROOM = (6.0, 4.0, 2.8)  # m
LUMINAIRES = ((1.5, 1.0), (4.5, 1.0), (1.5, 3.0), (4.5, 3.0))  # m, plan positions
MOUNTING = 2.7  # m above the floor
REFLECTANCE = {"Floor": 0.2, "Walls": 0.5, "Ceiling": 0.7}
PROFILE = "PRESET_cosine_downlight"
I0 = 1000.0  # cd at nadir of that profile


def _diffuse(bpy, name, rho):
    mat = bpy.data.materials.new(name)
    if mat.node_tree is None:
        mat.use_nodes = True
    tree = mat.node_tree
    tree.nodes.clear()
    out = tree.nodes.new("ShaderNodeOutputMaterial")
    bsdf = tree.nodes.new("ShaderNodeBsdfDiffuse")
    bsdf.inputs["Color"].default_value = (rho, rho, rho, 1.0)
    tree.links.new(bsdf.outputs["BSDF"], out.inputs["Surface"])
    return mat


def build_office(bpy):
    """The office in the current (empty) scene; returns the room object (active and selected)."""
    w, d, h = ROOM
    v = [(x, y, z) for z in (0.0, h) for (x, y) in ((0, 0), (w, 0), (w, d), (0, d))]
    faces = [(0, 1, 2, 3), (4, 7, 6, 5), (0, 4, 5, 1), (1, 5, 6, 2), (2, 6, 7, 3), (3, 7, 4, 0)]
    me = bpy.data.meshes.new("Office")
    me.from_pydata(v, [], faces)
    for name in ("Floor", "Walls", "Ceiling"):
        me.materials.append(_diffuse(bpy, name, REFLECTANCE[name]))
    for poly, slot in zip(me.polygons, (0, 2, 1, 1, 1, 1)):
        poly.material_index = slot
    me.update()
    room = bpy.data.objects.new("Office", me)
    scene = bpy.context.scene
    scene.collection.objects.link(room)
    cam = bpy.data.objects.new("Camera", bpy.data.cameras.new("Camera"))
    cam.location = (w / 2, -0.5 * d, 1.6)
    cam.rotation_euler = (1.35, 0.0, 0.0)
    scene.collection.objects.link(cam)
    scene.camera = cam
    for k, (x, y) in enumerate(LUMINAIRES):
        data = bpy.data.lights.new(f"Downlight {k + 1}", "POINT")
        data.shadow_soft_size = 0.0
        data.spectral_gi.profile = PROFILE
        data.spectral_gi.profile_brightness = "FILE"
        obj = bpy.data.objects.new(data.name, data)
        obj.location = (x, y, MOUNTING)
        scene.collection.objects.link(obj)
    bpy.context.view_layer.objects.active = room
    room.select_set(True)
    return room


def direct_illuminance(x, y, z):
    """The direct illuminance (lx) on a horizontal plane at (x, y, z) from the four downlights, by hand:
    Σ I(θ) cos θ / d² with I(θ) = I0 cos θ, cos θ = Δz / d, so Σ I0 Δz² / d⁴."""
    dz = MOUNTING - z
    return sum(I0 * dz * dz / ((x - lx) ** 2 + (y - ly) ** 2 + dz * dz) ** 2 for lx, ly in LUMINAIRES)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--out", default=os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "docs", "images"))
    ap.add_argument("--samples", type=int, default=256)
    args = ap.parse_args()

    import bpy

    from spectral_gi.addon import registration
    from spectral_gi.addon.operators import lux as ops
    from spectral_gi.core import lux

    registration.register()
    bpy.ops.wm.read_homefile(use_empty=True)
    build_office(bpy)
    folder = tempfile.mkdtemp(prefix="spectral-gi-office-")
    scene = bpy.context.scene
    scene.spectral_gi_report_dir = folder
    ops.add_workplane(bpy.context, bpy.data.objects["Office"], scene.spectral_gi_workplane_height,
                      scene.spectral_gi_workplane_band)
    wp = bpy.data.objects["Work Plane"]
    wp.spectral_gi_lux.samples = args.samples
    wp.spectral_gi_lux.maintenance_factor = 0.8
    assert bpy.ops.spectral_gi.lux_report() == {"FINISHED"}
    surface, e, se, spp, luminaires = ops.saved_result(wp)
    os.makedirs(args.out, exist_ok=True)
    out = os.path.join(args.out, "office_report.png")
    lux.render_report(surface, e, se, samples=spp, luminaires=luminaires, project="Office 6 × 4 m",
                      date="", png_path=out, dpi=100)
    s = wp.spectral_gi_lux
    print(f"work plane: {s.grid_cols} × {s.grid_rows} points, Ē {s.mean:.1f} lx, Emin {s.minimum:.1f} lx, "
          f"Emax {s.maximum:.1f} lx, U0 {s.u0:.3f}, Emin/Emax {s.ud:.3f}, MF {s.mf_used}, {spp} samples per point, "
          f"largest rel. std. error {100 * s.max_rel_error:.2f} %")
    print(f"wrote {out} ({os.path.getsize(out) // 1024} KB); the full report is in {folder}")


if __name__ == "__main__":
    main()
