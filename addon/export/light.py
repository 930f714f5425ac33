"""Blender lights → core lights: area, point, spot and sun, with photometric units.

Brightness (``Light.spectral_gi.unit``): by default Blender's Power / Strength and colour,
read as Cycles reads them at 683 lm per Blender watt (core/photometry/units.py); or lumens,
candela, lux (sun) or cd/m² (area) from a data sheet. Colour
(``Light.spectral_gi.spectrum``): the light's RGB colour (and Blender's temperature
tint) as a smooth spectrum, or a blackbody, a CIE illuminant or a CIE LED spectrum.
With a named spectrum and Blender's units, the light counts as white (its luminous
output is 683 lm per Blender watt) and Blender's colour is not used.

Photometric profile (``Light.spectral_gi.profile``, point and spot lights): an IES or
EULUMDAT file, or a sample from presets/ies, read by core into ``Scene.profiles``; the
light's frame is its object's: nadir along local −Z, C0 towards local −Y (Cycles' IES
convention). Brightness: the profile's candela, or the light's unit (lumens: total output;
candela: peak; Blender Power: the output the light has without the profile). A missing or
unreadable file is reported in the export warning and the light renders without it.
"""
import math

import numpy as np

from .context import ExportError
from .convert import (
    AREA_SHAPES, area_light_geometry, area_light_normalising_area, light_power_watts, light_rgb)

UNIT_NAMES = {"BLENDER": "blender_W", "LUMEN": "lm", "CANDELA": "cd", "LUX": "lux", "NIT": "cd/m2"}
SOURCE_NAMES = {"RGB": "rgb", "BLACKBODY": "blackbody", "ILLUMINANT": "illuminant", "LED": "led", "FILE": "file"}


# ----------------------------------------------------------------------------- geometry (pure functions)

def light_position_metres(matrix, scale_length):
    """World position of a light object (its matrix's translation) in metres."""
    m = np.asarray(matrix, dtype=np.float64)
    return tuple(float(x) for x in m[:3, 3] * float(scale_length))


def light_direction(matrix):
    """Unit world direction of the light object's local -Z axis (where spots point and sunlight travels)."""
    m = np.asarray(matrix, dtype=np.float64)
    d = -m[:3, 2]
    n = float(np.linalg.norm(d))
    if not n > 0.0:
        raise ExportError("a light's matrix has a zero scale")
    return tuple(float(x) for x in d / n)


def has_uniform_scale(matrix, tolerance=1e-6):
    """True if the matrix scales its three axes alike (a spot's cone stays circular)."""
    m = np.asarray(matrix, dtype=np.float64)
    s = np.linalg.norm(m[:3, :3], axis=0)
    return bool(np.all(np.abs(s - s.mean()) <= tolerance * max(1.0, float(s.mean()))))


def sphere_luminance(intensity_cd, radius_m):
    """Luminance (cd/m²) of a sphere of ``radius_m`` with luminous intensity ``intensity_cd``: I / (π r²);
    0 for a point."""
    r = float(radius_m)
    return float(intensity_cd) / (math.pi * r * r) if r > 0.0 else 0.0


def sun_disc_luminance(illuminance_lux, angle_rad):
    """Luminance (cd/m²) of a uniform sun disc of angular diameter ``angle_rad`` giving ``illuminance_lux``.

    A disc of half-angle θ seen at normal incidence gives E = L π sin²θ. 0 for a point sun.
    """
    s = math.sin(0.5 * float(angle_rad))
    return float(illuminance_lux) / (math.pi * s * s) if s > 0.0 else 0.0


# ----------------------------------------------------------------------------- settings of one light

def _settings(data):
    """(unit name, value, spectrum source, temperature, name) from ``Light.spectral_gi`` (defaults without it)."""
    s = getattr(data, "spectral_gi", None)
    if s is None:
        return "blender_W", None, "rgb", 6500.0, ""
    source = SOURCE_NAMES.get(s.spectrum, "rgb")
    name = s.illuminant if source == "illuminant" else s.led if source == "led" else ""
    if source == "file":
        name = getattr(s, "spectrum_file", "")
    return UNIT_NAMES.get(s.unit, "blender_W"), float(s.value), source, float(s.temperature), name


