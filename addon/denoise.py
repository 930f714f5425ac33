"""Denoising of final renders: Blender's compositor Denoise node (OpenImageDenoise) on Combined.

With Render > Denoise on, the scene's compositing node group gets one Denoise node named
``DENOISE_NODE`` between the Render Layers node's Image output and what it fed, with the
Albedo and Normal passes (enabled on every view layer) as its guides; with it off, the node
is muted, which passes the image through unchanged. A scene without a compositing node
group gets one (Render Layers → Denoise → Group Output). Only the composited image is
denoised: the passes of the render result (Luminance, XYZ, Lab, Illuminance, …) are the
renderer's own, unfiltered (docs/user/blender.md says why).
"""
DENOISE_NODE = "Spectral GI Denoise"
GROUP_NAME = "Spectral GI Compositing"


def _render_layers_node(tree):
    return next((n for n in tree.nodes if n.bl_idname == "CompositorNodeRLayers"), None)


def _new_group(bpy):
    tree = bpy.data.node_groups.new(GROUP_NAME, "CompositorNodeTree")
    tree.interface.new_socket("Image", in_out="OUTPUT", socket_type="NodeSocketColor")
    rl = tree.nodes.new("CompositorNodeRLayers")
    out = tree.nodes.new("NodeGroupOutput")
    rl.location, out.location = (-400, 0), (300, 0)
    tree.links.new(rl.outputs["Image"], out.inputs[0])
    return tree


def _link_guides(tree, rl, node):
    for name in ("Albedo", "Normal"):
        src = rl.outputs.get(name)
        if src is not None and not any(link.from_socket == src for link in node.inputs[name].links):
            tree.links.new(src, node.inputs[name])


def sync_compositor(scene):
    """Make ``scene``'s compositor match ``scene.spectral_gi.use_denoise``. Returns the Denoise node or None."""
    import bpy

    on = bool(getattr(getattr(scene, "spectral_gi", None), "use_denoise", False))
    tree = scene.compositing_node_group
    if tree is None:
        if not on:
            return None
        tree = _new_group(bpy)
        scene.compositing_node_group = tree
    node = tree.nodes.get(DENOISE_NODE)
    if on:
        for view_layer in scene.view_layers:  # the guides
            s = getattr(view_layer, "spectral_gi", None)
            if s is not None:
                s.use_pass_albedo = True
                s.use_pass_normal = True
    if node is None:
        if not on:
            return None
        rl = _render_layers_node(tree)
        if rl is None:
            rl = tree.nodes.new("CompositorNodeRLayers")
            rl.location = (-400, 0)
        node = tree.nodes.new("CompositorNodeDenoise")
        node.name = node.label = DENOISE_NODE
        node.location = (rl.location.x + 250, rl.location.y)
        image = rl.outputs["Image"]
        targets = [link.to_socket for link in tree.links if link.from_socket == image]
        for link in [link for link in tree.links if link.from_socket == image]:
            tree.links.remove(link)
        tree.links.new(image, node.inputs["Image"])
        for sock in targets:
            tree.links.new(node.outputs["Image"], sock)
        hdr = node.inputs.get("HDR")
        if hdr is not None:
            hdr.default_value = True  # scene-linear radiance, not display values
    else:
        rl = _render_layers_node(tree)
    if rl is not None:
        # the passes appear on the Render Layers node once the engine has registered them
        _link_guides(tree, rl, node)
    node.mute = not on
    return node
