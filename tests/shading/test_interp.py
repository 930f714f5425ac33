"""The shader program compiler and interpreter: every op of the numba interpreter against the
slow oracle (tests/oracles/shading.py, written from Blender's formulas) and against closed
forms; the compiler's conversions, ramps, Map Range, Mapping, Blackbody against core's Planck."""
import colorsys
import math

import numpy as np
import pytest

from spectral_gi.core.shading import compiler as K, ops as O
from spectral_gi.core.shading.compiler import compile_output
from spectral_gi.core.shading.interp import run
from spectral_gi.core.shading.program import check
from oracles import shading as oracle

POINT = {"P": [0.3, -0.2, 0.5], "N": [0.0, 0.0, 1.0], "Ng": [0.0, 0.0, 1.0],
         "I": list(np.array([0.3, 0.1, 0.9]) / np.linalg.norm([0.3, 0.1, 0.9]))}
ATTRS = {"@generated": (0.25, 0.6, 0.1), "uv:": (0.7, 0.2, 0.0), "col:Col": (0.9, 0.3, 0.05),
         "@object": (1.5, -2.0, 0.25), "@normal": (0.0, 0.6, 0.8)}


def numba_eval(prog):
    """The interpreter's result for ``prog`` at POINT: one triangle whose three corners carry ATTRS."""
    names = prog.attributes
    tri = np.zeros((1, 9 * max(1, len(names))), np.float32)
    for j, name in enumerate(names):
        tri[0, 9 * j:9 * j + 9] = np.tile(ATTRS[name], 3)
    ctx = tuple(float(x) for k in ("P", "N", "Ng", "I") for x in POINT[k])
    regs = np.zeros(512, np.float32)
    consts = np.concatenate([prog.consts, np.zeros(1, np.float32)])
    return np.array(run(prog.ops, consts, np.zeros(1, np.float32), np.zeros((1, 6), np.int64), tri,
                        np.int64(0), np.int64(0), 0.2, 0.3, ctx, regs))


def both(prog):
    assert check(prog, 0) is None
    got = numba_eval(prog)
    want = np.array(oracle.evaluate(prog, dict(POINT, attrs=ATTRS)))
    # float32 registers: the oracle's float64 within float32 rounding
    np.testing.assert_allclose(got, want, rtol=2e-6, atol=2e-6)
    return got


def node(t, props=None, **inputs):
    return {"type": t, "props": props or {}, "inputs": inputs}


def graph(**nodes):
    return {"nodes": nodes}


def out(g, name, socket, kind="vector"):
    return both(compile_output(g, ("link", name, socket), kind))


MATH_ARGS = [(0.7, 2.5, 0.3), (-1.3, 0.4, 2.0), (2.0, -3.0, 0.1), (0.0, 0.0, 0.0), (5.5, 2.0, 1.0)]


@pytest.mark.parametrize("op", O.MATH_OPS)
def test_math_op_matches_the_oracle(op):
    for a, b, c in MATH_ARGS:
        g = graph(m=node("MATH", {"operation": op}, Value=a, Value_001=b, Value_002=c))
        out(g, "m", "Value", "value")


@pytest.mark.parametrize("op, args, want", [
    ("POWER", (2.0, 3.0, 0), 8.0), ("POWER", (-8.0, 1 / 3, 0), 0.0), ("LOGARITHM", (8.0, 2.0, 0), 3.0),
    ("DIVIDE", (1.0, 0.0, 0), 0.0), ("WRAP", (5.5, 2.0, 0.0), 1.5), ("PINGPONG", (3.5, 2.0, 0), 0.5),
    ("FLOORED_MODULO", (-1.0, 3.0, 0), 2.0), ("MODULO", (-1.0, 3.0, 0), -1.0), ("SNAP", (7.3, 2.0, 0), 6.0),
    ("SMOOTH_MIN", (1.0, 1.0, 1.0), 1.0 - 1.0 / 6.0), ("COMPARE", (1.0, 1.05, 0.1), 1.0),
    ("INVERSE_SQRT", (4.0, 0, 0), 0.5), ("ARCTAN2", (1.0, -1.0, 0), 3 * math.pi / 4)])
