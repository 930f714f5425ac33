"""Blender materials → core materials: a tree of the core's BSDF models plus one emission.

The surface shader tree is evaluated into a small tree of core materials: BSDF leaves
(Lambert, conductors, dielectrics, plastic, ...) joined by MAT_MIX (Mix Shader, and the
Principled BSDF's metallic / transmission / alpha weights) and MAT_ADD (Add Shader).
Every emitter in the tree, scaled by the weights above it, is summed into the root
material's emission. Components with weight exactly 0 or 1 make no mix.

Node → model (α = roughness², as Cycles):

* Principled BSDF → MIX(metallic: metal, MIX(transmission: glass, plastic)); metal is a
  GGX conductor (smooth CONDUCTOR when α ≈ 0) whose η, κ come from the base colour and
  specular tint (``conductor_from_colour``), glass a (GGX_)DIELECTRIC tinted by the base
  colour, plastic MAT_PLASTIC (diffuse base colour under a dielectric coat of the IOR).
  Coat (weight, roughness, IOR, tint) and sheen (weight, roughness, grey tint) are the
  plastic's outer layers (core/bsdfs/principled.py); on the metal and glass components
  they are listed in the warning, as are a coloured sheen tint (its luminance used), the
  Coat Normal, subsurface, thin film and diffuse roughness, each with the substitute used.
  Alpha < 1 mixes in a transparent surface.
* Diffuse → LAMBERT; Glossy → GGX conductor with the Fresnel of a perfect conductor
  (η = κ = 0: reflectance 1 at every angle) tinted by its colour, MIRROR at roughness 0;
  Metallic → GGX conductor (F82: η, κ fitted to base colour and edge tint; physical
  conductor: its RGB η, κ interpolated over wavelength); Glass → (GGX_)DIELECTRIC,
  colour tinting reflection and transmission; Refraction →
  the same without reflection (noted); Transparent → a dielectric of IOR 1;
  Emission → emission; Mix / Add Shader → MAT_MIX / MAT_ADD (a Mix Shader whose Factor a node
  graph drives: MAT_MIX with a mix program, and its constant emitters one emission program of
  the two, (1 − Factor)·first + Factor·second). A Blackbody node as an emitter's
  colour gives Planck's spectrum at its temperature (luminance from its colour, Y = 1 as in Cycles).

The Material Output's Volume socket becomes a homogeneous core Medium inside the mesh
(Material.interior; see "the Volume socket" below); a Volume without a Surface gives a
MAT_NULL surface that only bounds it.

Image textures (Image Texture nodes on the active render UV map) feeding the Principled BSDF's
Base Color and Roughness, the Diffuse BSDF's Color, and a tangent-space Normal Map node feeding
their Normal become core textures (core/textures.py): base colour on the plastic, diffuse and
glass leaves (a metal uses the image's mean colour, noted), roughness on the GGX leaves, normal
maps on every leaf. An image that cannot be loaded is listed in the warning with the constant
used instead.

``material.spectral_gi.model`` (the material panel) overrides the BSDF with one of the
core's models and its parameters; the emission of the node tree is kept.
"""
from .convert import (
    SMOOTH_ALPHA, combine_emission, glossy_alpha, is_smooth, mix_first_weight, principled_alpha, rgb_of,
    specular_level_ior)
from .nodes import (
    active_output, constant_input, ignored_links, image_node, image_pixels, input_value, normal_map_node,
    shader_inputs, surface_node)
from .shading import compile_input as _compile_input, compile_mixed_emission, needs_program

SUPPORTED_SURFACES = ("BSDF_PRINCIPLED", "BSDF_DIFFUSE", "BSDF_GLOSSY", "BSDF_METALLIC", "BSDF_GLASS",
                      "BSDF_REFRACTION", "BSDF_TRANSPARENT", "EMISSION", "MIX_SHADER", "ADD_SHADER",
                      "BSDF_HAIR_PRINCIPLED", "BSDF_HAIR")
COLOUR_INPUTS = ("Base Color", "Color")
WHITE = (1.0, 1.0, 1.0)
BLACK = (0.0, 0.0, 0.0)
PERFECT_CONDUCTOR = "perfect conductor η = 0"
# Principled inputs the core has no model for: (input, substitute shown in the warning)
PRINCIPLED_UNSUPPORTED = (("Subsurface Weight", "subsurface", "diffuse base colour"),
                          ("Thin Film Thickness", "thin film", "ignored"),
                          ("Diffuse Roughness", "diffuse roughness", "Lambert"))
IOR_RANGE = (1e-3, 100.0)  # core.validate's range for Material.ior
GGX_DISTRIBUTIONS = ("GGX", "MULTI_GGX")
REC709_Y = (0.2126, 0.7152, 0.0722)  # luminance of linear Rec.709 RGB (a grey sheen tint)
MIX_DEPTH = 8  # core.constants.MIX_DEPTH (the kernel follows at most this many nested mixes)


def material_key(mat):
    return ("material", mat.name_full) if mat is not None else None


def export_material(ctx, mat):
    """Index into ``ctx.materials`` of the core material for Blender material ``mat`` (None: default grey)."""
    if mat is None:
        return ctx.default_material()
    return ctx.material_index(material_key(mat), lambda: build_material(ctx, mat))


# ----------------------------------------------------------------------------- the BSDF tree
#
# A tree is None (black: no BSDF), ("leaf", Material), ("mix", w_first, a, b), ("add", a, b) or
# ("pmix", program, w_first, a, b): a mix whose weight of a is the program's value at each point.


def _mix(w_first, a, b):
    """The tree of MIX(w_first: a, else b), without needless mixes."""
    if w_first >= 1.0 or (a is None and b is None):
        return a
    if w_first <= 0.0:
        return b
    return ("mix", float(w_first), a, b)


def _add(a, b):
    if a is None:
        return b
    if b is None:
        return a
    return ("add", a, b)


def _depth(tree):
    if tree is None or tree[0] == "leaf":
        return 0
    return 1 + max(_depth(t) for t in tree[-2:])


def _emit_tree(ctx, name, tree):
    """Add the components of ``tree`` to ctx.materials and return its root Material (not added)."""
    from ...core import Material, constants, lambert_params

    if tree is None:
        return Material(name=name, model=constants.MAT_LAMBERT, params=lambert_params())  # black
    if tree[0] == "leaf":
        return tree[1]
    a, b = tree[-2], tree[-1]
    ia = ctx.add_material(_emit_tree(ctx, f"{name} mix.a", a))
    ib = ctx.add_material(_emit_tree(ctx, f"{name} mix.b", b))
    if tree[0] == "mix":
        return Material(name=name, model=constants.MAT_MIX, params=[tree[1], float(ia), float(ib)])
    if tree[0] == "pmix":
        return Material(name=name, model=constants.MAT_MIX, params=[tree[2], float(ia), float(ib)],
                        mix_program=tree[1])
    return Material(name=name, model=constants.MAT_ADD, params=[0.0, float(ia), float(ib)])


def _scaled(emissions, w):
    return [(rgb, s * w) for rgb, s in emissions]


# ----------------------------------------------------------------------------- spectra and IOR curves


def _refl(ctx, name, rgb):
    return ctx.reflectance(name, tuple(min(max(float(c), 0.0), 1.0) for c in rgb))


def _tint(ctx, name, rgb):
    """A tint spectrum (-1 = white, the kernels' default for ``specular``)."""
    rgb = rgb_of(rgb)
    if all(c >= 1.0 for c in rgb):
        return -1
    return _refl(ctx, name, rgb)


