"""Properties > Material: the Spectral GI panel (BSDF model override, parameters, spectra).

Shown for every render engine (as the render panel is), so that it is there when Spectral
GI's own engine (``SPECTRAL_GI``) is active and when rendering with the Render GI button
under another engine. With the Spectral GI engine active, a "Surface" sub-panel also
shows the node tree feeding the material output (Cycles' and EEVEE's panels are hidden
then).
"""
import bpy

ENGINE_ID = "SPECTRAL_GI"

PARAMETERS = {  # which settings each model uses, in drawing order
    "AUTO": (),
    "LAMBERT": ("spectrum", "two_sided"),
    "PHONG": ("spectrum", "specular_color", "exponent", "two_sided"),
    "BLINN_PHONG": ("spectrum", "specular_color", "exponent", "two_sided"),
    "WARD": ("spectrum", "specular_color", "alpha_x", "alpha_y", "ward_variant", "two_sided"),
    "LAFORTUNE": ("spectrum", "specular_color", "lobe_count", "lobes", "two_sided"),
    "MIRROR": ("spectrum", "two_sided"),
    "CONDUCTOR": ("spectrum", "alpha_x", "alpha_y", "two_sided"),
    "GLASS": ("spectrum", "alpha_x", "alpha_y"),
}
PRESET_PROPERTY = {"CONDUCTOR": "metal_preset", "GLASS": "glass_preset"}  # others: reflectance_preset


def draw_settings(layout, settings):
    """Draw ``material.spectral_gi`` (also used by tests with a mock layout)."""
    col = layout.column()
    col.use_property_split = True
    col.use_property_decorate = False
    col.prop(settings, "model")
    model = settings.model
    if model == "AUTO":
        col.label(text="Translated from the shader nodes", icon="NODETREE")
        col.prop(settings, "physical_layering")
        return
    for name in PARAMETERS[model]:
        if name == "spectrum":
            col.prop(settings, "spectrum")
            if settings.spectrum == "PRESET":
                col.prop(settings, PRESET_PROPERTY.get(model, "reflectance_preset"))
            elif settings.spectrum == "FILE":
                col.prop(settings, "spectrum_file")
                if model in PRESET_PROPERTY:
                    col.label(text="Files are reflectances: this model uses the node colour", icon="INFO")
        elif name == "lobes":
            for k in range(1, settings.lobe_count + 1):
                col.prop(settings, f"lobe_{k}")
        else:
            col.prop(settings, name)


class SPECTRALGI_PT_material(bpy.types.Panel):
    bl_idname = "SPECTRALGI_PT_material"
    bl_label = "Spectral GI"
    bl_space_type = "PROPERTIES"
    bl_region_type = "WINDOW"
    bl_context = "material"

    @classmethod
    def poll(cls, context):
        return getattr(context, "material", None) is not None

    def draw(self, context):
        settings = getattr(context.material, "spectral_gi", None)
        if settings is None:
            self.layout.label(text="Spectral GI add-on properties are not registered", icon="ERROR")
            return
        draw_settings(self.layout, settings)


class SPECTRALGI_PT_material_surface(bpy.types.Panel):
    bl_idname = "SPECTRALGI_PT_material_surface"
    bl_label = "Surface"
    bl_space_type = "PROPERTIES"
    bl_region_type = "WINDOW"
    bl_context = "material"
    bl_parent_id = "SPECTRALGI_PT_material"

    @classmethod
    def poll(cls, context):
        mat = getattr(context, "material", None)
        return mat is not None and context.scene.render.engine == ENGINE_ID

    def draw(self, context):
        mat = context.material
        tree = mat.node_tree
        output = None
        if tree is not None:
            output = next((n for n in tree.nodes if n.bl_idname == "ShaderNodeOutputMaterial"
                           and getattr(n, "is_active_output", False)), None)
        if output is None:
            self.layout.prop(mat, "diffuse_color", text="Viewport Colour")
            return
        self.layout.template_node_view(tree, output, output.inputs["Surface"])


classes = (SPECTRALGI_PT_material, SPECTRALGI_PT_material_surface)