def test_math_closed_forms(op, args, want):
    g = graph(m=node("MATH", {"operation": op}, Value=args[0], Value_001=args[1], Value_002=args[2]))
    assert out(g, "m", "Value", "value")[0] == pytest.approx(want, abs=1e-6)


def test_math_clamp():
    g = graph(m=node("MATH", {"operation": "MULTIPLY", "use_clamp": True}, Value=3.0, Value_001=2.0))
    assert out(g, "m", "Value", "value")[0] == 1.0


VEC = [(0.3, -1.2, 2.0), (1.5, 0.5, -0.25), (0.2, 0.4, 0.9)]


@pytest.mark.parametrize("op", O.VMATH_OPS)
def test_vector_math_op_matches_the_oracle(op):
    a, b, c = VEC
    g = graph(m=node("VECT_MATH", {"operation": op}, Vector=a, Vector_001=b, Vector_002=c, Scale=0.8))
    socket = "Value" if op in O.VMATH_VALUE else "Vector"
    out(g, "m", socket, "value" if socket == "Value" else "vector")


def test_vector_math_closed_forms():
    g = graph(m=node("VECT_MATH", {"operation": "CROSS_PRODUCT"}, Vector=(1, 0, 0), Vector_001=(0, 1, 0)))
    np.testing.assert_allclose(out(g, "m", "Vector"), (0, 0, 1))
    g = graph(m=node("VECT_MATH", {"operation": "REFLECT"}, Vector=(1, -1, 0), Vector_001=(0, 2, 0)))
    np.testing.assert_allclose(out(g, "m", "Vector"), (1, 1, 0))
    g = graph(m=node("VECT_MATH", {"operation": "DISTANCE"}, Vector=(1, 2, 3), Vector_001=(4, 6, 3)))
    assert out(g, "m", "Value", "value")[0] == pytest.approx(5.0)


@pytest.mark.parametrize("mode", O.BLEND_MODES)
def test_mix_blend_mode_matches_the_oracle(mode):
    for fac, a, b in [(0.35, (0.8, 0.3, 0.1), (0.2, 0.6, 0.9)), (1.0, (0.4, 0.7, 0.05), (0.9, 0.1, 0.5)),
                      (0.6, (0.0, 0.5, 1.0), (1.0, 0.0, 0.25))]:
        g = graph(m=node("MIX", {"data_type": "RGBA", "blend_type": mode}, Factor_Float=fac, A_Color=a,
                         B_Color=b))
        out(g, "m", "Result_Color", "colour")


def test_mix_closed_forms():
    a, b = (0.8, 0.3, 0.1), (0.2, 0.6, 0.9)
    cases = {"MULTIPLY": [x * y for x, y in zip(a, b)], "SCREEN": [1 - (1 - x) * (1 - y) for x, y in zip(a, b)],
             "ADD": [x + y for x, y in zip(a, b)], "DIFFERENCE": [abs(x - y) for x, y in zip(a, b)],
             "DARKEN": [min(x, y) for x, y in zip(a, b)]}
    for mode, want in cases.items():
        g = graph(m=node("MIX", {"data_type": "RGBA", "blend_type": mode}, Factor_Float=1.0, A_Color=a, B_Color=b))
        np.testing.assert_allclose(out(g, "m", "Result_Color", "colour"), want, atol=1e-6)
    g = graph(m=node("MIX", {"data_type": "RGBA", "blend_type": "ADD", "clamp_result": True}, Factor_Float=1.0,
                     A_Color=a, B_Color=b))
    np.testing.assert_allclose(out(g, "m", "Result_Color", "colour"), [1.0, 0.9, 1.0], atol=1e-6)
    g = graph(m=node("MIX", {"data_type": "FLOAT", "clamp_factor": True}, Factor_Float=1.5, A_Float=1.0, B_Float=3.0))
    assert out(g, "m", "Result_Float", "value")[0] == pytest.approx(3.0)
    g = graph(m=node("MIX", {"data_type": "VECTOR", "factor_mode": "NON_UNIFORM"}, Factor_Vector=(0, 0.5, 1),
                     A_Vector=(1, 1, 1), B_Vector=(3, 3, 3)))
    np.testing.assert_allclose(out(g, "m", "Result_Vector"), (1, 2, 3), atol=1e-6)


