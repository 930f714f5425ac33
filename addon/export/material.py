"""Blender materials → core materials (diffuse reflectance + emission)."""
from .convert import rgb_of
from .nodes import active_output, input_value, surface_node

SUPPORTED_SURFACES = ("BSDF_PRINCIPLED", "BSDF_DIFFUSE", "EMISSION")
COLOUR_INPUTS = ("Base Color", "Color")


def material_key(mat):
    return ("material", mat.name_full) if mat is not None else None


def export_material(ctx, mat):
    """Index into ``ctx.materials`` of the core material for Blender material ``mat`` (None: default grey)."""
    if mat is None:
        return ctx.default_material()
    return ctx.material_index(material_key(mat), lambda: build_material(ctx, mat))


def _emission(ctx, name, rgb, strength):
    """(spectrum index, luminance cd/m²) of an emitter, or (-1, 0.0) when it emits nothing."""
    from ...core import emission_luminance

    if not strength > 0.0 or not max(rgb) > 0.0:
        return -1, 0.0
    return ctx.emission(f"{name} emission", rgb), float(emission_luminance(rgb, strength))


def build_material(ctx, mat):
    from ...core import Material

    name = mat.name
    tree = mat.node_tree
    output = active_output(tree, "ShaderNodeOutputMaterial")
    if output is None:
        # No node tree (or no output): Blender's viewport colour stands in.
        return Material(name=name, reflectance=ctx.reflectance(name, rgb_of(mat.diffuse_color)))
    node = surface_node(output)
    if node is None:
        return Material(name=name)  # an unconnected output renders black
    kind = node.type
    if kind == "BSDF_PRINCIPLED":
        base = input_value(ctx, name, node, ("Base Color",), "colour")
        refl = ctx.reflectance(name, base)
        e_rgb = input_value(ctx, name, node, ("Emission Color", "Emission"), "colour") or (0.0, 0.0, 0.0)
        e_strength = input_value(ctx, name, node, ("Emission Strength",), "value")
        e_strength = 1.0 if e_strength is None else e_strength
        spec, lum = _emission(ctx, name, e_rgb, e_strength)
        for inp in ("Metallic", "Transmission Weight"):
            v = input_value(ctx, name, node, (inp,), "value")
            if v is not None and v > 0.0:
                ctx.note(f"{name}: {inp} ignored (rendered as diffuse)")
        return Material(name=name, reflectance=refl, emission=spec, emission_luminance=lum)
    if kind == "BSDF_DIFFUSE":
        colour = input_value(ctx, name, node, ("Color",), "colour")
        return Material(name=name, reflectance=ctx.reflectance(name, colour))
    if kind == "EMISSION":
        colour = input_value(ctx, name, node, ("Color",), "colour")
        strength = input_value(ctx, name, node, ("Strength",), "value")
        spec, lum = _emission(ctx, name, colour, strength)
        return Material(name=name, emission=spec, emission_luminance=lum)
    # Unsupported shader: listed in the warning; its colour (if any) stands in as a diffuse colour.
    ctx.skip("shader nodes", f"{name}/{node.name}")
    colour = None
    for inp in COLOUR_INPUTS:
        if node.inputs.get(inp) is not None and node.inputs[inp].type == "RGBA":
            colour = input_value(ctx, name, node, (inp,), "colour")
            break
    if colour is None:
        from .context import DEFAULT_GREY
        colour = DEFAULT_GREY
    return Material(name=name, reflectance=ctx.reflectance(name, colour))
