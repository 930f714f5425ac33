"""Shader node graphs against Cycles: an emission-only plane whose colour one node (fed by the
plane's texture coordinates) drives, rendered by Cycles (bpy) and by this engine, filling a
48×48 orthographic frame: mean ΔE00 ≤ 1 and 99th percentile ≤ 3 (core.colour.compare, white
683 cd/m² = Blender's emission 1). The renders see the emission directly (no bounce), so
the difference measures the node's arithmetic and the per-evaluation emission uplift (and
what is left of the noise at 256 samples). Both engines use a Gaussian filter 0.02 px wide, so
every sample sees the pixel's centre (within 0.01 px): a pattern's hard edges (a checker, brick
mortar, white-noise cells) and its fine detail are compared value for value rather than through
each engine's sampling noise of a filter straddling an edge. Not a box filter: Cycles renders a
box filter 1 px wide whatever its width setting (the samples then cover the whole pixel).
"""
import importlib
import math

import numpy as np
import pytest

pytestmark = [pytest.mark.blender, pytest.mark.slow]

RES = 48
# enough samples that the spectral estimate's colour noise (four wavelengths a path) sits well
# below the tolerance: at 256 samples and pixel centres every node measured a mean ΔE00 of at most
# 0.3 and a 99th percentile of at most 0.5
SAMPLES = 256
FIGURES = {}


def _sep(nt, vec):
    s = nt.nodes.new("ShaderNodeSeparateXYZ")
    nt.links.new(vec, s.inputs[0])
    return s


def _node(nt, idname, **props):
    n = nt.nodes.new(idname)
    for k, v in props.items():
        setattr(n, k, v)
    return n


def case_generated(nt, tc):
    return tc.outputs["Generated"]


def case_uv(nt, tc):
    return tc.outputs["UV"]


def case_object_mapping(nt, tc):
    m = _node(nt, "ShaderNodeMapping", vector_type="POINT")
    m.inputs["Location"].default_value = (0.5, 0.5, 0.2)
    m.inputs["Rotation"].default_value = (0.0, 0.0, math.radians(30))
    m.inputs["Scale"].default_value = (0.4, 0.4, 1.0)
    nt.links.new(tc.outputs["Object"], m.inputs["Vector"])
    return m.outputs[0]


def case_math(nt, tc):
    s = _sep(nt, tc.outputs["Generated"])
    m1 = _node(nt, "ShaderNodeMath", operation="MULTIPLY")
    nt.links.new(s.outputs["X"], m1.inputs[0])
    m1.inputs[1].default_value = 9.0
    m2 = _node(nt, "ShaderNodeMath", operation="SINE")
    nt.links.new(m1.outputs[0], m2.inputs[0])
    m3 = _node(nt, "ShaderNodeMath", operation="MULTIPLY_ADD")
    nt.links.new(m2.outputs[0], m3.inputs[0])
    m3.inputs[1].default_value = 0.5
    m3.inputs[2].default_value = 0.5
    m4 = _node(nt, "ShaderNodeMath", operation="PINGPONG")
    nt.links.new(s.outputs["Y"], m4.inputs[0])
    m4.inputs[1].default_value = 0.3
    c = nt.nodes.new("ShaderNodeCombineColor")
    nt.links.new(m3.outputs[0], c.inputs[0])
    nt.links.new(m4.outputs[0], c.inputs[1])
    c.inputs[2].default_value = 0.2
    return c.outputs[0]


def case_vector_math(nt, tc):
    v = _node(nt, "ShaderNodeVectorMath", operation="CROSS_PRODUCT")
    nt.links.new(tc.outputs["Generated"], v.inputs[0])
    v.inputs[1].default_value = (0.3, 0.9, 0.4)
    w = _node(nt, "ShaderNodeVectorMath", operation="ABSOLUTE")
    nt.links.new(v.outputs[0], w.inputs[0])
    return w.outputs[0]