def _spectrum(ctx, name, data, source, temperature, preset):
    """(spectrum index, rgb weight for Blender's units) of the light's emission."""
    from ...core import light_emission_coeffs

    if source == "file":  # a tabulated emission shape; a bad file falls back to the RGB colour (reported)
        index = ctx.spectrum_file(preset, "emission", f"light {name!r}")
        if index is not None:
            return index, (1.0, 1.0, 1.0)
        source = "rgb"
    if source == "rgb":
        rgb = light_rgb(data.color, getattr(data, "use_temperature", False),
                        getattr(data, "temperature_color", (1.0, 1.0, 1.0)))
        if not max(rgb) > 0.0:
            return None, rgb
        return ctx.emission(f"{name} light", rgb), rgb
    key = (source, round(temperature, 6)) if source == "blackbody" else (source, preset)
    label = f"blackbody {temperature:g} K" if source == "blackbody" else preset
    try:
        index = ctx.emission_spectrum(key, label, lambda: light_emission_coeffs(
            source, temperature=temperature, name=preset, n_coeffs=ctx.n_coeffs))
    except ValueError as exc:
        raise ExportError(f"light {name!r}: {exc}") from None
    return index, (1.0, 1.0, 1.0)


def _photometric(name, kind, unit, value, **kw):
    from ...core import light_photometric

    try:
        return float(light_photometric(kind, unit, value, **kw))
    except ValueError as exc:
        raise ExportError(f"light {name!r}: {exc}") from None


def light_x_axis(matrix):
    """Unit world direction of the light object's local +X axis (with local −Z, a profile's frame)."""
    m = np.asarray(matrix, dtype=np.float64)
    x = m[:3, 0]
    n = float(np.linalg.norm(x))
    if not n > 0.0:
        raise ExportError("a light's matrix has a zero scale")
    return tuple(float(v) for v in x / n)


def profile_file(data):
    """(label, absolute path) of the light's profile, or None: a preset from presets/ies or a file."""
    s = getattr(data, "spectral_gi", None)
    choice = getattr(s, "profile", "NONE") if s is not None else "NONE"
    if choice == "NONE":
        return None
    if choice.startswith("PRESET_"):
        from ...core import photometric_presets

        stem = choice[len("PRESET_"):]
        path = photometric_presets().get(stem)
        return (stem, str(path) if path is not None else stem)
    raw = str(getattr(s, "profile_path", "") or "")
    try:
        import bpy

        path = bpy.path.abspath(raw) if raw else ""
    except Exception:  # outside Blender (tests of the pure functions)
        path = raw
    return (raw, path)


def _profile_index(ctx, path):
    """Index of the profile read from ``path`` in this export (each file read once)."""
    from ...core import read_profile

    if not hasattr(ctx, "profiles"):
        ctx.profiles = []
        ctx.profile_index = {}
    if path not in ctx.profile_index:
        ctx.profiles.append(read_profile(path))
        ctx.profile_index[path] = len(ctx.profiles) - 1
    return ctx.profile_index[path]


def _apply_profile(ctx, data, matrix, name, light, unit, amount):
    """Give a point or spot ``light`` its photometric profile, if it has one; a file that
    cannot be read is reported (the light renders without a profile)."""
    from ...core import PhotometricError, spot_solid_angle

    found = profile_file(data)
    if found is None:
        return
    label, path = found
    if not path:
        ctx.skip("light profiles with no file set", name)
        return
    try:
        index = _profile_index(ctx, path)
    except (PhotometricError, OSError) as exc:
        ctx.skip("light profiles that could not be read", f"{name}: {exc}")
        return
    light.profile = index
    light.axis_u = light_x_axis(matrix)
    brightness = getattr(data.spectral_gi, "profile_brightness", "FILE")
    if brightness == "FILE":
        light.profile_mode = "file"
    elif unit == "cd":
        light.profile_mode = "peak"  # intensity is already the value in cd
    elif unit == "lm":
        light.profile_mode = "flux"
        light.flux = float(amount)
    else:  # Blender power: the output the light has without the profile
        light.profile_mode = "flux"
        cone = spot_solid_angle(light.spot_angle, light.spot_blend) if data.type == "SPOT" else 4.0 * math.pi
        light.flux = float(light.intensity) * cone


