"""Op codes and sub-op tags of shader programs (the tags are stored in scene files: never reorder).

An instruction is ``op, n, out, p, q, a_0 .. a_{n-1}``: the op code, the number of operands,
the first output register, two integer parameters and n operands. An operand k ≥ 0 is
register k (a 3-vector: registers k, k+1, k+2); k < 0 is the constant consts[-1 - k] (a
3-vector: the three constants from there).
"""

HEADER = 5  # op, n, out, p, q

OP_END = 0  # a0: the result (3-vector)
OP_COORD = 1  # out vec3: p = COORD_*
OP_ATTR = 2  # out vec3: corner attribute q interpolated by the barycentrics; p bit 0 normalises, bits 1, 2
# offset the barycentrics (bu, bv) by BUMP_DELTA (the Bump node's neighbouring points)
OP_XFORM = 3  # out vec3 = M a0 (M: consts[q..q+12], 3×4 rows); p: XF_*
OP_MATH = 4  # out = MATH_p(a0, a1, a2), clamped to [0, 1] when q
OP_VMATH = 5  # out vec3 and out+3 value = VMATH_p(a0, a1, a2 vec3; a3 scale)
OP_MIXF = 6  # out = a1 + (a2 − a1) a0; q bit 0 clamps the factor
OP_MIXV = 7  # out vec3 = mix of a1, a2 by a0 (q bit 1: a0 a 3-vector factor; bit 0 clamps it)
OP_MIXC = 8  # out vec3 = blend mode p of a1 by a2 at a0; q bit 0 clamps the factor, bit 1 the result
OP_TABLE = 9  # out (scalar, or vec3 when p bit 0) = table lookup of a0 (table at consts[q..]), see _table
OP_CURVES = 10  # out vec3: RGB Curves: a0 factor, a1 colour, tables at consts[q..]
OP_HSV = 11  # out vec3: Hue/Saturation/Value: a0 hue, a1 saturation, a2 value, a3 factor, a4 colour
OP_INVERT = 12  # out vec3: a0 factor, a1 colour
OP_BRIGHT = 13  # out vec3: a0 colour, a1 brightness, a2 contrast
OP_GAMMA = 14  # out vec3: a0 colour, a1 gamma
OP_CONVERT = 15  # out vec3 = CONV_p(a0)
OP_COMBINE = 16  # out vec3 = (a0, a1, a2)
OP_MAPRANGE = 17  # out (vec3 when q bit 1) = map range mode p of a0 from [a1, a2] to [a3, a4], steps a5; q bit 0 clamps
OP_CLAMP = 18  # out = clamp of a0 to [a1, a2]; p 1: the bounds in either order
OP_FRESNEL = 19  # out = Fresnel of IOR a0 at normal a1 (vec3)
OP_LAYER = 20  # out, out+1 = Layer Weight (fresnel, facing) of blend a0 at normal a1 (vec3)
OP_IMAGE = 21  # out vec3 (+ alpha at out+3) = texture q at UV a0 (vec3)
OP_RAMP = 22  # out vec3 + alpha at out+3 = colour ramp table at consts[q..] at factor a0; p 1 interpolates
OP_BUMP = 23  # out vec3: Bump: a0..a2 heights (centre, +bu, +bv), a3 strength, a4 distance, a5..a7 the
# positions there, a8 the normal in; q 1 inverts
OP_PROC = 24  # out: colour (3) then the float outputs of procedural texture p; settings at consts[q..]
OP_NORMALMAP = 25  # out vec3: Normal Map of space p: a0 colour, a1 strength, a2..a4 positions and a5..a7 UVs
# (centre, +bu, +bv), a8 the normal

OP_NAMES = ("end", "coord", "attr", "xform", "math", "vmath", "mixf", "mixv", "mixc", "table", "curves", "hsv",
            "invert", "bright", "gamma", "convert", "combine", "maprange", "clamp", "fresnel", "layer", "image",
            "ramp", "bump", "proc", "normalmap")
OUT_WIDTH = {OP_END: 0, OP_COORD: 3, OP_ATTR: 3, OP_XFORM: 3, OP_MATH: 1, OP_VMATH: 4, OP_MIXF: 1, OP_MIXV: 3,
             OP_MIXC: 3, OP_TABLE: 3, OP_CURVES: 3, OP_HSV: 3, OP_INVERT: 3, OP_BRIGHT: 3, OP_GAMMA: 3,
             OP_CONVERT: 3, OP_COMBINE: 3, OP_MAPRANGE: 3, OP_CLAMP: 1, OP_FRESNEL: 1, OP_LAYER: 2, OP_IMAGE: 4,
             OP_RAMP: 4, OP_PROC: 9, OP_BUMP: 3, OP_NORMALMAP: 3}
BUMP_DELTA = 1e-3  # the barycentric offset of the Bump node's and tangent frame's neighbouring points
NORMALMAP_SPACES = {"TANGENT": 0, "WORLD": 1, "BLENDER_WORLD": 2}

