"""Image textures through the add-on: UV maps per corner, Image Texture nodes on Base Color,
Roughness and a Normal Map, sRGB decoding, missing images (listed, never a crash), renders."""
import numpy as np
import pytest

blender = pytest.mark.blender

ENCODED = [(0.9, 0.2, 0.2), (0.2, 0.8, 0.3)]  # sRGB-encoded texels of the 2×1 checker: left red, right green


def srgb_decode(v):
    v = np.asarray(v, float)
    return np.where(v <= 0.04045, v / 12.92, ((v + 0.055) / 1.055) ** 2.4)


def uv_plane(b, bpy, name, material):
    """The square [-1, 1]² at z = 0 with a UV map (x + 1, y + 1) / 2."""
    obj = b.plane(name, size=2.0, material=material)
    me = obj.data
    layer = me.uv_layers.new(name="UVMap")
    for loop in me.loops:
        co = me.vertices[loop.vertex_index].co
        layer.data[loop.index].uv = ((co.x + 1) / 2, (co.y + 1) / 2)
    return obj


def image(bpy, name, texels, non_color=False, pack=True):
    """A packed byte image of 1 row of (r, g, b) texels (as stored: sRGB-encoded unless non_color)."""
    img = bpy.data.images.new(name, len(texels), 1, is_data=non_color)
    img.pixels = [c for t in texels for c in (*t, 1.0)]
    if pack:
        img.pack()
    return img


def textured_material(bpy, name, base_img=None, rough_img=None, normal_img=None, shader="ShaderNodeBsdfPrincipled",
                      colour_input="Base Color"):
    mat = bpy.data.materials.new(name)
    tree = mat.node_tree
    tree.nodes.clear()
    out = tree.nodes.new("ShaderNodeOutputMaterial")
    bsdf = tree.nodes.new(shader)
    tree.links.new(bsdf.outputs[0], out.inputs["Surface"])
    if base_img is not None:
        tex = tree.nodes.new("ShaderNodeTexImage")
        tex.name = "Base Image"
        tex.image = base_img
        tex.interpolation = "Closest"
        tree.links.new(tex.outputs["Color"], bsdf.inputs[colour_input])
    if rough_img is not None:
        tex = tree.nodes.new("ShaderNodeTexImage")
        tex.name = "Rough Image"
        tex.image = rough_img
        tree.links.new(tex.outputs["Color"], bsdf.inputs["Roughness"])
    if normal_img is not None:
        tex = tree.nodes.new("ShaderNodeTexImage")
        tex.name = "Normal Image"
        tex.image = normal_img
        nmap = tree.nodes.new("ShaderNodeNormalMap")
        nmap.inputs["Strength"].default_value = 0.7
        tree.links.new(tex.outputs["Color"], nmap.inputs["Color"])
        tree.links.new(nmap.outputs["Normal"], bsdf.inputs["Normal"])
    return mat


def top_view(b, bpy, res=8):
    """An orthographic camera looking straight down at exactly the plane; a white uniform world."""
    cam = b.camera(location=(0, 0, 1), rotation=(0, 0, 0))
    cam.data.type = "ORTHO"
    cam.data.ortho_scale = 2.0
    b.resolution(res, res)
    b.scene.spectral_gi.pixel_filter, b.scene.spectral_gi.filter_width = "BOX", 1.0  # the texels stay apart
    world = bpy.data.worlds.new("W")
    bg = next(n for n in world.node_tree.nodes if n.type == "BACKGROUND")
    bg.inputs["Color"].default_value = (1, 1, 1, 1)
    bg.inputs["Strength"].default_value = 1.0
    b.scene.world = world


def leaves(scene, m):
    """The BSDF leaves under material ``m`` (following mixes)."""
    from spectral_gi.core import constants as C

    if m.model in (C.MAT_MIX, C.MAT_ADD):
        return leaves(scene, scene.materials[int(m.params[1])]) + leaves(scene, scene.materials[int(m.params[2])])
    return [m]