def _mix(mode):
    def case(nt, tc):
        m = _node(nt, "ShaderNodeMix", data_type="RGBA", blend_type=mode)
        s = _sep(nt, tc.outputs["Generated"])
        nt.links.new(s.outputs["X"], m.inputs["Factor"])
        nt.links.new(tc.outputs["Generated"], m.inputs[6])
        m.inputs[7].default_value = (0.9, 0.35, 0.1, 1.0)
        return m.outputs[2]
    return case


def _ramp(ipo):
    def case(nt, tc):
        r = nt.nodes.new("ShaderNodeValToRGB")
        ramp = r.color_ramp
        ramp.interpolation = ipo
        ramp.elements[0].position, ramp.elements[0].color = 0.1, (0.9, 0.1, 0.05, 1)
        ramp.elements[1].position, ramp.elements[1].color = 0.85, (0.05, 0.2, 0.9, 1)
        e = ramp.elements.new(0.45)
        e.color = (0.2, 0.8, 0.3, 1)
        s = _sep(nt, tc.outputs["Generated"])
        nt.links.new(s.outputs["X"], r.inputs[0])
        return r.outputs[0]
    return case


def case_map_range(nt, tc):
    m = _node(nt, "ShaderNodeMapRange", interpolation_type="SMOOTHERSTEP")
    s = _sep(nt, tc.outputs["Generated"])
    nt.links.new(s.outputs["Y"], m.inputs["Value"])
    m.inputs["From Min"].default_value = 0.2
    m.inputs["From Max"].default_value = 0.8
    c = nt.nodes.new("ShaderNodeCombineColor")
    c.mode = "HSV"
    nt.links.new(m.outputs[0], c.inputs[0])
    c.inputs[1].default_value = 0.7
    c.inputs[2].default_value = 0.8
    return c.outputs[0]


def case_hsv(nt, tc):
    h = nt.nodes.new("ShaderNodeHueSaturation")
    h.inputs["Hue"].default_value = 0.3
    h.inputs["Saturation"].default_value = 1.4
    h.inputs["Value"].default_value = 0.9
    nt.links.new(tc.outputs["Generated"], h.inputs["Color"])
    return h.outputs[0]


def case_invert_gamma_bright(nt, tc):
    i = nt.nodes.new("ShaderNodeInvert")
    nt.links.new(tc.outputs["Generated"], i.inputs["Color"])
    g = nt.nodes.new("ShaderNodeGamma")
    g.inputs["Gamma"].default_value = 1.8
    nt.links.new(i.outputs[0], g.inputs["Color"])
    b = nt.nodes.new("ShaderNodeBrightContrast")
    b.inputs["Bright"].default_value = 0.05
    b.inputs["Contrast"].default_value = 0.3
    nt.links.new(g.outputs[0], b.inputs["Color"])
    return b.outputs[0]


def case_separate_hsl(nt, tc):
    s = nt.nodes.new("ShaderNodeSeparateColor")
    s.mode = "HSL"
    nt.links.new(tc.outputs["Generated"], s.inputs[0])
    c = nt.nodes.new("ShaderNodeCombineColor")
    c.mode = "HSV"
    nt.links.new(s.outputs[0], c.inputs[0])
    nt.links.new(s.outputs[1], c.inputs[1])
    nt.links.new(s.outputs[2], c.inputs[2])
    return c.outputs[0]


def case_rgb_curves(nt, tc):
    c = nt.nodes.new("ShaderNodeRGBCurve")
    c.mapping.curves[0].points.new(0.5, 0.8)
    c.mapping.curves[3].points.new(0.3, 0.5)
    c.mapping.update()
    nt.links.new(tc.outputs["Generated"], c.inputs["Color"])
    return c.outputs[0]


def case_float_curve(nt, tc):
    c = nt.nodes.new("ShaderNodeFloatCurve")
    c.mapping.curves[0].points.new(0.4, 0.9)
    c.mapping.update()
    s = _sep(nt, tc.outputs["Generated"])
    nt.links.new(s.outputs["X"], c.inputs["Value"])
    k = nt.nodes.new("ShaderNodeCombineXYZ")
    nt.links.new(c.outputs[0], k.inputs[0])
    nt.links.new(s.outputs["Y"], k.inputs[1])
    return k.outputs[0]


