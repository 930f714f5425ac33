"""The "Add Cornell Box" operator: the published Cornell box as Blender objects."""
import bpy

CORNELL_RESOLUTION = (256, 256)


def _colour(rgb):
    """A colour for a Blender socket: three floats, negative (out-of-gamut) parts clipped to 0."""
    return tuple(max(0.0, float(c)) for c in rgb[:3])


def _diffuse(name, rgb):
    """A Diffuse BSDF material: the published box is Lambertian (a Principled BSDF would add a glossy coat)."""
    mat = bpy.data.materials.new(name)
    mat.diffuse_color = (*rgb, 1.0)
    tree = mat.node_tree
    if tree is None:  # Blender < 5.0
        mat.use_nodes = True
        tree = mat.node_tree
    tree.nodes.clear()
    out = tree.nodes.new("ShaderNodeOutputMaterial")
    bsdf = tree.nodes.new("ShaderNodeBsdfDiffuse")
    bsdf.inputs["Color"].default_value = (*rgb, 1.0)
    bsdf.inputs["Roughness"].default_value = 0.0
    tree.links.new(bsdf.outputs["BSDF"], out.inputs["Surface"])
    return mat


def _emission(name, rgb, strength):
    mat = bpy.data.materials.new(name)
    mat.diffuse_color = (*rgb, 1.0)
    tree = mat.node_tree
    if tree is None:
        mat.use_nodes = True
        tree = mat.node_tree
    tree.nodes.clear()
    out = tree.nodes.new("ShaderNodeOutputMaterial")
    out.location = (300, 0)
    em = tree.nodes.new("ShaderNodeEmission")
    em.inputs["Color"].default_value = (*rgb, 1.0)
    em.inputs["Strength"].default_value = strength
    tree.links.new(em.outputs["Emission"], out.inputs["Surface"])
    return mat


def _join_quads(me):
    """Merge the triangle pairs of the published quads back into quads (cosmetic)."""
    import math

    import bmesh

    bm = bmesh.new()
    try:
        bm.from_mesh(me)
        bmesh.ops.join_triangles(bm, faces=bm.faces[:], angle_face_threshold=math.radians(1.0),
                                 angle_shape_threshold=math.radians(180.0))
        bm.to_mesh(me)
    except (TypeError, ValueError, RuntimeError):
        pass  # keep triangles
    finally:
        bm.free()
    me.update()


def _black_world(name):
    world = bpy.data.worlds.new(name)
    world.color = (0.0, 0.0, 0.0)
    tree = world.node_tree
    if tree is not None:
        for node in tree.nodes:
            if node.type == "BACKGROUND":
                node.inputs["Color"].default_value = (0.0, 0.0, 0.0, 1.0)
                node.inputs["Strength"].default_value = 0.0
    return world


class SPECTRALGI_OT_add_cornell_box(bpy.types.Operator):
    """Add the Cornell box (Cornell Program of Computer Graphics' published geometry, camera and colours)
to the scene, with its camera as the active camera, a black world and a 256 × 256 resolution"""

    bl_idname = "spectral_gi.add_cornell_box"
    bl_label = "Add Cornell Box"
    bl_options = {"REGISTER", "UNDO"}

    @classmethod
    def poll(cls, context):
        return context.scene is not None

    def execute(self, context):
        try:
            self._build(context)
        except Exception as exc:
            import traceback

            traceback.print_exc()
            self.report({"ERROR"}, f"Spectral GI: cannot build the Cornell box: {exc}")
            return {"CANCELLED"}
        return {"FINISHED"}

    def _build(self, context):
        from mathutils import Matrix

        from ...core import cornell_box, emission_to_rgb, reflectance_to_rgb

        scene = context.scene
        ref = cornell_box(*CORNELL_RESOLUTION)  # meshes in Blender axes and metres, camera matrix
        coll = bpy.data.collections.new("Cornell Box")
        scene.collection.children.link(coll)

        # Colours from the published spectra: reflectances as seen under D65, the light as
        # Blender colour × strength of the same luminance.
        materials = {}
        for m in ref.materials:
            if m.emission >= 0:
                rgb, strength = emission_to_rgb(ref.spectra.coeffs[m.emission], m.emission_luminance)
                materials[m.name] = _emission(f"Cornell {m.name}", _colour(rgb), float(strength))
            else:
                rgb = reflectance_to_rgb(ref.spectra.coeffs[m.reflectance])
                materials[m.name] = _diffuse(f"Cornell {m.name}", _colour(rgb))

        for mesh in ref.meshes:
            me = bpy.data.meshes.new(f"Cornell {mesh.name}")
            me.from_pydata(mesh.positions.tolist(), [], mesh.indices.tolist())
            _join_quads(me)
            mat_name = ref.materials[int(mesh.material[0])].name
            me.materials.append(materials[mat_name])
            obj = bpy.data.objects.new(f"Cornell {mesh.name}", me)
            coll.objects.link(obj)

        cam_ref = ref.camera
        cam = bpy.data.cameras.new("Cornell Camera")
        cam.lens = cam_ref.lens_mm
        cam.sensor_width = cam_ref.sensor_width_mm
        cam.sensor_height = cam_ref.sensor_height_mm
        cam.sensor_fit = "AUTO"
        cam_obj = bpy.data.objects.new("Cornell Camera", cam)
        cam_obj.matrix_world = Matrix(cam_ref.to_world.tolist())
        coll.objects.link(cam_obj)
        scene.camera = cam_obj

        scene.render.resolution_x, scene.render.resolution_y = CORNELL_RESOLUTION
        scene.render.resolution_percentage = 100
        scene.world = _black_world("Cornell Box World")
        self.report({"INFO"}, "Spectral GI: added the Cornell box (camera, black world, 256 × 256)")