@pytest.mark.parametrize("mode", O.MAPRANGE_TYPES)
@pytest.mark.parametrize("clamp", [False, True])
def test_map_range_matches_the_oracle_and_closed_forms(mode, clamp):
    for v in (-0.5, 0.3, 0.75, 1.3):  # away from the steps (float32 constants)
        g = graph(m=node("MAP_RANGE", {"interpolation_type": mode, "clamp": clamp}, **{
            "Value": v, "From Min": 0.0, "From Max": 1.0, "To Min": 2.0, "To Max": 4.0, "Steps": 4.0}))
        r = out(g, "m", "Result", "value")[0]
        t = min(max(v, 0.0), 1.0)
        want = {"LINEAR": 2 + 2 * v, "STEPPED": 2 + 2 * math.floor(v * 5) / 4,
                "SMOOTHSTEP": 2 + 2 * t * t * (3 - 2 * t),
                "SMOOTHERSTEP": 2 + 2 * t ** 3 * (t * (6 * t - 15) + 10)}[mode]
        if clamp and mode in ("LINEAR", "STEPPED"):
            want = min(max(want, 2.0), 4.0)
        assert r == pytest.approx(want, abs=1e-6)
    g = graph(m=node("MAP_RANGE", {"data_type": "FLOAT_VECTOR", "interpolation_type": mode, "clamp": clamp}, **{
        "Vector": (0.1, 0.5, 2.0), "From_Min_FLOAT3": (0, 0, 0), "From_Max_FLOAT3": (1, 2, 4),
        "To_Min_FLOAT3": (0, 1, 0), "To_Max_FLOAT3": (1, 3, -1), "Steps_FLOAT3": (4, 4, 4)}))
    out(g, "m", "Vector")


def test_hsv_matches_colorsys():
    rgb = (0.7, 0.2, 0.4)
    g = graph(m=node("HUE_SAT", {}, Hue=0.6, Saturation=0.5, Value=1.2, Fac=1.0, Color=rgb))
    h, s, v = colorsys.rgb_to_hsv(*rgb)
    want = colorsys.hsv_to_rgb((h + 0.1) % 1.0, s * 0.5, v * 1.2)
    np.testing.assert_allclose(out(g, "m", "Color", "colour"), want, atol=1e-6)
    for mode in ("HSV", "HSL"):
        g = graph(c=node("COMBINE_COLOR", {"mode": mode}, Red=0.3, Green=0.6, Blue=0.4),
                  s=node("SEPARATE_COLOR", {"mode": mode}, Color=("link", "c", "Color")),
                  x=node("COMBXYZ", {}, X=("link", "s", "Red"), Y=("link", "s", "Green"), Z=("link", "s", "Blue")))
        np.testing.assert_allclose(out(g, "x", "Vector"), (0.3, 0.6, 0.4), atol=1e-5)
    g = graph(c=node("COMBINE_COLOR", {"mode": "HSL"}, Red=0.3, Green=0.6, Blue=0.4))
    np.testing.assert_allclose(out(g, "c", "Color", "colour"), colorsys.hls_to_rgb(0.3, 0.4, 0.6), atol=1e-6)