def case_blackbody(nt, tc):
    m = _node(nt, "ShaderNodeMapRange")
    s = _sep(nt, tc.outputs["Generated"])
    nt.links.new(s.outputs["X"], m.inputs["Value"])
    m.inputs["To Min"].default_value = 1500.0
    m.inputs["To Max"].default_value = 9000.0
    b = nt.nodes.new("ShaderNodeBlackbody")
    nt.links.new(m.outputs[0], b.inputs[0])
    g = nt.nodes.new("ShaderNodeMix")
    g.data_type, g.blend_type = "RGBA", "MULTIPLY"
    g.inputs["Factor"].default_value = 1.0
    nt.links.new(b.outputs[0], g.inputs[6])
    g.inputs[7].default_value = (0.5, 0.5, 0.5, 1.0)
    return g.outputs[2]


def case_wavelength(nt, tc):
    m = _node(nt, "ShaderNodeMapRange")
    s = _sep(nt, tc.outputs["Generated"])
    nt.links.new(s.outputs["X"], m.inputs["Value"])
    m.inputs["To Min"].default_value = 400.0
    m.inputs["To Max"].default_value = 700.0
    w = nt.nodes.new("ShaderNodeWavelength")
    nt.links.new(m.outputs[0], w.inputs[0])
    return w.outputs[0]


def case_clamp_value_rgb(nt, tc):
    s = _sep(nt, tc.outputs["Generated"])
    v = nt.nodes.new("ShaderNodeValue")
    v.outputs[0].default_value = 0.35
    c = _node(nt, "ShaderNodeClamp", clamp_type="RANGE")
    nt.links.new(s.outputs["X"], c.inputs["Value"])
    nt.links.new(v.outputs[0], c.inputs["Min"])
    c.inputs["Max"].default_value = 0.7
    rgb = nt.nodes.new("ShaderNodeRGB")
    rgb.outputs[0].default_value = (0.2, 0.5, 0.9, 1.0)
    m = _node(nt, "ShaderNodeMix", data_type="RGBA", blend_type="MULTIPLY")
    nt.links.new(c.outputs[0], m.inputs["Factor"])
    m.inputs[6].default_value = (1, 1, 1, 1)
    nt.links.new(rgb.outputs[0], m.inputs[7])
    return m.outputs[2]


def case_group_and_mute(nt, tc):
    bpy = importlib.import_module("bpy")
    grp = bpy.data.node_groups.new("Swap", "ShaderNodeTree")
    grp.interface.new_socket("In", in_out="INPUT", socket_type="NodeSocketColor")
    grp.interface.new_socket("Out", in_out="OUTPUT", socket_type="NodeSocketColor")
    gi = grp.nodes.new("NodeGroupInput")
    go = grp.nodes.new("NodeGroupOutput")
    inv = grp.nodes.new("ShaderNodeInvert")
    grp.links.new(gi.outputs[0], inv.inputs["Color"])
    muted = grp.nodes.new("ShaderNodeGamma")
    muted.inputs["Gamma"].default_value = 3.0
    muted.mute = True
    grp.links.new(inv.outputs[0], muted.inputs["Color"])
    grp.links.new(muted.outputs[0], go.inputs[0])
    g = nt.nodes.new("ShaderNodeGroup")
    g.node_tree = grp
    rr = nt.nodes.new("NodeReroute")
    nt.links.new(tc.outputs["Generated"], rr.inputs[0])
    nt.links.new(rr.outputs[0], g.inputs[0])
    return g.outputs[0]


def case_vertex_colour(nt, tc):
    a = nt.nodes.new("ShaderNodeVertexColor")
    a.layer_name = "Col"
    return a.outputs["Color"]


def case_attribute(nt, tc):
    a = nt.nodes.new("ShaderNodeAttribute")
    a.attribute_name = "Col"
    h = nt.nodes.new("ShaderNodeHueSaturation")
    h.inputs["Hue"].default_value = 0.7
    nt.links.new(a.outputs["Color"], h.inputs["Color"])
    return h.outputs[0]


