"""The one export warning names everything exported with a substitute or not at all: a
procedural texture replaced by a constant, particle hair and a Curves object (tessellated), a
shadow catcher, motion blur, a Principled coat and sheen over a metal — each with the object and node names;
ray visibility and light linking, which carry over, are not in it."""
import re

import pytest

pytestmark = pytest.mark.blender


def test_every_unsupported_feature_is_named_in_the_warning(ext, bpy):
    b = ext.build
    b.camera()
    mat = b.principled("Varnish", (0.5, 0.5, 0.5))
    tree = mat.node_tree
    node = next(n for n in tree.nodes if n.type == "BSDF_PRINCIPLED")
    node.inputs["Coat Weight"].default_value = 0.5
    node.inputs["Sheen Weight"].default_value = 0.3
    node.inputs["Metallic"].default_value = 0.5  # coat and sheen layer the dielectric half only
    noise = tree.nodes.new("ShaderNodeTexGabor")  # a texture shader programs do not support
    noise.name = "Grain"
    tree.links.new(noise.outputs[0], node.inputs["Base Color"])
    floor = b.plane("Floor", size=4.0, material=mat)
    floor.is_shadow_catcher = True
    ghost = b.cube("Ghost", location=(0.0, 0.0, 1.0))
    ghost.visible_shadow = False
    ghost.visible_glossy = False
    furry = b.cube("Furry", location=(2.0, 0.0, 1.0))
    furry.modifiers.new("Fur", "PARTICLE_SYSTEM")
    furry.particle_systems[0].settings.type = "HAIR"
    furry.particle_systems[0].name = "Fur"
    strands = bpy.data.hair_curves.new("Strands")
    strands.add_curves([2])
    hair = bpy.data.objects.new("Strands", strands)
    b.link(hair)
    lamp = b.light("Key", "POINT", location=(0.0, -1.0, 3.0), energy=100.0)
    coll = bpy.data.collections.new("Lit")
    coll.objects.link(ghost)
    lamp.light_linking.receiver_collection = coll
    b.scene.render.use_motion_blur = True
    b.resolution(8, 8)
    w = b.export(ext).warning
    assert w is not None
    for expected in ("Varnish/Principled BSDF: coat 0.5", "Varnish/Principled BSDF: sheen 0.3",  # coat, sheen
                     "'Grain'", "Base Color",  # the procedural texture and the input it drove
                     "'Floor'",  # as the material's user and as a shadow catcher
                     "shadow catchers", "Furry/Fur: hair rendered as", "Strands: curves rendered as",
                     "motion blur"):
        assert expected in w, (expected, w)
    assert "ray visibility" not in w and "linking" not in w, w
    # only the floor is a shadow catcher (a light's flag means nothing)
    assert re.search(r"shadow catchers \(rendered as ordinary surfaces\): 'Floor'(;|\.|$)", w), w