def _preset_reflectance(ctx, patch):
    from ...core import constants, reflectance_preset

    key = ("P", patch)
    index = ctx._spectrum_index
    if key not in index:
        index[key] = ctx.spectra.add(f"ColorChecker {patch}", reflectance_preset(patch, ctx.n_coeffs),
                                     constants.SPECTRUM_BOUNDED)
    return index[key]


def _perfect_conductor(ctx):
    from ...core import constants
    import numpy as np

    return ctx.ior_table(PERFECT_CONDUCTOR, np.zeros(constants.N_LAMBDA))


def _conductor_tables(ctx, rgb, edge_rgb):
    """(η table, κ table) of the conductor whose normal-incidence reflectance is the colour ``rgb``
    and edge tint ``edge_rgb`` (Gulbrandsen 2014, per wavelength of the uplifted spectra)."""
    import numpy as np

    from ...core import conductor_from_colour, reflectance_from_rgb, tabulate_reflectance

    rgb = tuple(min(max(float(c), 0.0), 1.0) for c in rgb_of(rgb))
    edge = tuple(min(max(float(c), 0.0), 1.0) for c in rgb_of(edge_rgb))
    key = f"conductor r={rgb!r} g={edge!r}"
    if key + " η" not in ctx._ior_index:
        r = np.clip(tabulate_reflectance(reflectance_from_rgb(rgb)), 0.0, 0.9999)
        g = np.clip(tabulate_reflectance(reflectance_from_rgb(edge)), 0.0, 1.0)
        eta, kappa = conductor_from_colour(r, g)
        ctx.ior_table(key + " η", np.asarray(eta, np.float64))
        ctx.ior_table(key + " κ", np.asarray(kappa, np.float64))
    return ctx.ior_table(key + " η", None), ctx.ior_table(key + " κ", None)


def _metal_tables(ctx, metal):
    from ...core import metal_preset

    key = f"metal {metal}"
    if key + " η" not in ctx._ior_index:
        eta, kappa = metal_preset(metal)
        ctx.ior_table(key + " η", eta)
        ctx.ior_table(key + " κ", kappa)
    return ctx.ior_table(key + " η", None), ctx.ior_table(key + " κ", None)


def _glass_table(ctx, glass):
    from ...core import glass_preset

    key = f"glass {glass} η"
    if key not in ctx._ior_index:
        ctx.ior_table(key, glass_preset(glass))
    return ctx.ior_table(key, None)


def _ior(ctx, owner, value):
    lo, hi = IOR_RANGE
    v = float(value)
    if not lo <= v <= hi:
        ctx.note(f"{owner}: IOR {v:g} clamped to [{lo:g}, {hi:g}]")
        v = min(max(v, lo), hi)
    return v


# ----------------------------------------------------------------------------- leaves


def _leaf(**fields):
    from ...core import Material

    return ("leaf", Material(**fields))


def conductor_leaf(ctx, name, ax, ay, eta_table, kappa_table=-1, reflectance=None, two_sided=True):
    """A GGX conductor, or a smooth CONDUCTOR when α ≈ 0; ``reflectance`` (a spectrum index) tints it."""
    from ...core import conductor_params, constants, ggx_conductor_params

    refl = _refl(ctx, "white", WHITE) if reflectance is None else reflectance
    if is_smooth(ax, ay):
        return _leaf(name=name, model=constants.MAT_CONDUCTOR, params=conductor_params(two_sided),
                     reflectance=refl, eta_table=eta_table, kappa_table=kappa_table)
    return _leaf(name=name, model=constants.MAT_GGX_CONDUCTOR, params=ggx_conductor_params(ax, ay, two_sided),
                 reflectance=refl, eta_table=eta_table, kappa_table=kappa_table)


def dielectric_leaf(ctx, name, ax, ay, ior=1.5, eta_table=-1, transmission=None, reflection=-1):
    """A GGX dielectric, or a smooth DIELECTRIC when α ≈ 0; spectra index the tints (None: white)."""
    from ...core import constants, dielectric_params, ggx_dielectric_params

    tra = _refl(ctx, "white", WHITE) if transmission is None else transmission
    if is_smooth(ax, ay):
        return _leaf(name=name, model=constants.MAT_DIELECTRIC, params=dielectric_params(), reflectance=tra,
                     specular=reflection, ior=ior, eta_table=eta_table)
    return _leaf(name=name, model=constants.MAT_GGX_DIELECTRIC, params=ggx_dielectric_params(ax, ay),
                 reflectance=tra, specular=reflection, ior=ior, eta_table=eta_table)


def _transparent(ctx, name, rgb=WHITE):
    from ...core import constants, dielectric_params

    return _leaf(name=name, model=constants.MAT_DIELECTRIC, params=dielectric_params(),
                 reflectance=_refl(ctx, name, rgb), specular=_refl(ctx, "black", BLACK), ior=1.0)


# ----------------------------------------------------------------------------- image textures
#
# An Image Texture node's pixels become a core Texture (linear, rows top-down): byte images
# in the sRGB colour space are decoded, Non-Color / linear ones kept, float images are
# linear already (as for the world's environment image). Roughness uses the image's Rec.709
# luminance (Blender's colour → value conversion), normal maps its rgb.

TEXTURE_INTERPOLATION = {"Closest": "closest", "Linear": "linear", "Cubic": "linear", "Smart": "linear"}
TEXTURE_EXTENSION = {"REPEAT": "repeat", "EXTEND": "extend", "CLIP": "clip", "MIRROR": "repeat"}
LUMA_709 = (0.2126, 0.7152, 0.0722)


def _image_linear_rgb(ctx, owner, img):
    """float32 (H, W, 3) linear values of bpy image ``img``, or None when it has no pixels."""
    import numpy as np

    from ...core import sRGB_decode
    from .world import LINEAR_SPACES, SRGB_SPACES

    rgba = image_pixels(img)
    if rgba is None:
        return None
    rgb = rgba[..., :3]
    space = img.colorspace_settings.name
    if not img.is_float and space in SRGB_SPACES:
        rgb = np.asarray(sRGB_decode(rgb), dtype=np.float32)
    elif space not in LINEAR_SPACES and space not in SRGB_SPACES:
        ctx.note(f"{owner}: image {img.name!r} in colour space {space!r} read as linear Rec.709")
    bad = ~np.isfinite(rgb)
    if bad.any():
        ctx.note(f"{owner}: {int(bad.sum())} non-finite texels of {img.name!r} set to 0")
        rgb = np.where(bad, np.float32(0.0), rgb)
    return np.ascontiguousarray(rgb, dtype=np.float32)