def _tex(idname, out="Color", **props):
    def case(nt, tc):
        n = _node(nt, idname, **props)
        if "Scale" in n.inputs:
            n.inputs["Scale"].default_value = 3.0
        nt.links.new(tc.outputs["Object"], n.inputs["Vector"])
        return n.outputs[out]
    return case


def case_window(nt, tc):
    return tc.outputs["Window"]


def case_camera(nt, tc):
    v = _node(nt, "ShaderNodeVectorMath", operation="MULTIPLY_ADD")
    nt.links.new(tc.outputs["Camera"], v.inputs[0])
    v.inputs[1].default_value = (0.4, 0.4, 0.1)  # Cycles camera space: z is the distance in front
    v.inputs[2].default_value = (0.5, 0.5, 0.0)
    return v.outputs[0]


def _facing(nt, normal):
    lw = nt.nodes.new("ShaderNodeLayerWeight")
    lw.inputs["Blend"].default_value = 0.5
    nt.links.new(normal, lw.inputs["Normal"])
    c = nt.nodes.new("ShaderNodeCombineColor")
    nt.links.new(lw.outputs["Facing"], c.inputs[0])
    nt.links.new(lw.outputs["Fresnel"], c.inputs[1])
    c.inputs[2].default_value = 0.3
    return c.outputs[0]


def case_bump(nt, tc):
    s = _sep(nt, tc.outputs["Object"])
    m = _node(nt, "ShaderNodeMath", operation="SINE")
    k = _node(nt, "ShaderNodeMath", operation="MULTIPLY")
    nt.links.new(s.outputs["X"], k.inputs[0])
    k.inputs[1].default_value = 3.0
    nt.links.new(k.outputs[0], m.inputs[0])
    b = nt.nodes.new("ShaderNodeBump")
    b.inputs["Distance"].default_value = 0.3
    nt.links.new(m.outputs[0], b.inputs["Height"])
    return _facing(nt, b.outputs[0])


def case_normal_map_tangent(nt, tc):
    # a tilt along the tangent (+x on the "Flat" UV map) growing with x, then Layer Weight
    s = _sep(nt, tc.outputs["Generated"])
    k = _node(nt, "ShaderNodeMath", operation="MULTIPLY_ADD")
    nt.links.new(s.outputs["X"], k.inputs[0])
    k.inputs[1].default_value = 0.5
    k.inputs[2].default_value = 0.25
    c = nt.nodes.new("ShaderNodeCombineXYZ")
    nt.links.new(k.outputs[0], c.inputs[0])
    c.inputs[1].default_value = 0.5
    c.inputs[2].default_value = 0.9
    n = nt.nodes.new("ShaderNodeNormalMap")
    n.uv_map = "Flat"
    nt.links.new(c.outputs[0], n.inputs["Color"])
    n.inputs["Strength"].default_value = 0.7
    return _facing(nt, n.outputs[0])


def case_white_noise_cells(nt, tc):
    v = _node(nt, "ShaderNodeVectorMath", operation="SNAP")
    nt.links.new(tc.outputs["Generated"], v.inputs[0])
    # z: the plane's Generated z is 0.5, a multiple of 0.125, where Cycles' interpolated z (0.5 or
    # just below) snaps to 0.5 or 0.375 from sample to sample; an increment of 0.3 keeps it at 0.3
    v.inputs[1].default_value = (0.125, 0.125, 0.3)
    n = nt.nodes.new("ShaderNodeTexWhiteNoise")
    nt.links.new(v.outputs[0], n.inputs["Vector"])
    return n.outputs["Color"]


def case_layer_weight_fresnel(nt, tc):
    lw = nt.nodes.new("ShaderNodeLayerWeight")
    lw.inputs["Blend"].default_value = 0.3
    fr = nt.nodes.new("ShaderNodeFresnel")
    c = nt.nodes.new("ShaderNodeCombineColor")
    nt.links.new(lw.outputs["Fresnel"], c.inputs[0])
    nt.links.new(lw.outputs["Facing"], c.inputs[1])
    nt.links.new(fr.outputs[0], c.inputs[2])
    return c.outputs[0]


