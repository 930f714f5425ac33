"""Denoise in Blender: the compositor's Denoise node on Combined, guided by Albedo and Normal; passes untouched."""
import importlib

import numpy as np
import pytest

pytestmark = pytest.mark.blender

MODULE = "bl_ext.user_default.spectral_gi"


def denoise_module():
    return importlib.import_module(MODULE + ".addon.denoise")


def links_between(tree, a, out_name, b, in_name):
    return [lk for lk in tree.links if lk.from_node == a and lk.from_socket.name == out_name and lk.to_node == b
            and lk.to_socket.name == in_name]


def test_denoise_sets_up_the_compositor(ext, bpy):
    dn = denoise_module()
    scene = bpy.context.scene
    scene.render.engine = "SPECTRAL_GI"
    assert scene.compositing_node_group is None
    scene.spectral_gi.use_denoise = True  # its update sets the compositor up
    tree = scene.compositing_node_group
    assert tree is not None
    node = tree.nodes[dn.DENOISE_NODE]
    rl = next(n for n in tree.nodes if n.bl_idname == "CompositorNodeRLayers")
    out = next(n for n in tree.nodes if n.bl_idname == "NodeGroupOutput")
    assert links_between(tree, rl, "Image", node, "Image")
    assert [lk.to_node for lk in tree.links if lk.from_node == node] == [out]
    assert not any(lk.from_node == rl and lk.to_node == out for lk in tree.links)
    vl = bpy.context.view_layer.spectral_gi
    assert vl.use_pass_albedo and vl.use_pass_normal  # the guides
    assert node.inputs["HDR"].default_value and not node.mute
    scene.spectral_gi.use_denoise = False
    assert node.mute  # passes the image through
    scene.spectral_gi.use_denoise = True
    assert not node.mute
    assert sum(n.bl_idname == "CompositorNodeDenoise" for n in tree.nodes) == 1


def test_denoise_goes_into_the_users_own_compositor(ext, bpy):
    dn = denoise_module()
    scene = bpy.context.scene
    tree = bpy.data.node_groups.new("Mine", "CompositorNodeTree")
    tree.interface.new_socket("Image", in_out="OUTPUT", socket_type="NodeSocketColor")
    rl = tree.nodes.new("CompositorNodeRLayers")
    grade = tree.nodes.new("CompositorNodeExposure")
    out = tree.nodes.new("NodeGroupOutput")
    tree.links.new(rl.outputs["Image"], grade.inputs["Image"])
    tree.links.new(grade.outputs["Image"], out.inputs[0])
    scene.compositing_node_group = tree
    node = dn.sync_compositor(scene)
    assert node is None  # off: nothing added
    scene.spectral_gi.use_denoise = True
    node = tree.nodes[dn.DENOISE_NODE]
    assert links_between(tree, rl, "Image", node, "Image") and links_between(tree, node, "Image", grade, "Image")
    assert not links_between(tree, rl, "Image", grade, "Image")
    assert links_between(tree, grade, "Image", out, "Image")  # the user's node stays in place


def read_multilayer(path):
    import OpenEXR

    out = {}
    with OpenEXR.File(str(path), separate_channels=True) as f:
        for part in f.parts:
            for name, ch in part.channels.items():
                out[name] = np.array(ch.pixels, np.float64)
    return out


def rgb_of(ch, prefix):
    return np.dstack([ch[prefix + c] for c in "RGB"])


@pytest.mark.slow
def test_f12_denoise_brings_combined_closer_to_converged_and_keeps_luminance(ext, bpy, tmp_path):
    scene = bpy.context.scene
    assert bpy.ops.spectral_gi.add_cornell_box() == {"FINISHED"}
    scene.render.engine = "SPECTRAL_GI"
    scene.render.resolution_x = scene.render.resolution_y = 64
    scene.render.resolution_percentage = 100
    s = scene.spectral_gi
    s.max_bounces, s.seed = 8, 1
    scene.render.image_settings.media_type = "MULTI_LAYER_IMAGE"
    scene.render.image_settings.color_depth = "32"
    bpy.context.view_layer.spectral_gi.use_pass_luminance = True

    def f12(name, spp, denoise):
        s.samples, s.use_denoise = spp, denoise
        scene.render.filepath = str(tmp_path / name)
        assert bpy.ops.render.render(write_still=True) == {"FINISHED"}
        return read_multilayer(tmp_path / (name + ".exr"))

    noisy = f12("noisy", 16, False)
    den = f12("denoised", 16, True)
    s.seed = 7
    ref = f12("ref", 1024, False)
    # the compositor's output (without a node group, before Denoise was first turned on, the
    # file holds the render's own Combined only)
    composite = "Composite.Combined."
    assert composite + "R" in den, sorted(den)
    shown = lambda ch: rgb_of(ch, composite if composite + "R" in ch else "ViewLayer.Combined.")  # noqa: E731
    lit = rgb_of(ref, "ViewLayer.Combined.").max(axis=2) < 1.0
    noisy_rgb, den_rgb, ref_rgb = shown(noisy), shown(den), shown(ref)
    rmse = lambda a: float(np.sqrt(np.mean((a[lit] - ref_rgb[lit]) ** 2)))  # noqa: E731
    print(f"\nF12 Cornell box 64x64, 16 spp: RMSE to 1024 spp noisy {rmse(noisy_rgb):.4g}, "
          f"denoised {rmse(den_rgb):.4g}")
    assert rmse(den_rgb) < 0.7 * rmse(noisy_rgb)
    # the render's own passes are never denoised
    np.testing.assert_array_equal(den["ViewLayer.Luminance.Y"], noisy["ViewLayer.Luminance.Y"])
    np.testing.assert_array_equal(rgb_of(den, "ViewLayer.Combined."), rgb_of(noisy, "ViewLayer.Combined."))