def image_texture(ctx, owner, tex_node, usage):
    """(index into ctx.textures, mean) of Image Texture node ``tex_node`` used as ``usage``
    ("colour", "roughness" or "normal"); mean is the image's mean rgb (a float for roughness).
    (-1, None) when the image cannot be read (the caller substitutes a constant and lists it)."""
    import numpy as np

    from ...core import Texture

    img = tex_node.image
    if img is None:
        return -1, None
    interp = TEXTURE_INTERPOLATION.get(getattr(tex_node, "interpolation", "Linear"), "linear")
    ext = TEXTURE_EXTENSION.get(getattr(tex_node, "extension", "REPEAT"), "repeat")
    key = (img.name_full, usage, interp, ext)
    if key not in ctx.texture_index:
        rgb = _image_linear_rgb(ctx, owner, img)
        if rgb is None:
            ctx.texture_index[key] = (-1, None)
        else:
            if usage == "roughness":
                data = np.ascontiguousarray((rgb @ np.asarray(LUMA_709, np.float32))[..., None], np.float32)
                mean = float(np.clip(data, 0.0, 1.0).mean())
            else:
                data = rgb
                mean = tuple(float(x) for x in np.clip(rgb, 0.0, 1.0).reshape(-1, 3).mean(0))
            ctx.textures.append(Texture(name=f"{img.name} ({usage})", image=data, interpolation=interp,
                                        extension=ext, colour=usage == "colour"))
            ctx.texture_index[key] = (len(ctx.textures) - 1, mean)
    index, mean = ctx.texture_index[key]
    if index >= 0:
        if getattr(tex_node, "interpolation", "Linear") in ("Cubic", "Smart"):
            ctx.note(f"{owner}: '{tex_node.name}' {tex_node.interpolation} interpolation rendered as linear")
        if getattr(tex_node, "extension", "REPEAT") == "MIRROR":
            ctx.note(f"{owner}: '{tex_node.name}' mirror extension rendered as repeat")
        if getattr(tex_node, "projection", "FLAT") != "FLAT":
            ctx.note(f"{owner}: '{tex_node.name}' {tex_node.projection} projection rendered as flat (UV)")
        vec = tex_node.inputs.get("Vector")
        if vec is not None and vec.is_linked:
            src = vec.links[0].from_node
            if not (src.type == "TEX_COORD" and vec.links[0].from_socket.name == "UV") and src.type != "UVMAP":
                ctx.note(f"{owner}: '{tex_node.name}' vector from {src.name!r} ignored (the active render "
                         f"UV map used)")
    return index, mean


def texture_input(ctx, owner, node, name, usage):
    """(texture index or -1, constant or None) for input ``name`` of ``node``.

    Fed by an Image Texture: its index and the image's mean (a constant for models without
    texture support); if the image cannot be loaded, -1 and the socket's own value, listed in
    the warning. Not fed by an image: (-1, None), the caller reads the input as usual."""
    tex_node = image_node(node, name)
    if tex_node is None:
        return -1, None
    index, mean = image_texture(ctx, owner, tex_node, usage)
    if index >= 0:
        return index, mean
    value = node.inputs[name].default_value
    value = float(value) if usage == "roughness" else rgb_of(value)
    shown = f"{value:g}" if usage == "roughness" else "(" + ", ".join(f"{c:.3g}" for c in value) + ")"
    what = tex_node.image.name if tex_node.image is not None else "no image"
    ctx.skip("image textures that cannot be loaded", f"{owner}/{tex_node.name} ({what}): used {name} {shown}")
    return -1, value


def normal_input(ctx, owner, node):
    """(texture index or -1, strength) of a tangent-space Normal Map node fed by an Image Texture
    on the Normal input of ``node``; anything else there is left to ``ignored_links``."""
    nmap = normal_map_node(node)
    if nmap is None:
        return -1, 1.0
    label = f"{owner}/{nmap.name}"
    if getattr(nmap, "space", "TANGENT") != "TANGENT":
        ctx.skip("normal maps other than tangent space", f"{label} ({nmap.space})")
        return -1, 1.0
    tex_node = image_node(nmap, "Color")
    if tex_node is None:
        return -1, 1.0
    if getattr(nmap, "uv_map", ""):
        ctx.note(f"{owner}: '{nmap.name}' UV map {nmap.uv_map!r}: the active render UV map used")
    index, _ = image_texture(ctx, owner, tex_node, "normal")
    if index < 0:
        what = tex_node.image.name if tex_node.image is not None else "no image"
        ctx.skip("image textures that cannot be loaded", f"{owner}/{tex_node.name} ({what}): no normal map")
        return -1, 1.0
    strength = constant_input(ctx, owner, nmap, "Strength", 1.0)
    return index, max(float(1.0 if strength is None else strength), 0.0)


def compile_input(ctx, owner, node, name, kind, **kw):
    """export/shading.py compile_input with this module's image textures."""
    return _compile_input(ctx, owner, node, name, kind, images=image_texture, **kw)


def program_input(ctx, owner, node, name, kind):
    """(index into ctx.programs or None, constant or None) for input ``name`` of ``node`` driven
    by a node graph: the program, and the socket's own value for the models that cannot take
    one. (None, None) when the input needs no program (the caller reads it as usual)."""
    sock = node.inputs.get(name)
    if not needs_program(sock, kind):
        return None, None
    prog = compile_input(ctx, owner, node, name, "value" if kind == "roughness" else "colour")
    value = float(sock.default_value) if kind == "roughness" else rgb_of(sock.default_value)
    return prog, value


class ProgramEmission(tuple):
    """An emitter term whose colour or strength a node graph drives: white, remembering the node
    and its colour and strength inputs (compiled with the weight of the mixes above it); or, with
    ``mixed`` = (rgb of the first shader, rgb of the second), the emission of a Mix Shader whose
    Factor a graph drives over constant emitters."""

    node = None
    names = ("Color", "Strength")
    mixed = None


def emission_term(ctx, owner, node, colour_name, strength_name):
    """The (rgb, strength) term of an emitter node: a ProgramEmission when a graph drives it
    (and its strength is not a constant 0)."""
    strength = node.inputs.get(strength_name)
    if strength is not None and not strength.is_linked and float(strength.default_value) == 0.0:
        return BLACK, 0.0
    if needs_program(node.inputs.get(colour_name), "emission") or needs_program(node.inputs.get(strength_name),
                                                                                 "value"):
        term = ProgramEmission((1.0, 1.0, 1.0))
        term.node = node
        term.names = (colour_name, strength_name)
        return term, 1.0
    return (input_value(ctx, owner, node, (colour_name,), "colour"),
            input_value(ctx, owner, node, (strength_name,), "value"))


def normal_slot(ctx, owner, node):
    """(normal texture or -1, strength, normal program or None) of the Normal input of ``node``:
    a tangent-space Normal Map of an image on the render UV map takes the texture path, any
    other node graph there (Bump, Normal Map of another UV map or space, ...) a program."""
    from .nodes import linked_node

    nmap = normal_map_node(node)
    if (nmap is not None and getattr(nmap, "space", "TANGENT") == "TANGENT" and not getattr(nmap, "uv_map", "")
            and image_node(nmap, "Color") is not None and not needs_program(nmap.inputs.get("Color"), "colour")
            and not (nmap.inputs["Strength"].is_linked and linked_node(nmap.inputs["Strength"]) is not None)):
        return (*normal_input(ctx, owner, node), None)
    sock = node.inputs.get("Normal")
    if sock is not None and sock.is_linked and linked_node(sock) is not None:
        prog = compile_input(ctx, owner, node, "Normal", "vector")
        if prog is not None:
            return -1, 1.0, prog
    return (*normal_input(ctx, owner, node), None)


def textured_leaf(leaf, base=-1, rough=-1, normal=-1, strength=1.0, base_prog=None, rough_prog=None,
                  normal_prog=None):
    """``leaf`` with the textures and programs its model supports (base colour on its ``ra``, GGX
    roughness, normal map)."""
    from ...core import constants as C

    if leaf is None or leaf[0] != "leaf":
        return leaf
    m = leaf[1]
    if base_prog is not None and m.model in (C.MAT_LAMBERT, C.MAT_PLASTIC, C.MAT_DIELECTRIC, C.MAT_GGX_DIELECTRIC):
        m.base_colour_program = base_prog
    if rough_prog is not None and m.model in (C.MAT_GGX_CONDUCTOR, C.MAT_GGX_DIELECTRIC, C.MAT_PLASTIC):
        m.roughness_program = rough_prog
    if normal_prog is not None and m.model not in (C.MAT_MIX, C.MAT_ADD, C.MAT_NULL):
        m.normal_program = normal_prog
    if base >= 0 and m.model in (C.MAT_LAMBERT, C.MAT_PLASTIC, C.MAT_DIELECTRIC, C.MAT_GGX_DIELECTRIC):
        m.base_colour_texture = base
    if rough >= 0 and m.model in (C.MAT_GGX_CONDUCTOR, C.MAT_GGX_DIELECTRIC, C.MAT_PLASTIC):
        m.roughness_texture = rough
    if normal >= 0 and m.model not in (C.MAT_MIX, C.MAT_ADD, C.MAT_NULL):
        m.normal_texture = normal
        m.normal_strength = float(strength)
    return leaf