def test_colour_adjustments_closed_forms():
    c = (0.5, 0.25, 0.8)
    g = graph(m=node("INVERT", {}, Fac=1.0, Color=c))
    np.testing.assert_allclose(out(g, "m", "Color", "colour"), [1 - x for x in c], atol=1e-6)
    g = graph(m=node("GAMMA", {}, Color=c, Gamma=2.2))
    np.testing.assert_allclose(out(g, "m", "Color", "colour"), [x ** 2.2 for x in c], atol=1e-6)
    g = graph(m=node("BRIGHTCONTRAST", {}, Color=c, Bright=0.1, Contrast=0.5))
    np.testing.assert_allclose(out(g, "m", "Color", "colour"), [max(1.5 * x + 0.1 - 0.25, 0) for x in c], atol=1e-6)
    g = graph(m=node("RGBTOBW", {}, Color=c), x=node("COMBXYZ", {}, X=("link", "m", "Val")))
    assert out(g, "x", "Vector")[0] == pytest.approx(np.dot(c, K.LUMA), abs=1e-6)
    g = graph(m=node("CLAMP", {"clamp_type": "RANGE"}, Value=5.0, Min=3.0, Max=1.0))
    assert out(g, "m", "Result", "value")[0] == pytest.approx(3.0)


def test_socket_conversions_are_cycles():
    # colour → float by luminance, vector → float by the mean, float → vector by (f, f, f)
    g = graph(m=node("MATH", {"operation": "ADD"}, Value=("link", "c", "Color"), Value_001=0.0),
              c=node("RGB", {"color": (1.0, 0.0, 0.0)}))
    assert out(g, "m", "Value", "value")[0] == pytest.approx(K.LUMA[0], abs=1e-6)
    g = graph(m=node("MATH", {"operation": "ADD"}, Value=("link", "v", "Vector"), Value_001=0.0),
              v=node("VECT_MATH", {"operation": "ADD"}, Vector=(1, 2, 6), Vector_001=(0, 0, 0)))
    assert out(g, "m", "Value", "value")[0] == pytest.approx(3.0)
    g = graph(m=node("MATH", {"operation": "ADD"}, Value=0.25, Value_001=0.5))
    np.testing.assert_allclose(out(g, "m", "Value", "colour"), (0.75, 0.75, 0.75))


@pytest.mark.parametrize("ipo", ["CONSTANT", "LINEAR", "EASE", "CARDINAL", "B_SPLINE"])
def test_color_ramp(ipo):
    stops = [(0.2, (1, 0, 0, 1)), (0.5, (0, 1, 0, 0.5)), (0.9, (0, 0, 1, 0))]
    for fac in (0.0, 0.3, 0.6, 0.95):
        g = graph(r=node("VALTORGB", {"stops": stops, "interpolation": ipo}, Fac=fac))
        got = out(g, "r", "Color", "colour")
        if ipo == "LINEAR" and fac == 0.3:
            # a third of the way from red to green (to the table's 1/255 resolution)
            np.testing.assert_allclose(got, (2 / 3, 1 / 3, 0), atol=4e-3)
        if ipo == "CONSTANT" and fac == 0.6:
            np.testing.assert_allclose(got, (0, 1, 0), atol=1e-6)
        if ipo == "EASE" and fac == 0.3:
            t = 1 / 3
            e = t * t * (3 - 2 * t)
            np.testing.assert_allclose(got, (1 - e, e, 0), atol=5e-3)
        if fac == 0.0 and ipo in ("CONSTANT", "LINEAR", "EASE"):
            np.testing.assert_allclose(got, (1, 0, 0), atol=1e-6)


def test_texture_coordinates_and_attributes():
    g = graph(t=node("TEX_COORD"))
    np.testing.assert_allclose(out(g, "t", "Generated"), ATTRS["@generated"], atol=1e-6)
    np.testing.assert_allclose(out(g, "t", "UV"), ATTRS["uv:"], atol=1e-6)
    np.testing.assert_allclose(out(g, "t", "Object"), ATTRS["@object"], atol=1e-6)
    np.testing.assert_allclose(out(g, "t", "Normal"), ATTRS["@normal"], atol=1e-6)
    i, n = np.array(POINT["I"]), np.array(POINT["N"])
    np.testing.assert_allclose(out(g, "t", "Reflection"), 2 * np.dot(n, i) * n - i, atol=1e-6)
    g = graph(a=node("ATTRIBUTE", {"attribute_name": "Col"}))
    np.testing.assert_allclose(out(g, "a", "Color", "colour"), ATTRS["col:Col"], atol=1e-6)
    g = graph(a=node("NEW_GEOMETRY"))
    np.testing.assert_allclose(out(g, "a", "Position"), POINT["P"], atol=1e-6)