CASES = {
    "generated": case_generated, "uv": case_uv, "object_mapping": case_object_mapping, "math": case_math,
    "vector_math": case_vector_math, "mix_overlay": _mix("OVERLAY"), "mix_hue": _mix("HUE"),
    "mix_soft_light": _mix("SOFT_LIGHT"), "mix_dodge": _mix("DODGE"),
    "ramp_linear": _ramp("LINEAR"), "ramp_constant": _ramp("CONSTANT"), "ramp_ease": _ramp("EASE"),
    "ramp_cardinal": _ramp("CARDINAL"), "ramp_b_spline": _ramp("B_SPLINE"), "map_range": case_map_range,
    "hsv": case_hsv, "invert_gamma_bright": case_invert_gamma_bright, "separate_hsl": case_separate_hsl,
    "rgb_curves": case_rgb_curves, "float_curve": case_float_curve, "blackbody": case_blackbody,
    "wavelength": case_wavelength, "clamp_value_rgb": case_clamp_value_rgb, "group_and_mute": case_group_and_mute,
    "vertex_colour": case_vertex_colour, "attribute": case_attribute,
    "layer_weight_fresnel": case_layer_weight_fresnel,
    "noise_fbm": _tex("ShaderNodeTexNoise"), "noise_ridged": _tex("ShaderNodeTexNoise", "Fac",
                                                                  noise_type="RIDGED_MULTIFRACTAL"),
    "voronoi_f1": _tex("ShaderNodeTexVoronoi"), "voronoi_edge": _tex("ShaderNodeTexVoronoi", "Distance",
                                                                     feature="DISTANCE_TO_EDGE"),
    "wave_rings": _tex("ShaderNodeTexWave", wave_type="RINGS"), "magic": _tex("ShaderNodeTexMagic"),
    "checker": _tex("ShaderNodeTexChecker"), "brick": _tex("ShaderNodeTexBrick"),
    "gradient_radial": _tex("ShaderNodeTexGradient", gradient_type="RADIAL"),
    "white_noise_cells": case_white_noise_cells, "window": case_window, "camera": case_camera,
    "bump": case_bump, "normal_map_tangent": case_normal_map_tangent,
}


def emission_plane(b, bpy, case):
    mat = bpy.data.materials.new("Node")
    nt = mat.node_tree
    nt.nodes.clear()
    out = nt.nodes.new("ShaderNodeOutputMaterial")
    em = nt.nodes.new("ShaderNodeEmission")
    em.inputs["Strength"].default_value = 1.0
    nt.links.new(em.outputs[0], out.inputs["Surface"])
    tc = nt.nodes.new("ShaderNodeTexCoord")
    nt.links.new(case(nt, tc), em.inputs["Color"])
    obj = b.plane("Plane", size=2.0, material=mat)
    me = obj.data
    uv = me.uv_layers.new(name="UVMap")
    for i, (u, v) in enumerate([(0.1, 0.0), (0.9, 0.2), (1.0, 1.0), (0.0, 0.8)]):
        uv.data[i].uv = (u, v)
    flat = me.uv_layers.new(name="Flat")
    for i, (u, v) in enumerate([(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)]):
        flat.data[i].uv = (u, v)
    me.uv_layers.active = uv
    uv.active_render = True
    col = me.color_attributes.new("Col", "FLOAT_COLOR", "POINT")
    for i, c in enumerate([(0.9, 0.1, 0.1, 1), (0.1, 0.9, 0.1, 1), (0.1, 0.1, 0.9, 1), (0.9, 0.9, 0.2, 1)]):
        col.data[i].color = c
    cam = b.camera(location=(0.0, 0.0, 5.0), rotation=(0.0, 0.0, 0.0))
    cam.data.type = "ORTHO"
    cam.data.ortho_scale = 2.0
    b.resolution(RES, RES)
    s = b.scene.spectral_gi
    s.samples, s.max_bounces, s.seed = SAMPLES, 0, 1
    s.pixel_filter, s.filter_width = "GAUSSIAN", 0.02
    return mat