# Cycles' IES Texture node (intern/cycles util/ies.cpp, Blender 4.x/5.x) outputs the file's
# candela (times its multiplier and ballast factors) times 4π/177.83: a candela read as W/sr
# at D65's luminous efficacy, 177.83 lm/W, times the 4π of a point light's watts per W/sr.
# The light's intensity is then P/(4π) · strength · that, i.e. P · strength · I_file / 177.83
# W/sr, and at 683 lm per Blender watt the profile's candela are scaled by 683 P / 177.83:
# a 177.83/683 W light shows the file's candela as they are.
CYCLES_IES_EFFICACY = 177.83  # lm/W


def cycles_ies_node(data):
    """The IES Texture node of a point or spot light's node tree (Cycles), or None."""
    tree = getattr(data, "node_tree", None)
    if tree is None or not getattr(data, "use_nodes", False) or data.type not in ("POINT", "SPOT"):
        return None
    for node in tree.nodes:
        if node.type == "TEX_IES" and not getattr(node, "mute", False) and any(
                o.is_linked for o in node.outputs):
            return node
    return None


def _ies_node_profile(ctx, node, name):
    """Index of the profile of an IES Texture node (its file, or its internal text), or None."""
    import bpy

    if getattr(node, "mode", "EXTERNAL") == "INTERNAL":
        text = getattr(node, "ies", None)
        if text is None:
            ctx.skip("IES Texture nodes with no text", name)
            return None
        import tempfile
        from pathlib import Path

        folder = Path(tempfile.mkdtemp(prefix="spectral_gi_ies_"))
        path = folder / (Path(text.name).stem + ".ies")
        path.write_text(text.as_string(), encoding="utf-8")
    else:
        raw = str(getattr(node, "filepath", "") or "")
        if not raw:
            ctx.skip("IES Texture nodes with no file", name)
            return None
        path = bpy.path.abspath(raw)
    from ...core import PhotometricError

    try:
        return _profile_index(ctx, str(path))
    except (PhotometricError, OSError) as exc:
        ctx.skip("light profiles that could not be read", f"{name}: {exc}")
        return None


def _apply_cycles_ies(ctx, node, matrix, name, light, unit):
    """The light's IES Texture node as its profile, at Cycles' brightness (see above)."""
    index = _ies_node_profile(ctx, node, name)
    if index is None:
        return
    prof = ctx.profiles[index]
    light.profile = index
    light.axis_u = light_x_axis(matrix)
    strength = node.inputs["Strength"].default_value if "Strength" in node.inputs else 1.0
    if "Strength" in node.inputs and node.inputs["Strength"].is_linked:
        ctx.note(f"{name}: the IES Texture node's Strength is linked, used its unlinked value")
    if "Vector" in node.inputs and node.inputs["Vector"].is_linked:
        ctx.note(f"{name}: the IES Texture node's Vector input is ignored (the light's own frame)")
    if unit != "blender_W":
        ctx.note(f"{name}: IES Texture node with a photometric unit: the unit's value is the profile's peak")
        light.profile_mode = "peak"
        return
    peak = float(np.max(prof.candela)) if prof.candela.size else 0.0
    # light.intensity holds the light's candela without a profile, 683 P lum(rgb) / (4π)
    light.intensity = float(light.intensity) * 4.0 * math.pi * max(float(strength), 0.0) * peak \
        / CYCLES_IES_EFFICACY
    light.profile_mode = "peak"