# ----------------------------------------------------------------------------- shader nodes

def _principled(ctx, owner, node):
    from ...core import constants, lambert_params, plastic_params

    label = f"{owner}/{node.name}"

    def val(name, default=0.0):
        v = input_value(ctx, owner, node, (name,), "value")
        return default if v is None else v

    def col(name, default=WHITE):
        v = input_value(ctx, owner, node, (name,), "colour")
        return default if v is None else v

    base_tex, base = texture_input(ctx, owner, node, "Base Color", "colour")
    base_prog = None
    if base is None:
        base_prog, base = program_input(ctx, owner, node, "Base Color", "colour")
    if base is None:
        base = col("Base Color", (0.8, 0.8, 0.8))
    metallic = min(max(val("Metallic"), 0.0), 1.0)
    transmission = min(max(val("Transmission Weight"), 0.0), 1.0)
    alpha = min(max(val("Alpha", 1.0), 0.0), 1.0)
    rough_tex, roughness = texture_input(ctx, owner, node, "Roughness", "roughness")
    rough_prog = None
    if roughness is None:
        rough_prog, roughness = program_input(ctx, owner, node, "Roughness", "roughness")
    if roughness is None:
        roughness = val("Roughness", 0.5)
    ax, ay = principled_alpha(roughness, val("Anisotropic"))
    if rough_tex >= 0 or rough_prog is not None:
        if val("Anisotropic") > 0.0:
            ctx.note(f"{owner}: '{node.name}' roughness texture rendered isotropic (anisotropy ignored)")
        ax = ay = max(ax, ay, 2.0 * SMOOTH_ALPHA)  # a GGX model, whose α the texture sets per point
    normal_tex, normal_strength, normal_prog = normal_slot(ctx, owner, node)
    ior = _ior(ctx, owner, val("IOR", 1.5))
    spec_tint = col("Specular Tint")
    level = val("Specular IOR Level", 0.5)
    if val("Anisotropic") > 0.0 and val("Anisotropic Rotation") != 0.0:
        ctx.note(f"{owner}: anisotropic rotation ignored (the tangent frame is the renderer's own)")
    if getattr(node, "distribution", "GGX") not in GGX_DISTRIBUTIONS:
        ctx.note(f"{owner}: '{node.name}' distribution {node.distribution} rendered as GGX")
    ignored_links(ctx, owner, node, ("Tangent", "Coat Normal") if normal_tex >= 0 or normal_prog is not None
                  else ("Normal", "Tangent", "Coat Normal"))
    for inp, what, substitute in PRINCIPLED_UNSUPPORTED:
        v = val(inp)
        if v > 0.0:
            ctx.skip("Principled BSDF inputs", f"{label}: {what} {v:g} ({substitute})")

    layers = _outer_layers(ctx, owner, label, node, val, col, metallic, transmission)
    metal = glass = plastic = None
    if metallic > 0.0:
        eta, kappa = _conductor_tables(ctx, base, spec_tint)
        metal = conductor_leaf(ctx, f"{owner}: metal", ax, ay, eta, kappa)
    if metallic < 1.0 and transmission > 0.0:
        glass = dielectric_leaf(ctx, f"{owner}: glass", ax, ay, ior=ior,
                                transmission=_refl(ctx, owner, base), reflection=_tint(ctx, f"{owner} tint", spec_tint))
        if level != 0.5:
            ctx.note(f"{owner}: Specular IOR Level not applied to transmission")
    if metallic < 1.0 and transmission < 1.0:
        coat_ior = _ior(ctx, owner, specular_level_ior(ior, level))
        outer, tint_table = layers
        if abs(coat_ior - 1.0) < 1e-9 and not outer:  # no specular layer at all: plain Lambert
            plastic = _leaf(name=f"{owner}: diffuse", model=constants.MAT_LAMBERT, params=lambert_params(),
                            reflectance=_refl(ctx, owner, base))
        else:
            if ctx.physical_layering:
                layering = dict(layering="physical")
                if getattr(node, "distribution", "GGX") == "MULTI_GGX":
                    ctx.note(f"{owner}: physical layering: the specular layer has no multiple-scattering "
                             "compensation (single-scattering GGX)")
            else:  # Cycles' Principled layering (core/bsdfs/plastic.py)
                layering = dict(layering="cycles", multiscatter=getattr(node, "distribution", "GGX") == "MULTI_GGX")
            plastic = _leaf(name=f"{owner}: plastic", model=constants.MAT_PLASTIC,
                            params=plastic_params(ax, ay, **layering, **outer),
                            reflectance=_refl(ctx, owner, base), specular=_tint(ctx, f"{owner} tint", spec_tint),
                            ior=coat_ior, kappa_table=tint_table)
    if metal is not None and base_tex >= 0:
        ctx.note(f"{owner}: a metal's base colour texture is not supported, used the image's mean colour")
    if metal is not None and base_prog is not None:
        ctx.note(f"{owner}: a metal's base colour node graph is not supported, used the socket's own colour")
    textures = dict(rough=rough_tex, normal=normal_tex, strength=normal_strength, rough_prog=rough_prog,
                    normal_prog=normal_prog)
    metal = textured_leaf(metal, **textures)
    glass = textured_leaf(glass, base=base_tex, base_prog=base_prog, **textures)
    plastic = textured_leaf(plastic, base=base_tex, base_prog=base_prog, **textures)
    tree = _mix(metallic, metal, _mix(transmission, glass, plastic))
    if alpha < 1.0:
        ctx.note(f"{owner}: alpha {alpha:g} rendered as a stochastic mix with a transparent surface")
        tree = _mix(alpha, tree, _transparent(ctx, f"{owner}: transparent"))
    emission = [emission_term(ctx, owner, node, "Emission Color", "Emission Strength")]
    return tree, emission


def _outer_layers(ctx, owner, label, node, val, col, metallic, transmission):
    """(plastic_params keywords, coat tint table or -1) of the Principled coat and sheen
    (core/bsdfs/principled.py): empty keywords when both weights are 0. They layer the
    dielectric (plastic) component only; on the metal and glass components they are listed
    in the warning."""
    coat = min(max(val("Coat Weight"), 0.0), 1.0)
    sheen = max(val("Sheen Weight"), 0.0)
    others = metallic > 0.0 or transmission > 0.0
    for what, w in (("coat", coat), ("sheen", sheen)):
        if w > 0.0 and others:
            ctx.skip("Principled BSDF inputs", f"{label}: {what} {w:g} (on the metallic and transmission "
                                               "components ignored: layered on the dielectric base only)")
    if (coat > 0.0 or sheen > 0.0) and val("Emission Strength") > 0.0:
        ctx.note(f"{owner}: emission not dimmed by the coat and sheen above it (Cycles dims it towards the viewer)")
    if coat == 0.0 and sheen == 0.0 or metallic >= 1.0 or transmission >= 1.0:
        return {}, -1
    out = {}
    table = -1
    if coat > 0.0:
        rough = min(max(val("Coat Roughness", 0.03), 0.0), 1.0)
        tint = tuple(max(float(c), 0.0) for c in rgb_of(col("Coat Tint")))
        out.update(coat=coat, coat_alpha=rough * rough, coat_ior=min(max(val("Coat IOR", 1.5), 1.0), IOR_RANGE[1]))
        if any(abs(c - 1.0) > 1e-6 for c in tint):
            table = _coat_tint_table(ctx, tint)
            out["coat_tinted"] = True
    if sheen > 0.0:
        tint = tuple(max(float(c), 0.0) for c in rgb_of(col("Sheen Tint")))
        grey = sum(w * c for w, c in zip(REC709_Y, tint))
        if max(tint) - min(tint) > 1e-6:
            ctx.skip("Principled BSDF inputs", f"{label}: sheen tint {tuple(round(c, 3) for c in tint)} "
                                               f"(grey of its luminance {grey:.3g})")
        out.update(sheen=sheen * grey, sheen_roughness=min(max(val("Sheen Roughness", 0.5), 0.0), 1.0))
    return out, table