def beside_cycles(ext, compare, scene, core_scene, film):
    """(our image, Cycles' at the settings the comparison matches, mean ΔE00, p99 ΔE00)."""
    ours = film.develop().rgb
    m = compare.matched_settings(scene, core_scene.settings, film.spp)
    ref = compare.render_cycles_rgb(scene, m["samples"], m["max_bounces"], m["pixel_filter"], m["filter_width"],
                                    m["seed"])
    _report, de = ext.core.compare_images(ours, ref)
    return ours, ref, float(de.mean()), float(np.percentile(de, 99))


@pytest.mark.parametrize("name", sorted(CASES))
def test_node_emission_matches_cycles(ext, bpy, name):
    compare = importlib.import_module(ext.module.__name__ + ".addon.operators.compare")
    b = ext.build
    emission_plane(b, bpy, CASES[name])
    scene = b.scene
    depsgraph = bpy.context.evaluated_depsgraph_get()
    core_scene, film, _stats, warning = compare.render_ours(scene, depsgraph)
    assert len(core_scene.programs) == 1, warning
    assert not warning or "Node" not in warning, warning
    ours, ref, mean, p99 = beside_cycles(ext, compare, scene, core_scene, film)
    FIGURES[name] = (mean, p99)
    print(f"{name}: ΔE00 mean {mean:.3f}, p99 {p99:.3f}")
    assert mean <= 1.0 and p99 <= 3.0, (name, mean, p99)


@pytest.mark.parametrize("pixel_filter, width", [("BLACKMAN_HARRIS", 1.5), ("GAUSSIAN", 1.5), ("BLACKMAN_HARRIS", 3.0)])
def test_pixel_filter_width_reads_as_cycles(ext, bpy, pixel_filter, width):
    """The panel's Pixel Filter and Width blur a checker's hard edges as Cycles' do (Cycles spreads
    Blackman–Harris over twice the width and gives its Gaussian σ = width/4): read as the core's
    own support, the default filter's edges are twice as sharp: mean ΔE00 1.86, p99 10.1)."""
    compare = importlib.import_module(ext.module.__name__ + ".addon.operators.compare")
    b = ext.build
    emission_plane(b, bpy, _tex("ShaderNodeTexChecker"))
    s = b.scene.spectral_gi
    s.pixel_filter, s.filter_width = pixel_filter, width
    core_scene, film, _stats, _warning = compare.render_ours(b.scene, bpy.context.evaluated_depsgraph_get())
    _ours, _ref, mean, p99 = beside_cycles(ext, compare, b.scene, core_scene, film)
    print(f"{pixel_filter} {width}: ΔE00 mean {mean:.3f}, p99 {p99:.3f}")
    assert mean <= 1.0 and p99 <= 3.0, (mean, p99)


# ----------------------------------------------------------------------------- Mix Shader factors


def mix_fac_generated_x(nt, tc):
    return _sep(nt, tc.outputs["Generated"]).outputs["X"]


def mix_fac_layer_weight_facing(nt, tc):
    lw = nt.nodes.new("ShaderNodeLayerWeight")
    lw.inputs["Blend"].default_value = 0.6
    return lw.outputs["Facing"]


# (factor, the two shaders); the perspective cases put the camera close to the plane
MIX_CASES = {"generated_x": (mix_fac_generated_x, "ShaderNodeBsdfDiffuse"),
             "layer_weight_facing": (mix_fac_layer_weight_facing, "ShaderNodeBsdfDiffuse"),
             "emission_generated_x": (mix_fac_generated_x, "ShaderNodeEmission"),
             "emission_layer_weight_facing": (mix_fac_layer_weight_facing, "ShaderNodeEmission")}
MIX_COLOURS = ((0.8, 0.25, 0.1, 1.0), (0.1, 0.35, 0.8, 1.0))