def export_light(ctx, obj, matrix, name):
    """A core Light for evaluated light object ``obj`` placed by ``matrix``, or None (recorded as skipped)."""
    from ...core import Light, constants

    data = obj.data
    kind = data.type
    if kind not in ("AREA", "POINT", "SPOT", "SUN"):
        ctx.skip(f"{kind.lower()} lights", name)
        return None
    ies_node = cycles_ies_node(data)
    if ies_node is None and getattr(data, "node_tree", None) is not None and getattr(data, "use_nodes", False):
        ctx.skip("light node trees", name)
    unit, value, source, temperature, preset = _settings(data)
    power = light_power_watts(data.energy, getattr(data, "exposure", 0.0))
    if power < 0.0:
        ctx.note(f"{name}: negative power treated as 0")
        power = 0.0
    spectrum, rgb = _spectrum(ctx, name, data, source, temperature, preset)
    if spectrum is None:
        return None  # black light
    amount = power if unit == "blender_W" else value
    visible = bool(getattr(obj, "visible_camera", False))
    zero = (0.0, 0.0, 0.0)

    if kind == "AREA":
        return _area_light(ctx, obj, data, matrix, name, unit, amount, rgb, spectrum, visible)

    position = light_position_metres(matrix, ctx.scale_length)
    if kind in ("POINT", "SPOT"):
        radius = max(0.0, float(data.shadow_soft_size)) * ctx.scale_length
        spot_angle = float(data.spot_size) if kind == "SPOT" else math.pi
        spot_blend = float(data.spot_blend) if kind == "SPOT" else 0.0
        intensity = _photometric(name, kind, unit, amount, rgb=rgb, spot_angle=spot_angle, spot_blend=spot_blend)
        if kind == "SPOT" and not has_uniform_scale(matrix):
            ctx.note(f"{name}: non-uniform scale of a spot light ignored (its cone stays circular)")
        light = Light(
            name=name, kind=constants.LIGHT_SPOT if kind == "SPOT" else constants.LIGHT_POINT,
            position=position, axis_u=zero, axis_v=zero, spectrum=spectrum,
            luminance=sphere_luminance(intensity, radius), two_sided=False, visible=visible,
            radius=radius, intensity=intensity, direction=light_direction(matrix),
            spot_angle=spot_angle, spot_blend=spot_blend)
        if ies_node is not None and profile_file(data) is None:
            _apply_cycles_ies(ctx, ies_node, matrix, name, light, unit)
        else:
            if ies_node is not None:
                ctx.note(f"{name}: the light's Spectral GI profile is used, not its IES Texture node")
            _apply_profile(ctx, data, matrix, name, light, unit, amount)
        return light
    # SUN
    angle = max(0.0, float(data.angle))
    illuminance = _photometric(name, kind, unit, amount, rgb=rgb)
    return Light(
        name=name, kind=constants.LIGHT_SUN, position=position, axis_u=zero, axis_v=zero, spectrum=spectrum,
        luminance=sun_disc_luminance(illuminance, angle), two_sided=False, visible=visible,
        direction=light_direction(matrix), illuminance=illuminance, angle=angle)


def _area_light(ctx, obj, data, matrix, name, unit, amount, rgb, spectrum, visible):
    from ...core import Light, constants

    if data.shape not in AREA_SHAPES:
        ctx.skip("area light shapes", f"{name} ({data.shape})")
        return None
    position, axis_u, axis_v, is_ellipse, area = area_light_geometry(
        matrix, data.shape, data.size, data.size_y, ctx.scale_length)
    if not area > 0.0:
        ctx.skip("area lights of zero size", name)
        return None
    if getattr(data, "spread", math.pi) < math.pi - 1e-6:
        ctx.note(f"{name}: spread ignored (emits over the full hemisphere)")
    if unit == "blender_W":
        area = area_light_normalising_area(area, getattr(data, "normalize", True), ctx.scale_length)
    luminance = _photometric(name, "AREA", unit, amount, rgb=rgb, area_m2=area)
    return Light(
        name=name,
        kind=constants.LIGHT_ELLIPSE if is_ellipse else constants.LIGHT_RECT,
        position=tuple(float(x) for x in position),
        axis_u=tuple(float(x) for x in axis_u),
        axis_v=tuple(float(x) for x in axis_v),
        spectrum=spectrum,
        luminance=luminance,
        two_sided=False,
        visible=visible,
    )