def _coat_tint_table(ctx, rgb):
    """Row of ``ior_tables`` holding the coat tint's spectrum (the plastic's κ slot, principled.py)."""
    import numpy as np

    from ...core import reflectance_from_rgb, tabulate_reflectance

    rgb = tuple(min(c, 1.0) for c in rgb)
    key = f"coat tint {rgb!r}"
    if key not in ctx._ior_index:
        ctx.ior_table(key, np.clip(tabulate_reflectance(reflectance_from_rgb(rgb)), 0.0, 1.0).astype(np.float64))
    return ctx.ior_table(key, None)


def _glossy(ctx, owner, node):
    from ...core import constants, mirror_params

    colour = input_value(ctx, owner, node, ("Color",), "colour")
    ax, ay = glossy_alpha(input_value(ctx, owner, node, ("Roughness",), "value"),
                          input_value(ctx, owner, node, ("Anisotropy",), "value") or 0.0)
    if not is_smooth(ax, ay) and getattr(node, "distribution", "GGX") not in GGX_DISTRIBUTIONS:
        ctx.note(f"{owner}: '{node.name}' distribution {node.distribution} rendered as GGX")
    ignored_links(ctx, owner, node, ("Normal", "Tangent"))
    name = f"{owner}: {node.name}"
    if is_smooth(ax, ay):
        return _leaf(name=name, model=constants.MAT_MIRROR, params=mirror_params(),
                     reflectance=_refl(ctx, owner, colour))
    return conductor_leaf(ctx, name, ax, ay, _perfect_conductor(ctx), -1, reflectance=_refl(ctx, owner, colour))


RGB_WAVELENGTHS_NM = (465.0, 532.0, 630.0)  # where a per-channel (B, G, R) index is placed on the spectrum


def _metallic(ctx, owner, node):
    """Metallic BSDF: F82 (base colour, edge tint) → fitted η, κ; physical conductor → its RGB η, κ
    interpolated over the spectrum (B at 465, G at 532, R at 630 nm, held beyond)."""
    import numpy as np

    from ...core import wavelength_grid

    ax, ay = glossy_alpha(input_value(ctx, owner, node, ("Roughness",), "value"),
                          input_value(ctx, owner, node, ("Anisotropy",), "value") or 0.0)
    ignored_links(ctx, owner, node, ("Normal", "Tangent"))
    if (input_value(ctx, owner, node, ("Thin Film Thickness",), "value") or 0.0) > 0.0:
        ctx.skip("shader inputs", f"{owner}/{node.name}: thin film (ignored)")
    name = f"{owner}: {node.name}"
    if getattr(node, "fresnel_type", "F82") == "PHYSICAL_CONDUCTOR":
        eta_rgb = [max(float(v), 0.0) for v in node.inputs["IOR"].default_value]
        kappa_rgb = [max(float(v), 0.0) for v in node.inputs["Extinction"].default_value]
        for sock in ("IOR", "Extinction"):
            if node.inputs[sock].is_linked:
                ctx.note(f"{owner}: '{node.name}' input '{sock}' is linked, used its unlinked value")
        key = f"RGB conductor η={tuple(eta_rgb)!r} κ={tuple(kappa_rgb)!r}"
        wl = wavelength_grid()
        eta = ctx.ior_table(key + " η", np.interp(wl, RGB_WAVELENGTHS_NM, eta_rgb[::-1]))
        kappa = ctx.ior_table(key + " κ", np.interp(wl, RGB_WAVELENGTHS_NM, kappa_rgb[::-1]))
        ctx.note(f"{owner}: '{node.name}' RGB η, κ interpolated over wavelength")
    else:
        eta, kappa = _conductor_tables(ctx, input_value(ctx, owner, node, ("Base Color",), "colour"),
                                       input_value(ctx, owner, node, ("Edge Tint",), "colour"))
    return conductor_leaf(ctx, name, ax, ay, eta, kappa)


def _glass(ctx, owner, node, reflect=True):
    colour = input_value(ctx, owner, node, ("Color",), "colour")
    r = input_value(ctx, owner, node, ("Roughness",), "value")
    a = min(max(r, 0.0), 1.0) ** 2
    ior = _ior(ctx, owner, input_value(ctx, owner, node, ("IOR",), "value"))
    if a > 0.0 and getattr(node, "distribution", "GGX") not in GGX_DISTRIBUTIONS:
        ctx.note(f"{owner}: '{node.name}' distribution {node.distribution} rendered as GGX")
    ignored_links(ctx, owner, node, ("Normal",))
    if (input_value(ctx, owner, node, ("Thin Film Thickness",), "value") or 0.0) > 0.0:
        ctx.skip("shader inputs", f"{owner}/{node.name}: thin film (ignored)")
    tint = _refl(ctx, owner, colour)
    if not reflect:
        ctx.note(f"{owner}: '{node.name}' (Refraction BSDF) rendered as a dielectric without its reflection")
    return dielectric_leaf(ctx, f"{owner}: {node.name}", a, a, ior=ior, transmission=tint,
                           reflection=tint if reflect else _refl(ctx, "black", BLACK))


