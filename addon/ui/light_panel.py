"""Properties > Light data: the light's shape and its photometric unit and spectrum (Spectral GI engine)."""
import bpy

ENGINE = "SPECTRAL_GI"
# units offered per light type (the export rejects the others, naming the problem)
UNITS_FOR = {
    "POINT": ("BLENDER", "LUMEN", "CANDELA"),
    "SPOT": ("BLENDER", "LUMEN", "CANDELA"),
    "SUN": ("BLENDER", "LUX"),
    "AREA": ("BLENDER", "LUMEN", "CANDELA", "NIT"),
}


class SPECTRALGI_PT_light(bpy.types.Panel):
    bl_idname = "SPECTRALGI_PT_light"
    bl_label = "Light"
    bl_space_type = "PROPERTIES"
    bl_region_type = "WINDOW"
    bl_context = "data"
    COMPAT_ENGINES = {ENGINE}

    @classmethod
    def poll(cls, context):
        return (context.engine in cls.COMPAT_ENGINES and context.light is not None
                and getattr(context.light, "spectral_gi", None) is not None)

    def draw(self, context):
        from ..properties.light import UNIT_SYMBOLS

        light = context.light
        s = light.spectral_gi
        layout = self.layout
        layout.row().prop(light, "type", expand=True)
        col = layout.column()
        col.use_property_split = True
        col.use_property_decorate = False

        # brightness
        col.prop(s, "unit")
        if s.unit not in UNITS_FOR.get(light.type, ()):
            col.label(text=f"{s.unit.title()} does not apply to a {light.type.lower()} light", icon="ERROR")
        if s.unit == "BLENDER":
            col.prop(light, "energy", text="Strength (W/m²)" if light.type == "SUN" else "Power (W)")
            col.prop(light, "exposure")
        else:
            col.prop(s, "value", text=f"Value ({UNIT_SYMBOLS.get(s.unit, '')})")

        col.prop(light, "use_shadow", text="Cast Shadow")

        # colour / spectrum
        col.separator()
        col.prop(s, "spectrum")
        if s.spectrum == "RGB":
            col.prop(light, "color")
            row = col.row(heading="Temperature")
            row.prop(light, "use_temperature", text="")
            sub = row.row()
            sub.active = light.use_temperature
            sub.prop(light, "temperature", text="")
        elif s.spectrum == "BLACKBODY":
            col.prop(s, "temperature")
        elif s.spectrum == "ILLUMINANT":
            col.prop(s, "illuminant")
        elif s.spectrum == "FILE":
            col.prop(s, "spectrum_file")
        else:
            col.prop(s, "led")

        # photometric profile (IES / EULUMDAT)
        if light.type in ("POINT", "SPOT") and hasattr(s, "profile"):
            col.separator()
            col.prop(s, "profile")
            if s.profile == "FILE":
                col.prop(s, "profile_path", text="File")
            if s.profile != "NONE":
                col.prop(s, "profile_brightness", text="Brightness")

        # shape
        col.separator()
        if light.type in ("POINT", "SPOT"):
            col.prop(light, "shadow_soft_size", text="Radius")
        if light.type == "SPOT":
            col.prop(light, "spot_size", text="Spot Size")
            col.prop(light, "spot_blend", text="Blend", slider=True)
            col.prop(light, "show_cone")
        elif light.type == "SUN":
            col.prop(light, "angle")
        elif light.type == "AREA":
            col.prop(light, "shape")
            sub = col.column(align=True)
            if light.shape in ("SQUARE", "DISK"):
                sub.prop(light, "size")
            else:
                sub.prop(light, "size", text="Size X")
                sub.prop(light, "size_y", text="Y")
            if s.unit == "BLENDER":
                col.prop(light, "normalize")


classes = (SPECTRALGI_PT_light,)