# OP_COORD: what of the shading point
COORD_P = 0  # world position
COORD_N = 1  # shading normal (world)
COORD_NG = 2  # geometric normal (world)
COORD_I = 3  # towards the viewer: −(ray direction)

# OP_XFORM
XF_POINT = 0
XF_VECTOR = 1
XF_NORMAL = 2  # linear part, then normalised

# Math node (Blender's operation names, in this order)
MATH_OPS = ("ADD", "SUBTRACT", "MULTIPLY", "DIVIDE", "MULTIPLY_ADD", "POWER", "LOGARITHM", "SQRT", "INVERSE_SQRT",
            "ABSOLUTE", "EXPONENT", "MINIMUM", "MAXIMUM", "LESS_THAN", "GREATER_THAN", "SIGN", "COMPARE",
            "SMOOTH_MIN", "SMOOTH_MAX", "ROUND", "FLOOR", "CEIL", "TRUNC", "FRACT", "MODULO", "FLOORED_MODULO",
            "WRAP", "SNAP", "PINGPONG", "SINE", "COSINE", "TANGENT", "ARCSINE", "ARCCOSINE", "ARCTANGENT",
            "ARCTAN2", "SINH", "COSH", "TANH", "RADIANS", "DEGREES")
MATH = {name: i for i, name in enumerate(MATH_OPS)}

# Vector Math node
VMATH_OPS = ("ADD", "SUBTRACT", "MULTIPLY", "DIVIDE", "MULTIPLY_ADD", "CROSS_PRODUCT", "PROJECT", "REFLECT",
             "REFRACT", "FACEFORWARD", "DOT_PRODUCT", "DISTANCE", "LENGTH", "SCALE", "NORMALIZE", "SNAP", "FLOOR",
             "CEIL", "MODULO", "WRAP", "FRACTION", "ABSOLUTE", "POWER", "SIGN", "MINIMUM", "MAXIMUM", "SINE",
             "COSINE", "TANGENT")
VMATH = {name: i for i, name in enumerate(VMATH_OPS)}
VMATH_VALUE = ("DOT_PRODUCT", "DISTANCE", "LENGTH")  # the ops whose result is the Value output

# Mix node colour blend modes
BLEND_MODES = ("MIX", "DARKEN", "MULTIPLY", "BURN", "LIGHTEN", "SCREEN", "DODGE", "ADD", "OVERLAY", "SOFT_LIGHT",
               "LINEAR_LIGHT", "DIFFERENCE", "EXCLUSION", "SUBTRACT", "DIVIDE", "HUE", "SATURATION", "COLOR",
               "VALUE")
BLEND = {name: i for i, name in enumerate(BLEND_MODES)}

# OP_CONVERT
CONV_RGB_HSV = 0
CONV_HSV_RGB = 1
CONV_RGB_HSL = 2
CONV_HSL_RGB = 3

# OP_MAPRANGE
MAPRANGE_TYPES = ("LINEAR", "STEPPED", "SMOOTHSTEP", "SMOOTHERSTEP")
MAPRANGE = {name: i for i, name in enumerate(MAPRANGE_TYPES)}

# OP_PROC kinds, their node types and socket operands (after the Vector and W operands)
PROC_NOISE, PROC_VORONOI, PROC_WAVE, PROC_MAGIC, PROC_CHECKER, PROC_BRICK, PROC_GRADIENT, PROC_WHITE = range(8)
PROC_TYPES = {"TEX_NOISE": PROC_NOISE, "TEX_VORONOI": PROC_VORONOI, "TEX_WAVE": PROC_WAVE, "TEX_MAGIC": PROC_MAGIC,
              "TEX_CHECKER": PROC_CHECKER, "TEX_BRICK": PROC_BRICK, "TEX_GRADIENT": PROC_GRADIENT,
              "TEX_WHITE_NOISE": PROC_WHITE}
PROC_SOCKETS = {
    PROC_NOISE: ("Scale", "Detail", "Roughness", "Lacunarity", "Offset", "Gain", "Distortion"),
    PROC_VORONOI: ("Scale", "Detail", "Roughness", "Lacunarity", "Smoothness", "Exponent", "Randomness"),
    PROC_WAVE: ("Scale", "Distortion", "Detail", "Detail Scale", "Detail Roughness", "Phase Offset"),
    PROC_MAGIC: ("Scale", "Distortion"),
    PROC_CHECKER: ("Scale", "Color1", "Color2"),
    PROC_BRICK: ("Scale", "Mortar Size", "Mortar Smooth", "Bias", "Brick Width", "Row Height", "Color1", "Color2",
                 "Mortar"),
    PROC_GRADIENT: (),
    PROC_WHITE: (),
}
RAMP_TABLE_SIZE = 256  # entries of a baked colour ramp or curve, as Cycles
MAX_REGISTERS = 256  # float registers of a program (they live in the BVH stack's scratch while shading)