def _shader(ctx, owner, node, depth=0):
    """(tree, emissions) of the shader produced by ``node`` (None: black, nothing emitted)."""
    from ...core import constants, lambert_params

    if node is None:
        return None, []
    kind = node.type
    if depth >= MIX_DEPTH - 2 and kind in ("MIX_SHADER", "ADD_SHADER"):
        ctx.skip("shader mixes nested too deeply", f"{owner}/{node.name}")
        return None, []
    if kind == "MIX_SHADER":
        programmed = _programmed_mix(ctx, owner, node, depth)
        if programmed is not None:
            return programmed
        fac = constant_input(ctx, owner, node, "Factor", 0.5)
        w = mix_first_weight(0.5 if fac is None else fac)
        a, b = shader_inputs(node)
        ta, ea = _shader(ctx, owner, a, depth + 1) if w > 0.0 else (None, [])
        tb, eb = _shader(ctx, owner, b, depth + 1) if w < 1.0 else (None, [])
        if ta is None and tb is not None and 0.0 < w < 1.0:
            ta = _emit_black_leaf(owner)
        elif tb is None and ta is not None and 0.0 < w < 1.0:
            tb = _emit_black_leaf(owner)
        return _mix(w, ta, tb), _scaled(ea, w) + _scaled(eb, 1.0 - w)
    if kind == "ADD_SHADER":
        a, b = shader_inputs(node)
        ta, ea = _shader(ctx, owner, a, depth + 1)
        tb, eb = _shader(ctx, owner, b, depth + 1)
        return _add(ta, tb), ea + eb
    if kind == "BSDF_PRINCIPLED":
        return _principled(ctx, owner, node)
    if kind == "BSDF_DIFFUSE":
        base_tex, colour = texture_input(ctx, owner, node, "Color", "colour")
        base_prog = None
        if colour is None:
            base_prog, colour = program_input(ctx, owner, node, "Color", "colour")
        if colour is None:
            colour = input_value(ctx, owner, node, ("Color",), "colour")
        if (input_value(ctx, owner, node, ("Roughness",), "value") or 0.0) > 0.0:
            ctx.note(f"{owner}: '{node.name}' roughness ignored (Lambert)")
        normal_tex, normal_strength, normal_prog = normal_slot(ctx, owner, node)
        if normal_tex < 0 and normal_prog is None:
            ignored_links(ctx, owner, node, ("Normal",))
        leaf = _leaf(name=f"{owner}: {node.name}", model=constants.MAT_LAMBERT, params=lambert_params(),
                     reflectance=_refl(ctx, owner, colour))
        return textured_leaf(leaf, base=base_tex, normal=normal_tex, strength=normal_strength, base_prog=base_prog,
                             normal_prog=normal_prog), []
    if kind == "BSDF_GLOSSY":
        return _glossy(ctx, owner, node), []
    if kind == "BSDF_METALLIC":
        return _metallic(ctx, owner, node), []
    if kind == "BSDF_GLASS":
        return _glass(ctx, owner, node), []
    if kind == "BSDF_REFRACTION":
        return _glass(ctx, owner, node, reflect=False), []
    if kind in ("BSDF_HAIR_PRINCIPLED", "BSDF_HAIR"):  # a substitute on the plastic / GGX models (hair.py)
        return _hair(ctx, owner, node), []
    if kind == "BSDF_TRANSPARENT":
        colour = input_value(ctx, owner, node, ("Color",), "colour")
        return _transparent(ctx, f"{owner}: {node.name}", colour), []
    if kind == "EMISSION":
        return None, [emission_term(ctx, owner, node, "Color", "Strength")]
    if kind == "HOLDOUT":  # only a whole surface can be a holdout; inside a mix or add it is black
        ctx.note(f"{owner}: '{node.name}' inside a shader mix is black (a partial holdout is not supported)")
        return None, []
    # Unsupported shader: listed in the warning; its colour (if any) stands in as a diffuse colour.
    ctx.skip("shader nodes (a diffuse surface of their colour instead)", f"{owner}/{node.name}")
    colour = node_colour(ctx, owner, node, fallback=None)
    if colour is None:
        from .context import DEFAULT_GREY
        colour = DEFAULT_GREY
    return _leaf(name=f"{owner}: {node.name}", model=constants.MAT_LAMBERT, params=lambert_params(),
                 reflectance=_refl(ctx, owner, colour)), []


def _programmed_mix(ctx, owner, node, depth):
    """(tree, emissions) of a Mix Shader whose Factor a node graph drives, or None when it is a
    constant (or its graph cannot be compiled: listed in the warning, 0.5 used). The tree is
    ("pmix", program, constant weight, first, second) with the shaders swapped, so that the
    program's value, the factor, is the weight of the first: the second shader's. Emitters
    under it are weighted by the factor's own value (listed in the warning)."""
    sock = node.inputs.get("Factor")
    if not needs_program(sock, "value"):
        return None
    prog = compile_input(ctx, owner, node, "Factor", "value")
    fac = float(sock.default_value)
    if prog is None:
        fac = 0.5
    a, b = shader_inputs(node)
    ta, ea = _shader(ctx, owner, a, depth + 1)
    tb, eb = _shader(ctx, owner, b, depth + 1)
    w = mix_first_weight(fac)
    emissions = _scaled(ea, w) + _scaled(eb, 1.0 - w)
    if prog is None:
        return _mix(w, ta, tb), emissions
    if ea or eb:
        emissions = _mixed_emission(ctx, owner, node, ea, eb, w)
    if ta is None and tb is None:
        return None, emissions
    return ("pmix", prog, 1.0 - w, tb or _emit_black_leaf(owner), ta or _emit_black_leaf(owner)), emissions


def _summed_rgb(terms):
    return tuple(sum(max(float(rgb[c]), 0.0) * s for rgb, s in terms) for c in range(3))


def _mixed_emission(ctx, owner, node, ea, eb, w):
    """The emitter terms of a Mix Shader whose Factor a graph drives, over the terms ``ea`` of
    its first shader and ``eb`` of its second: one MixedEmission term when all of them are
    constants, else the terms weighted by the Factor's own value (listed in the warning)."""
    if any(isinstance(t, ProgramEmission) for t, _s in ea + eb):
        ctx.note(f"{owner}: '{node.name}' emission weighted by its Factor's own value (a graph drives an "
                 f"emitter under it too)")
        return _scaled(ea, w) + _scaled(eb, 1.0 - w)
    term = ProgramEmission((1.0, 1.0, 1.0))
    term.node = node
    term.names = None
    term.mixed = (_summed_rgb(ea), _summed_rgb(eb))
    return [(term, 1.0)]


def _hair(ctx, owner, node):
    """The leaf standing in for a Principled Hair BSDF or a Hair BSDF (addon/export/hair.py)."""
    from ...core import constants, plastic_params
    from .hair import hair_bsdf, principled_hair

    name = f"{owner}: {node.name}"
    if node.type == "BSDF_HAIR_PRINCIPLED":
        rgb, alpha, ior = principled_hair(ctx, owner, node)
        return _leaf(name=name, model=constants.MAT_PLASTIC,
                     params=plastic_params(alpha, alpha, layering="cycles", multiscatter=False),
                     reflectance=_refl(ctx, f"{owner} hair", rgb), specular=-1, ior=_ior(ctx, owner, ior))
    component, colour, alpha = hair_bsdf(ctx, owner, node)
    if component == "Transmission":
        return _transparent(ctx, name, colour)
    return conductor_leaf(ctx, name, alpha, alpha, _perfect_conductor(ctx), -1, reflectance=_refl(ctx, owner, colour))


def _emit_black_leaf(owner):
    from ...core import Material, constants, lambert_params

    return ("leaf", Material(name=f"{owner}: black", model=constants.MAT_LAMBERT, params=lambert_params()))


def node_colour(ctx, owner, node, fallback=(0.8, 0.8, 0.8)):
    """The main colour of a shader node (Base Color / Color), following a mix's first shader input."""
    seen = 0
    while node is not None and node.type in ("MIX_SHADER", "ADD_SHADER") and seen < 16:
        a, b = shader_inputs(node)
        node = a if a is not None else b
        seen += 1
    if node is None:
        return fallback
    for inp in COLOUR_INPUTS:
        sock = node.inputs.get(inp)
        if sock is not None and sock.type == "RGBA":
            return input_value(ctx, owner, node, (inp,), "colour")
    return fallback


def _emission_fields(ctx, name, emissions):
    from ...core import emission_luminance

    rgb, strength = combine_emission(emissions)
    if not strength > 0.0 or not max(rgb) > 0.0:
        return -1, 0.0
    live = [c for c, s in emissions if s > 0.0 and max(c[:3]) > 0.0]
    kelvin = [getattr(c, "temperature", None) for c in live]
    if len(live) == 1 and kelvin[0] is not None:  # a Blackbody node's colour: Planck's spectrum
        from ...core import light_emission_coeffs

        t = kelvin[0]
        index = ctx.emission_spectrum(("blackbody", round(t, 6)), f"blackbody {t:g} K", lambda: light_emission_coeffs(
            "blackbody", temperature=t, n_coeffs=ctx.n_coeffs))
        return index, float(emission_luminance(rgb, strength))
    if any(k is not None for k in kelvin):
        ctx.note(f"{name}: a blackbody emission combined with other emitters is rendered as its colour")
    return ctx.emission(f"{name} emission", rgb), float(emission_luminance(rgb, strength))


