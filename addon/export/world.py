"""The Blender world → a constant background or an equirectangular environment image.

Supported: a Background (or Emission) node whose Color is a constant, an Environment
Texture node (equirectangular projection), optionally fed by a Mapping node's rotation
about Z, or a Sky Texture node of the single- or multiple-scattering type (its sky an
environment image and its sun disc a sun light, computed spectrally by the core) or of
the Preetham type (its closed form); the Background's Strength scales each.
"""
import numpy as np

from .convert import rgb_of
from .nodes import active_output, input_value, surface_node

BACKGROUND_NODES = ("BACKGROUND", "EMISSION")
LINEAR_SPACES = ("Linear Rec.709", "Linear", "Linear CIE-XYZ E", "Non-Color", "Raw", "scene_linear")
SRGB_SPACES = ("sRGB",)


def image_rgb_top_down(flat_rgba, width, height):
    """Blender's flat RGBA pixels (rows bottom-up) → float32 (H, W, 3) rows top-down (zenith first)."""
    a = np.asarray(flat_rgba, dtype=np.float32).reshape(int(height), int(width), 4)
    return np.ascontiguousarray(a[::-1, :, :3])


def mapping_z_rotation(ctx, name, mapping):
    """Z rotation (rad) of a Mapping node feeding the environment, as the core's ``World.rotation``.

    A POINT/VECTOR mapping rotates the lookup vector by +z, which turns the map by −z: the
    core's ``World.rotation`` is then −z (checked against Cycles renders of a rotated map:
    ΔE00 2.5 with −z, 14 with +z). A TEXTURE mapping applies the inverse transform, so +z.
    Location, scale and the X/Y rotations are not supported (noted).
    """
    rot = tuple(float(x) for x in mapping.inputs["Rotation"].default_value)
    loc = (tuple(float(x) for x in mapping.inputs["Location"].default_value) if "Location" in mapping.inputs
           else (0,) * 3)
    scale = tuple(float(x) for x in mapping.inputs["Scale"].default_value) if "Scale" in mapping.inputs else (1,) * 3
    if mapping.inputs["Rotation"].is_linked:
        ctx.note(f"{name}: a linked Mapping rotation is ignored")
        return 0.0
    if abs(rot[0]) > 1e-6 or abs(rot[1]) > 1e-6 or any(abs(x) > 1e-6 for x in loc) or \
            any(abs(x - 1.0) > 1e-6 for x in scale):
        ctx.note(f"{name}: only the Mapping node's Z rotation is used")
    z = rot[2]
    return z if getattr(mapping, "vector_type", "POINT") == "TEXTURE" else -z


def _environment(ctx, name, tex):
    """(image array (H, W, 3) linear Rec.709, rotation rad) of an Environment Texture node, or None."""
    from ...core import sRGB_decode

    img = tex.image
    if img is None:
        ctx.skip("environment textures without an image", f"{name}/{tex.name}")
        return None
    if getattr(tex, "projection", "EQUIRECTANGULAR") != "EQUIRECTANGULAR":
        ctx.skip("environment projections other than equirectangular", f"{name}/{tex.name} ({tex.projection})")
        return None
    w, h = (int(x) for x in img.size)
    if w < 1 or h < 1:
        ctx.skip("environment images that cannot be loaded", f"{name}/{img.name}")
        return None
    interp = getattr(tex, "interpolation", "Linear")
    if interp != "Linear":
        ctx.note(f"{name}/{tex.name}: {interp} interpolation rendered as Linear (bilinear)")
    buf = np.empty(w * h * 4, dtype=np.float32)
    img.pixels.foreach_get(buf)
    rgb = image_rgb_top_down(buf, w, h)
    space = img.colorspace_settings.name
    if not img.is_float and space in SRGB_SPACES:
        rgb = np.asarray(sRGB_decode(rgb), dtype=np.float32)  # byte images keep their file's encoding
    elif space not in LINEAR_SPACES and space not in SRGB_SPACES:
        ctx.note(f"{name}: image {img.name!r} in colour space {space!r} read as linear Rec.709")
    bad = ~np.isfinite(rgb) | (rgb < 0.0)
    if bad.any():
        ctx.note(f"{name}: {int(bad.sum())} negative or non-finite texels of {img.name!r} set to 0")
        rgb = np.where(bad, np.float32(0.0), rgb).astype(np.float32)
    rotation = 0.0
    vec = tex.inputs.get("Vector")
    if vec is not None and vec.is_linked:
        src = vec.links[0].from_node
        if src.type == "MAPPING":
            rotation = mapping_z_rotation(ctx, name, src)
        elif src.type != "TEX_COORD":
            ctx.note(f"{name}: environment vector from {src.name!r} ignored (default direction used)")
    return np.ascontiguousarray(rgb, dtype=np.float32), float(rotation)