def mixed_plane(b, bpy, factor, shader, perspective):
    """A plane of a Mix Shader of two Diffuse BSDFs (under a white world of strength 1: nothing
    but the world lights it, so each point's radiance is its mixed albedo times the world) or
    two Emission shaders (no world) whose Factor ``factor`` drives."""
    mat = bpy.data.materials.new("Mixed")
    nt = mat.node_tree
    nt.nodes.clear()
    out = nt.nodes.new("ShaderNodeOutputMaterial")
    mix = nt.nodes.new("ShaderNodeMixShader")
    for k, rgb in enumerate(MIX_COLOURS):
        d = nt.nodes.new(shader)
        d.inputs["Color"].default_value = rgb
        nt.links.new(d.outputs[0], mix.inputs[1 + k])
    tc = nt.nodes.new("ShaderNodeTexCoord")
    nt.links.new(factor(nt, tc), mix.inputs[0])
    nt.links.new(mix.outputs[0], out.inputs["Surface"])
    b.plane("Plane", size=2.0, material=mat)
    world = bpy.data.worlds.new("White")
    world.use_nodes = True
    lit = shader != "ShaderNodeEmission"
    world.node_tree.nodes["Background"].inputs["Color"].default_value = (1.0, 1.0, 1.0, 1.0)
    world.node_tree.nodes["Background"].inputs["Strength"].default_value = 1.0 if lit else 0.0
    b.scene.world = world
    if perspective:  # close and wide (90°), so that the view's incidence varies; the plane overfills the frame
        b.camera(location=(0.0, 0.0, 0.9), rotation=(0.0, 0.0, 0.0), lens=18.0)
    else:
        cam = b.camera(location=(0.0, 0.0, 5.0), rotation=(0.0, 0.0, 0.0))
        cam.data.type = "ORTHO"
        cam.data.ortho_scale = 2.0
    b.resolution(RES, RES)
    s = b.scene.spectral_gi
    s.samples, s.max_bounces, s.seed = 2 * SAMPLES if lit else SAMPLES, 1 if lit else 0, 1
    s.pixel_filter, s.filter_width = "GAUSSIAN", 0.02  # Cycles renders a box 1 px wide
    return mat


@pytest.mark.parametrize("name", sorted(MIX_CASES))
def test_mix_shader_factor_program_matches_cycles(ext, bpy, name):
    """The Mix Shader's Factor as a program per shading point (of two BSDFs: a mix program; of
    two emitters: one emission program): the image of the plane, and the halves' mean
    luminance (the left one mixing mostly the first shader, the right one the second)."""
    compare = importlib.import_module(ext.module.__name__ + ".addon.operators.compare")
    b = ext.build
    factor, shader = MIX_CASES[name]
    mixed_plane(b, bpy, factor, shader, perspective="layer_weight" in name)
    scene = b.scene
    depsgraph = bpy.context.evaluated_depsgraph_get()
    core_scene, film, _stats, warning = compare.render_ours(scene, depsgraph)
    mixes = [m for m in core_scene.materials if m.model == ext.core.constants.MAT_MIX]
    if shader == "ShaderNodeEmission":
        assert not mixes and any(m.emission_program >= 0 for m in core_scene.materials), warning
    else:
        assert len(mixes) == 1 and mixes[0].mix_program >= 0, warning
    assert not warning or "Mixed" not in warning, warning
    ours, ref, mean, p99 = beside_cycles(ext, compare, scene, core_scene, film)
    lum = np.array([0.2126, 0.7152, 0.0722])
    half = RES // 2
    ratios = [float((ours[:, sl] @ lum).mean() / (ref[:, sl] @ lum).mean())
              for sl in (slice(0, half), slice(half, RES))]
    FIGURES[f"mix {name}"] = (mean, p99)
    print(f"mix {name}: ΔE00 mean {mean:.3f}, p99 {p99:.3f}, luminance ratio (left, right) {ratios}")
    assert mean <= 1.0 and p99 <= 3.0, (name, mean, p99)
    assert all(abs(r - 1.0) <= 0.03 for r in ratios), ratios