# ----------------------------------------------------------------------------- the Volume socket
#
# The Material Output's Volume socket becomes one homogeneous core Medium filling the
# mesh (Material.interior). Coefficients follow Cycles (intern/cycles/kernel/svm/closure.h,
# svm_node_closure_volume and svm_node_principled_volume), with d = Density and c = Color:
#
# * Volume Absorption: σa = d·(1 − c), no scattering.
# * Volume Scatter: σs = d·c; Cycles adds only σs to the extinction, so σa = 0.
# * Principled Volume: σs = d·c and σa = d·max(1 − c, 0)·max(1 − √a, 0) with a = Absorption
#   Color (Cycles takes the square root of the absorption colour); emission and blackbody
#   are not exported (noted), nor are volume-grid attributes (meshes have none).
# * Volume Coefficients: σa and σs are its Absorption / Scatter Coefficients.
# * Add Shader sums the coefficients; Mix Shader weights them by (1 − fac) and fac (a
#   linear mix of the closures, as Cycles does, not a stochastic choice).
#
# The phase function is Henyey–Greenstein; other phases are noted and rendered as HG with
# the node's Anisotropy (0 for Rayleigh, whose mean cosine is 0). Components with
# different anisotropies are combined into one HG whose g is their σs-weighted mean (the
# same mean cosine), noted. Blender's densities are per Blender unit: σ[1/m] = σ[1/BU] /
# scale_length. A colour becomes a spectrum as ctx.medium does: density × a bounded spectrum.

VOLUME_NODES = ("VOLUME_ABSORPTION", "VOLUME_SCATTER", "PRINCIPLED_VOLUME", "VOLUME_COEFFICIENTS")
G_LIMIT = 0.999  # |g| < 1 for core.validate


def _scale(rgb, k):
    return tuple(k * c for c in rgb)


def _volume_terms(ctx, owner, node, weight=1.0, depth=0):
    """The weighted volume closures of ``node``: [(σa rgb, σs rgb, g), ...] per Blender unit."""
    if node is None or weight <= 0.0:
        return []
    kind = node.type
    label = f"{owner}/{node.name}"
    if kind in ("MIX_SHADER", "ADD_SHADER"):
        if depth >= 2 * MIX_DEPTH:
            ctx.skip("shader mixes nested too deeply", label)
            return []
        a, b = shader_inputs(node)
        if kind == "ADD_SHADER":
            wa = wb = 1.0
        else:
            fac = constant_input(ctx, owner, node, "Factor", 0.5)
            wa = mix_first_weight(0.5 if fac is None else fac)
            wb = 1.0 - wa
        return (_volume_terms(ctx, owner, a, weight * wa, depth + 1)
                + _volume_terms(ctx, owner, b, weight * wb, depth + 1))
    if kind not in VOLUME_NODES:
        ctx.skip("volume shader nodes", label)
        return []

    def col(name):
        return tuple(max(c, 0.0) for c in input_value(ctx, owner, node, (name,), "colour"))

    def val(name, default=0.0):
        v = input_value(ctx, owner, node, (name,), "value")
        return default if v is None else v

    if kind == "VOLUME_ABSORPTION":
        d = max(val("Density"), 0.0) * weight
        return [(_scale(tuple(max(1.0 - c, 0.0) for c in col("Color")), d), BLACK, 0.0)]
    g = _phase_anisotropy(ctx, owner, node, val("Anisotropy"))
    if kind == "VOLUME_SCATTER":
        d = max(val("Density"), 0.0) * weight
        return [(BLACK, _scale(col("Color"), d), g)]
    if kind == "VOLUME_COEFFICIENTS":
        if max(col("Emission Coefficients")) > 0.0:
            ctx.skip("volume emission", f"{label}: emission coefficients (ignored)")
        return [(_scale(col("Absorption Coefficients"), weight), _scale(col("Scatter Coefficients"), weight), g)]
    # PRINCIPLED_VOLUME
    d = max(val("Density"), 0.0) * weight
    c = col("Color")
    root_a = tuple(c ** 0.5 for c in col("Absorption Color"))
    sigma_a = tuple(d * max(1.0 - ci, 0.0) * max(1.0 - ai, 0.0) for ci, ai in zip(c, root_a))
    if val("Emission Strength") > 0.0:
        ctx.skip("volume emission", f"{label}: emission (ignored)")
    if val("Blackbody Intensity") > 0.0:
        ctx.skip("volume emission", f"{label}: blackbody emission (ignored)")
    return [(sigma_a, _scale(c, d), g)]


def _phase_anisotropy(ctx, owner, node, anisotropy):
    phase = getattr(node, "phase", "HENYEY_GREENSTEIN")
    g = anisotropy
    if phase != "HENYEY_GREENSTEIN":
        g = 0.0 if phase == "RAYLEIGH" else anisotropy
        ctx.note(f"{owner}: '{node.name}' phase {phase.replace('_', '-').title()} rendered as "
                 f"Henyey–Greenstein g = {g:g}")
    return g


def export_volume(ctx, owner, node):
    """Index into ``ctx.media`` of the medium of the Volume shader ``node``, or -1 (none or empty)."""
    terms = _volume_terms(ctx, owner, node)
    if not terms:
        return -1
    sa = tuple(sum(t[0][k] for t in terms) for k in range(3))
    ss = tuple(sum(t[1][k] for t in terms) for k in range(3))
    weights = [sum(t[1]) for t in terms]
    gs = [t[2] for t, w in zip(terms, weights) if w > 0.0]
    g = sum(t[2] * w for t, w in zip(terms, weights)) / sum(weights) if gs else 0.0
    if gs and max(gs) - min(gs) > 1e-6:
        ctx.note(f"{owner}: volume anisotropies {', '.join(f'{x:g}' for x in gs)} combined into one "
                 f"Henyey–Greenstein g = {g:.4g} (their scattering-weighted mean)")
    if abs(g) >= G_LIMIT:
        ctx.note(f"{owner}: volume anisotropy {g:g} clamped to ±{G_LIMIT:g}")
        g = max(min(g, G_LIMIT), -G_LIMIT)
    per_metre = 1.0 / ctx.scale_length  # densities are per Blender unit
    return ctx.medium(f"{owner} volume", _scale(sa, per_metre), _scale(ss, per_metre), g)


def export_world_volume(ctx, world):
    """The world's Volume socket: the core's world has no medium, so a linked one is listed as not exported."""
    tree = getattr(world, "node_tree", None) if world is not None else None
    output = active_output(tree, "ShaderNodeOutputWorld")
    if output is not None and surface_node(output, "Volume") is not None:
        ctx.skip("world volume (the world has no medium)", world.name)


# ----------------------------------------------------------------------------- the material


def build_material(ctx, mat):
    """The root core Material of Blender material ``mat`` (its mix components are added to ctx first)."""
    from ...core import Material

    name = mat.name
    tree = mat.node_tree
    output = active_output(tree, "ShaderNodeOutputMaterial")
    # the original datablock's settings: edits of add-on properties need not re-evaluate the depsgraph
    settings = getattr(getattr(mat, "original", None) or mat, "spectral_gi", None)
    override = settings is not None and settings.model != "AUTO"
    if output is None:
        # No node tree (or no output): Blender's viewport colour stands in.
        if override:
            return _finish(ctx, name, override_tree(ctx, mat, settings, None), [])
        return Material(name=name, reflectance=_refl(ctx, name, rgb_of(mat.diffuse_color)))
    node = surface_node(output)
    volume = surface_node(output, "Volume")
    interior = export_volume(ctx, name, volume) if volume is not None else -1
    if node is None and not override:
        if volume is not None:  # a volume-only object: no surface, it only bounds its medium
            from ...core import constants
            return Material(name=name, model=constants.MAT_NULL, interior=interior)
        return Material(name=name)  # an unconnected output renders black
    if node is not None and node.type == "HOLDOUT" and not override:
        # Cycles' Holdout shader: a hole (alpha 0) for camera rays, black and absorbing for the others
        return Material(name=name, holdout=True, interior=interior)
    if override:
        root = _finish(ctx, name, override_tree(ctx, mat, settings, node), emission_terms(ctx, name, node))
    else:
        ctx.physical_layering = bool(getattr(settings, "physical_layering", False))
        try:
            bsdf, emissions = _shader(ctx, name, node)
        finally:
            ctx.physical_layering = False
        root = _finish(ctx, name, bsdf, emissions)
    root.interior = interior  # e.g. a glass holding a coloured liquid
    return root