SKY_TYPES = {"SINGLE_SCATTERING": "single", "MULTIPLE_SCATTERING": "multiple", "NISHITA": "single"}


def _sky(ctx, name, tex, strength):
    """(World, sun Light or None) of a Sky Texture node, or None for a sky type the core lacks."""
    from ...core import Light, World, blender_sky, constants, emission_from_samples

    kind = SKY_TYPES.get(tex.sky_type)
    if kind is None and tex.sky_type != "PREETHAM":
        ctx.skip("Sky Texture types other than Single Scattering, Multiple Scattering and Preetham "
                 "(constant colour used)", f"{name}/{tex.name} ({tex.sky_type})")
        return None
    vec = tex.inputs.get("Vector")
    if vec is not None and vec.is_linked:
        ctx.note(f"{name}: Sky Texture vector from {vec.links[0].from_node.name!r} ignored (default direction used)")
    if tex.sky_type == "PREETHAM":
        from ...core import preetham_sky

        image = preetham_sky(tuple(float(x) for x in tex.sun_direction), float(tex.turbidity))
        return World(image=image, image_scale=float(strength)), None
    if kind == "multiple":
        ctx.note(f"{name}: Multiple Scattering sky approximated (single scattering of its atmosphere "
                 "plus an analytic multiple-scattering term)")
    params = dict(sky_type=kind, sun_elevation=float(tex.sun_elevation), sun_rotation=float(tex.sun_rotation),
                  sun_size=float(tex.sun_size), sun_intensity=float(tex.sun_intensity), sun_disc=bool(tex.sun_disc),
                  altitude=float(tex.altitude), air_density=float(tex.air_density),
                  aerosol_density=float(getattr(tex, "aerosol_density", getattr(tex, "dust_density", 1.0))),
                  ozone_density=float(tex.ozone_density))  # Blender 4.x's Nishita names aerosols "dust"
    day = blender_sky(**params)
    world = World(image=day.image, image_scale=float(strength))
    if day.sun_direction is None or not day.sun_illuminance > 0.0:
        return world, None
    key = ("sky sun",) + tuple(sorted(params.items()))
    index = ctx.emission_spectrum(key, f"{name} sun", lambda: emission_from_samples(
        day.sun_wavelengths, day.sun_irradiance, ctx.n_coeffs))
    sun = Light(name=f"{name} sun", kind=constants.LIGHT_SUN, position=(0.0, 0.0, 0.0), axis_u=(0.0, 0.0, 0.0),
                axis_v=(0.0, 0.0, 0.0), spectrum=index, luminance=0.0, direction=day.sun_direction,
                illuminance=day.sun_illuminance * float(strength), angle=day.sun_angle, visible=True)
    return world, sun


def export_world(ctx, world):
    """A core World: an environment image × strength, the Background colour × strength, or black."""
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
        color = node.inputs.get("Color")
        if color is not None and color.is_linked and color.links[0].from_node.type == "TEX_ENVIRONMENT":
            strength = input_value(ctx, f"world {name}", node, ("Strength",), "value")
            env = _environment(ctx, f"world {name}", color.links[0].from_node)
            if env is not None:
                if not strength > 0.0:
                    return World()
                image, rotation = env
                return World(image=image, rotation=rotation, image_scale=float(strength))
        if color is not None and color.is_linked and color.links[0].from_node.type == "TEX_SKY":
            strength = input_value(ctx, f"world {name}", node, ("Strength",), "value")
            if not strength > 0.0:
                return World()
            sky = _sky(ctx, f"world {name}", color.links[0].from_node, strength)
            if sky is not None:
                core_world, sun = sky
                if sun is not None:
                    ctx.world_lights = [sun]
                return core_world
        rgb = input_value(ctx, f"world {name}", node, ("Color",), "colour")
        strength = input_value(ctx, f"world {name}", node, ("Strength",), "value")
    if not strength > 0.0 or not max(rgb) > 0.0:
        return World()
    return World(background=ctx.emission(f"world {name}", rgb), luminance=float(emission_luminance(rgb, strength)))