@pytest.mark.parametrize("vt", ["POINT", "TEXTURE", "VECTOR", "NORMAL"])
def test_mapping(vt):
    loc, rot, scale = np.array([0.5, -1.0, 2.0]), np.array([0.3, -0.4, 1.1]), np.array([2.0, 0.5, 1.5])
    g = graph(m=node("MAPPING", {"vector_type": vt}, Vector=(0.2, 0.7, -0.3), Location=tuple(loc),
                     Rotation=tuple(rot), Scale=tuple(scale)))
    got = out(g, "m", "Vector")
    v = np.array([0.2, 0.7, -0.3])
    r = K.euler_xyz(rot)
    want = {"POINT": r @ (v * scale) + loc, "TEXTURE": (r.T @ (v - loc)) / scale, "VECTOR": r @ (v * scale),
            "NORMAL": r @ (v / scale)}[vt]
    if vt == "NORMAL":
        want = want / np.linalg.norm(want)
    np.testing.assert_allclose(got, want, atol=1e-5)
    # XYZ Euler: a quarter turn about z takes x to y
    np.testing.assert_allclose(K.euler_xyz(np.array([0, 0, math.pi / 2])) @ [1, 0, 0], [0, 1, 0], atol=1e-12)


def test_fresnel_and_layer_weight():
    cosi = POINT["I"][2]
    g = graph(f=node("FRESNEL", {}, IOR=1.5))
    got = out(g, "f", "Fac", "value")[0]
    # Schlick is within 1 % of the exact dielectric Fresnel at this angle
    assert got == pytest.approx(0.04 + 0.96 * (1 - cosi) ** 5, rel=0.05)
    g = graph(f=node("LAYER_WEIGHT", {}, Blend=0.5))
    assert out(g, "f", "Facing", "value")[0] == pytest.approx(1 - cosi, abs=1e-6)
    out(g, "f", "Fresnel", "value")


def test_blackbody_is_cores_planck_colour():
    from spectral_gi.core import emission_to_rgb, light_emission_coeffs

    for t in (1500.0, 3200.0, 6500.0):
        g = graph(b=node("BLACKBODY", {}, Temperature=t))
        got = out(g, "b", "Color", "colour")
        want = emission_to_rgb(light_emission_coeffs("blackbody", temperature=t), 0.0)[0]
        np.testing.assert_allclose(got, want, rtol=0.02, atol=0.01)


def test_wavelength_is_the_cie_colour():
    g = graph(w=node("WAVELENGTH", {}, Wavelength=610.0))
    r, gg, b = out(g, "w", "Color", "colour")
    assert r > 0.3 and gg < r * 0.5 and b == 0.0
    g = graph(w=node("WAVELENGTH", {}, Wavelength=900.0))
    np.testing.assert_allclose(out(g, "w", "Color", "colour"), 0.0)


def test_curves_tables():
    x = np.linspace(0, 1, 256)
    tab = np.stack([x ** 2, x, np.sqrt(x)], axis=1)
    g = graph(c=node("CURVE_RGB", {"table": tab, "lo": 0.0, "hi": 1.0}, Fac=1.0, Color=(0.5, 0.5, 0.5)))
    np.testing.assert_allclose(out(g, "c", "Color", "colour"), (0.25, 0.5, math.sqrt(0.5)), atol=2e-3)
    g = graph(c=node("CURVE_FLOAT", {"table": 2 * x, "lo": 0.0, "hi": 1.0, "extrapolate": True}, Factor=1.0,
                     Value=1.5))
    assert out(g, "c", "Value", "value")[0] == pytest.approx(3.0, abs=1e-4)