def emission_terms(ctx, owner, node, depth=0):
    """The weighted emitters ``[(rgb, strength), ...]`` of the shader ``node`` (BSDFs are not read)."""
    if node is None or depth > 2 * MIX_DEPTH:
        return []
    if node.type == "MIX_SHADER":
        fac = constant_input(ctx, owner, node, "Factor", 0.5)
        w = mix_first_weight(0.5 if fac is None else fac)
        a, b = shader_inputs(node)
        return (_scaled(emission_terms(ctx, owner, a, depth + 1), w)
                + _scaled(emission_terms(ctx, owner, b, depth + 1), 1.0 - w))
    if node.type == "ADD_SHADER":
        a, b = shader_inputs(node)
        return emission_terms(ctx, owner, a, depth + 1) + emission_terms(ctx, owner, b, depth + 1)
    if node.type == "EMISSION":
        return [emission_term(ctx, owner, node, "Color", "Strength")]
    if node.type == "BSDF_PRINCIPLED":
        return [emission_term(ctx, owner, node, "Emission Color", "Emission Strength")]
    return []


def _finish(ctx, name, bsdf, emissions):
    if _depth(bsdf) > MIX_DEPTH:
        ctx.skip("shader mixes nested too deeply", name)
        bsdf = None
    root = _emit_tree(ctx, name, bsdf)
    root.name = name
    emissions, root.emission_program = _emission_program(ctx, name, emissions)
    root.emission, root.emission_luminance = _emission_fields(ctx, name, emissions)
    return root


def _emission_program(ctx, name, emissions):
    """(the constant emitter terms, index of the program of the one driven by a node graph or -1).
    A second graph-driven emitter, or one whose graph cannot be compiled, uses its inputs' own
    values (listed in the warning)."""
    consts = []
    prog = -1
    for term, weight in emissions:
        if not isinstance(term, ProgramEmission):
            consts.append((term, weight))
            continue
        node = term.node
        if prog < 0 and weight > 0.0:
            if term.mixed is not None:
                k = compile_mixed_emission(ctx, name, node, *term.mixed, weight=weight, images=image_texture)
            else:
                colour_name, strength_name = term.names
                k = compile_input(ctx, name, node, colour_name, "colour", scale=strength_name, weight=weight)
            if k is not None:
                prog = k
                continue
        elif prog >= 0:
            ctx.skip("shader nodes (the input's own value instead)",
                     f"{name}/{node.name}: a second emitter driven by a node graph")
        consts += _constant_terms(node, term, weight)
    return consts, prog


def _constant_terms(node, term, weight):
    """The constant stand-in of a graph-driven emitter term: its inputs' own values (a mixed
    emission: its shaders' terms by the Factor's own value)."""
    if term.mixed is not None:
        f = min(max(float(node.inputs["Factor"].default_value), 0.0), 1.0)
        return [(term.mixed[0], (1.0 - f) * weight), (term.mixed[1], f * weight)]
    colour_name, strength_name = term.names
    return [(rgb_of(node.inputs[colour_name].default_value), float(node.inputs[strength_name].default_value) * weight)]


# ----------------------------------------------------------------------------- the panel's override


def _spectrum_colour(ctx, mat, settings, node):
    """Reflectance spectrum index of the override: the node colour uplifted, or a ColorChecker patch."""
    if settings.spectrum == "PRESET":
        return _preset_reflectance(ctx, settings.reflectance_preset)
    if settings.spectrum == "FILE":  # a tabulated reflectance; a bad file falls back to the colour (reported)
        index = ctx.spectrum_file(getattr(settings, "spectrum_file", ""), "reflectance", f"material {mat.name!r}")
        if index is not None:
            return index
    colour = node_colour(ctx, mat.name, node, fallback=None) if node is not None else None
    if colour is None:
        colour = rgb_of(mat.diffuse_color)
    return _refl(ctx, mat.name, colour)


def override_tree(ctx, mat, settings, node):
    """The BSDF tree chosen in the material panel (``mat.spectral_gi``)."""
    from ...core import (
        blinn_phong_params, constants, lafortune_params, lambert_params, mirror_params, phong_params,
        ward_params)

    name = f"{mat.name}: {settings.model.lower()}"
    two = bool(settings.two_sided)
    model = settings.model
    if model in ("LAMBERT", "PHONG", "BLINN_PHONG", "WARD", "LAFORTUNE", "MIRROR"):
        ra = _spectrum_colour(ctx, mat, settings, node)
        spec = _tint(ctx, f"{mat.name} specular", tuple(settings.specular_color))
        if spec == -1:
            spec = _refl(ctx, "white", WHITE)
        if model == "LAMBERT":
            return _leaf(name=name, model=constants.MAT_LAMBERT, params=lambert_params(two), reflectance=ra)
        if model == "MIRROR":
            return _leaf(name=name, model=constants.MAT_MIRROR, params=mirror_params(two), reflectance=ra)
        if model == "PHONG":
            return _leaf(name=name, model=constants.MAT_PHONG, params=phong_params(settings.exponent, two),
                         reflectance=ra, specular=spec)
        if model == "BLINN_PHONG":
            return _leaf(name=name, model=constants.MAT_BLINN_PHONG,
                         params=blinn_phong_params(settings.exponent, two), reflectance=ra, specular=spec)
        if model == "WARD":
            return _leaf(name=name, model=constants.MAT_WARD,
                         params=ward_params(settings.alpha_x, settings.alpha_y, settings.ward_variant.lower(), two),
                         reflectance=ra, specular=spec)
        lobes = [tuple(getattr(settings, f"lobe_{k}")) for k in range(1, settings.lobe_count + 1)]
        return _leaf(name=name, model=constants.MAT_LAFORTUNE, params=lafortune_params(lobes, two),
                     reflectance=ra, specular=spec)
    ax, ay = float(settings.alpha_x), float(settings.alpha_y)
    if model == "CONDUCTOR":
        if settings.spectrum == "PRESET":
            eta, kappa = _metal_tables(ctx, settings.metal_preset)
        else:
            colour = node_colour(ctx, mat.name, node, fallback=None) if node is not None else None
            eta, kappa = _conductor_tables(ctx, colour or rgb_of(mat.diffuse_color), WHITE)
        return conductor_leaf(ctx, name, ax, ay, eta, kappa, two_sided=two)
    if model == "GLASS":
        if settings.spectrum == "PRESET":
            return dielectric_leaf(ctx, name, ax, ay, eta_table=_glass_table(ctx, settings.glass_preset))
        ior = 1.5
        tint = None
        if node is not None:
            v = input_value(ctx, mat.name, node, ("IOR",), "value")
            ior = _ior(ctx, mat.name, v) if v is not None else 1.5
            colour = node_colour(ctx, mat.name, node, fallback=None)
            tint = _refl(ctx, mat.name, colour) if colour is not None else None
        return dielectric_leaf(ctx, name, ax, ay, ior=ior, transmission=tint, reflection=tint if tint is not None
                               else -1)
    raise ValueError(f"unknown Spectral GI material model {model!r}")
