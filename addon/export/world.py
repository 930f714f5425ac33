"""The Blender world → a constant background."""
from .convert import rgb_of
from .nodes import active_output, input_value, surface_node

BACKGROUND_NODES = ("BACKGROUND", "EMISSION")


def export_world(ctx, world):
    """A core World: the Background node's colour × strength (or ``world.color``), or black."""
    from ...core import World, emission_luminance

    if world is None:
        return World()
    name = world.name
    tree = world.node_tree
    if tree is None:
        rgb, strength = rgb_of(world.color), 1.0
    else:
        output = active_output(tree, "ShaderNodeOutputWorld")
        node = surface_node(output)
        if node is None:
            return World()
        if node.type not in BACKGROUND_NODES:
            ctx.skip("world shader nodes", f"{name}/{node.name}")
            return World()
        rgb = input_value(ctx, f"world {name}", node, ("Color",), "colour")
        strength = input_value(ctx, f"world {name}", node, ("Strength",), "value")
    if not strength > 0.0 or not max(rgb) > 0.0:
        return World()
    return World(background=ctx.emission(f"world {name}", rgb), luminance=float(emission_luminance(rgb, strength)))