def test_unsupported_node_names_itself():
    g = graph(m=node("TEX_SKY"))
    with pytest.raises(K.Unsupported) as e:
        compile_output(g, ("link", "m", "Color"), "colour")
    assert e.value.node == "m"


def test_check_rejects_bad_programs():
    prog = compile_output(graph(m=node("MATH", {"operation": "ADD"}, Value=1.0, Value_001=2.0)),
                          ("link", "m", "Value"), "value")
    assert check(prog, 0) is None
    bad = prog.ops.copy()
    bad[0] = 99
    assert "unknown op" in check(type(prog)("x", bad, prog.consts, [], prog.n_registers), 0)
    assert "end" in check(type(prog)("x", prog.ops[:-6], prog.consts, [], prog.n_registers), 0)


def interp_only(prog):
    assert check(prog, 0) is None
    return numba_eval(prog)


@pytest.mark.parametrize("t, props, socket, call", [
    ("TEX_NOISE", {"noise_type": "FBM", "noise_dimensions": "3D"}, "Fac",
     lambda T, v: T.noise_texture(*v, 0.0, 3, 1, 5.0, 2.0, 0.5, 2.0, 0.0, 1.0, 0.0, 1, True)[0]),
    ("TEX_NOISE", {"noise_type": "RIDGED_MULTIFRACTAL", "noise_dimensions": "2D"}, "Color",
     lambda T, v: T.noise_texture(*v, 0.0, 2, 3, 5.0, 2.0, 0.5, 2.0, 0.0, 1.0, 0.0, 1, True)[1:]),
    ("TEX_VORONOI", {"feature": "F2", "distance": "MANHATTAN"}, "Distance",
     lambda T, v: T.voronoi_texture(*v, 0.0, 3, 1, 1, 5.0, 2.0, 0.5, 2.0, 1.0, 0.5, 1.0, 0)[0]),
    ("TEX_VORONOI", {}, "Position",
     lambda T, v: T.voronoi_texture(*v, 0.0, 3, 0, 0, 5.0, 2.0, 0.5, 2.0, 1.0, 0.5, 1.0, 0)[4:7]),
    ("TEX_WAVE", {"wave_type": "RINGS", "wave_profile": "TRI"}, "Fac",
     lambda T, v: T.wave_texture(*v, 1, 0, 0, 2, 5.0, 0.0, 2.0, 1.0, 0.5, 0.0)),
    ("TEX_MAGIC", {"turbulence_depth": 4}, "Color", lambda T, v: T.magic_texture(*v, 4, 5.0, 0.0)[:3]),
    ("TEX_CHECKER", {}, "Color",
     lambda T, v: T.checker_texture(*v, 5.0, 0.8, 0.8, 0.8, 0.2, 0.2, 0.2)[:3]),
    ("TEX_BRICK", {}, "Fac",
     lambda T, v: T.brick_texture(*v, 5.0, 0.02, 0.1, 0.0, 0.5, 0.25, 0.5, 2, 1.0, 2)[1]),
    ("TEX_GRADIENT", {"gradient_type": "RADIAL"}, "Fac", lambda T, v: T.gradient_texture(*v, 4)),
    ("TEX_WHITE_NOISE", {}, "Value", lambda T, v: T.white_noise_texture(*v, 0.0, 3)[0]),
])
def test_procedural_textures_are_wired_to_their_functions(t, props, socket, call):
    from spectral_gi.core.shading import procedural as T

    g = graph(n=node(t, props))  # Vector unlinked: generated coordinates
    kind = "value" if socket in ("Fac", "Distance", "Value") else "vector"
    prog = compile_output(g, ("link", "n", socket), kind)
    got = interp_only(prog)
    if t in ("TEX_NOISE", "TEX_VORONOI", "TEX_WAVE", "TEX_MAGIC"):
        attrs32 = {k: tuple(float(np.float32(x)) for x in a) for k, a in ATTRS.items()}
        np.testing.assert_allclose(got, oracle.evaluate(prog, dict(POINT, attrs=attrs32)), rtol=1e-5, atol=1e-6)
    v = tuple(float(np.float32(a)) for a in ATTRS["@generated"])  # the attribute table is float32
    want = np.atleast_1d(np.asarray(call(T, v), np.float64))
    np.testing.assert_allclose(got[:want.size] if want.size == 3 else got[0], want if want.size == 3 else want[0],
                               rtol=1e-5, atol=1e-6)