@blender
def test_principled_base_colour_texture_exports_and_renders(ext, bpy):
    b = ext.build
    img = image(bpy, "checker", ENCODED)
    uv_plane(b, bpy, "Plane", textured_material(bpy, "Tex", base_img=img))
    top_view(b, bpy)
    res = b.export(ext)
    s = res.scene
    assert len(s.textures) == 1
    tx = s.textures[0]
    assert tx.image.shape == (1, 2, 3) and tx.interpolation == "closest" and tx.colour
    stored = np.array(ENCODED).round(3)
    byte = np.floor(np.asarray(ENCODED, np.float32) * 255 + 0.5) / 255  # the packed byte image's values
    np.testing.assert_allclose(tx.image[0], srgb_decode(byte), atol=1e-5)
    assert not np.allclose(tx.image[0], stored, atol=0.01)  # decoded, not the encoded values
    mesh = s.meshes[0]
    assert mesh.corner_uvs is not None and mesh.corner_uvs.shape == (mesh.indices.shape[0] * 3, 2)
    # each corner's UV is its position mapped to [0, 1]²
    pos = mesh.positions[mesh.indices.reshape(-1)]
    np.testing.assert_allclose(mesh.corner_uvs, (pos[:, :2] + 1) / 2, atol=1e-6)
    root = s.materials[int(mesh.material[0])]
    assert any(m.base_colour_texture == 0 for m in leaves(s, root))
    s.settings.spp = 16
    s.settings.max_depth = 0
    film, _ = ext.core.render(s, threads=1)
    d = film.develop()
    # the albedo pass reproduces the decoded texel colours on the two halves
    np.testing.assert_allclose(d.albedo[:, :4].reshape(-1, 3).mean(0), tx.image[0, 0], atol=0.02)
    np.testing.assert_allclose(d.albedo[:, 4:].reshape(-1, 3).mean(0), tx.image[0, 1], atol=0.02)
    left, right = d.rgb[:, :4].reshape(-1, 3).mean(0), d.rgb[:, 4:].reshape(-1, 3).mean(0)
    assert left[0] > 2 * left[1] and right[1] > 2 * right[0]


@blender
def test_diffuse_texture_renders_the_texel_times_the_sky(ext, bpy):
    """A Diffuse BSDF under a white sky of strength 1 (L = 1 per channel): L_o = ρ, per half."""
    b = ext.build
    img = image(bpy, "checker", ENCODED)
    uv_plane(b, bpy, "Plane", textured_material(bpy, "Tex", base_img=img, shader="ShaderNodeBsdfDiffuse",
                                                colour_input="Color"))
    top_view(b, bpy)
    s = b.export(ext).scene
    s.settings.spp = 32
    s.settings.max_depth = 0
    d = ext.core.render(s, threads=1)[0].develop()
    lin = s.textures[0].image[0]
    np.testing.assert_allclose(d.rgb[:, :4].reshape(-1, 3).mean(0), lin[0], rtol=0.05, atol=0.01)
    np.testing.assert_allclose(d.rgb[:, 4:].reshape(-1, 3).mean(0), lin[1], rtol=0.05, atol=0.01)


@blender
def test_roughness_and_normal_map_textures(ext, bpy):
    b = ext.build
    C = ext.core.constants
    rough = image(bpy, "rough", [(0.2, 0.2, 0.2), (0.9, 0.9, 0.9)], non_color=True)
    normal = image(bpy, "normal", [(0.5, 0.5, 1.0), (0.7, 0.5, 0.9)], non_color=True)
    uv_plane(b, bpy, "Plane", textured_material(bpy, "Tex", rough_img=rough, normal_img=normal))
    top_view(b, bpy)
    res = b.export(ext)
    s = res.scene
    names = {t.name: t for t in s.textures}
    r = names["rough (roughness)"]
    n = names["normal (normal)"]
    assert r.image.shape == (1, 2, 1) and not r.colour
    np.testing.assert_allclose(r.image[0, :, 0], [0.2, 0.9], atol=2.5e-3)  # Non-Color: raw (byte) values
    assert n.image.shape == (1, 2, 3)
    root = s.materials[int(s.meshes[0].material[0])]
    plastic = [m for m in leaves(s, root) if m.model == C.MAT_PLASTIC]
    assert plastic and plastic[0].roughness_texture == next(i for i, t in enumerate(s.textures) if t is r)
    assert plastic[0].normal_texture == next(i for i, t in enumerate(s.textures) if t is n)
    assert plastic[0].normal_strength == pytest.approx(0.7)
    assert res.warning is None or "Normal" not in res.warning
    s.settings.spp = 2
    film, _ = ext.core.render(s, threads=1)
    assert np.all(np.isfinite(film.develop().rgb))


@blender
def test_missing_image_is_listed_and_the_render_still_happens(ext, bpy):
    b = ext.build
    img = bpy.data.images.new("lost", 4, 4)
    img.source = "FILE"
    img.filepath = "//no/such/texture.png"
    mat = textured_material(bpy, "Lost", base_img=img)
    next(n for n in mat.node_tree.nodes if n.type == "BSDF_PRINCIPLED").inputs["Base Color"].default_value = \
        (0.3, 0.4, 0.5, 1.0)
    uv_plane(b, bpy, "Plane", mat)
    top_view(b, bpy, res=4)
    res = b.export(ext)
    assert res.warning is not None
    assert "image textures that cannot be loaded" in res.warning and "Base Image" in res.warning
    assert "(0.3, 0.4, 0.5)" in res.warning  # the constant used instead
    assert res.scene.textures == []
    res.scene.settings.spp = 2
    film, _ = ext.core.render(res.scene, threads=1)
    assert np.all(np.isfinite(film.develop().rgb)) and film.develop().rgb.mean() > 0