def eval_on_triangle(prog):
    """The interpreter's result at barycentrics (0.2, 0.3) of the triangle (0, 0, 0), (1, 0, 0),
    (0, 1, 0) (normal +z), whose UV map is its x, y."""
    corners = {"@world": [(0, 0, 0), (1, 0, 0), (0, 1, 0)], "uv:": [(0, 0, 0), (1, 0, 0), (0, 1, 0)]}
    tri = np.zeros((1, 9 * max(1, len(prog.attributes))), np.float32)
    for j, name in enumerate(prog.attributes):
        tri[0, 9 * j:9 * j + 9] = np.ravel(corners[name])
    ctx = (0.2, 0.3, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 1.0, 0.0, 0.0, 1.0)
    consts = np.concatenate([prog.consts, np.zeros(1, np.float32)])
    got = np.array(run(prog.ops, consts, np.zeros(1, np.float32), np.zeros((1, 6), np.int64), tri,
                       np.int64(0), np.int64(0), 0.2, 0.3, ctx, np.zeros(512, np.float32)))
    point = {"P": ctx[:3], "N": ctx[3:6], "Ng": ctx[6:9], "I": ctx[9:], "corners": corners, "bary": (0.2, 0.3)}
    np.testing.assert_allclose(got, oracle.evaluate(prog, point), rtol=1e-5, atol=1e-5)
    return got


@pytest.mark.parametrize("strength, distance", [(1.0, 1.0), (1.0, 0.5), (0.5, 1.0)])
def test_bump_of_a_linear_height_tilts_the_normal_by_its_gradient(strength, distance):
    g = graph(geo=node("NEW_GEOMETRY"), s=node("SEPXYZ", {}, Vector=("link", "geo", "Position")),
              hx=node("MATH", {"operation": "MULTIPLY"}, Value=("link", "s", "X"), Value_001=0.3),
              h=node("MATH", {"operation": "MULTIPLY_ADD"}, Value=("link", "s", "Y"), Value_001=0.1,
                     Value_002=("link", "hx", "Value")),
              b=node("BUMP", {}, Height=("link", "h", "Value"), Strength=strength, Distance=distance))
    got = eval_on_triangle(compile_output(g, ("link", "b", "Normal"), "vector"))
    n = np.array([-0.3 * distance, -0.1 * distance, 1.0])
    n /= np.linalg.norm(n)
    if strength != 1.0:
        n = strength * n + (1 - strength) * np.array([0, 0, 1.0])
        n /= np.linalg.norm(n)
    np.testing.assert_allclose(got, n, atol=2e-4)


@pytest.mark.parametrize("space, colour, want", [
    ("TANGENT", (1.0, 0.5, 0.5), (1, 0, 0)), ("TANGENT", (0.5, 1.0, 0.5), (0, 1, 0)),
    ("TANGENT", (0.5, 0.5, 1.0), (0, 0, 1)), ("WORLD", (0.5, 0.5, 0.0), (0, 0, -1)),
    ("BLENDER_WORLD", (0.5, 0.0, 0.5), (0, 1, 0))])
def test_normal_map_spaces(space, colour, want):
    g = graph(n=node("NORMAL_MAP", {"space": space}, Color=colour, Strength=1.0))
    np.testing.assert_allclose(eval_on_triangle(compile_output(g, ("link", "n", "Normal"), "vector")), want,
                               atol=1e-5)
