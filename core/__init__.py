"""spectral_gi.core: the renderer. Never imports bpy.

The add-on and the command line use only the names in ``__all__``.
"""
from . import constants
from . import lux  # lighting analysis: calculation surfaces, grids, reports, false colour
from .lux.schedule import luminaire_schedule
from .io.atomic import atomic_path
from .io.atomic import write_text as write_text_atomic
from .film import Developed, Film, develop
from .farm import Farm, FarmError  # render farms on Dask (imported when used)
from .io.exr import read_channels as read_exr
from .io.exr import write_render as write_exr
from .io.png import encode_png, write_png
from .io.presets import load_cornell_box_data
from .integrators.render import RenderStats, kernels_compiled, render, warm_up
from .integrators.interactive import Frame, InteractiveRender
from .film.denoise import DenoiseUnavailable, denoise, denoise_available
from .scene import (
    Camera, Light, Material, Mesh, RenderSettings, Scene, SceneError, SpectrumTable, World, validate)
from .scene import load as load_scene
from .scene import save as save_scene
from .scene.builtin import cornell_box
from .spectra.uplift import (
    emission_from_rgb, emission_from_samples, emission_to_rgb, reflectance_from_rgb,
    reflectance_from_samples, reflectance_to_rgb)
from .colour import sRGB_decode
from .colour.compare import compare_images, delta_e_image, side_by_side
from .photometry.units import (
    EMITTER_UNITS, LIGHT_UNITS, area_light_luminance, emission_luminance, emitter_luminance, light_emission_coeffs,
    light_photometric, light_spectrum_names, point_light_intensity, scene_white_xy, spot_solid_angle, sun_illuminance)
# materials: BSDF parameter rows, IOR tables and named spectral presets (the add-on's material export)
from .bsdfs.params import (
    blinn_phong_params, conductor_params, dielectric_params, ggx_conductor_params, ggx_dielectric_params,
    lafortune_params, lambert_params, make_params, mirror_params, phong_params, plastic_params, ward_params)
from .bsdfs.artist import conductor_from_colour
from .bsdfs.presets import (
    glass_preset, glass_preset_names, metal_preset, metal_preset_names, reflectance_preset,
    reflectance_preset_names, tabulate_reflectance, wavelength_grid)
from .scene import IORTable
from .scene import Medium  # participating media (compendium item 54)
from .scene import Texture  # image textures
from .scene.textures import reached_materials
# tabulated spectrum files (materials' reflectance, lights' emission shape)
from .io.spectrum_file import SpectrumFileError, load_spectrum_file, spectrum_file_coeffs
# photometric light profiles (IES LM-63, EULUMDAT)
from .photometry.profiles import PhotometricError, read_profile
from .photometry.profiles import preset_profiles as photometric_presets
from .scene import Profile
# the daylight of Blender's Sky Texture, computed spectrally
from .lights.sky import Daylight, blender_sky, preetham_sky
# lux on sensor meshes
from .integrators.sensors import has_sensors, illuminance_image, illuminance_stats, render_illuminance
# radiosity for diffuse scenes (compendium items 53, 55–62)
from .integrators.radiosity import (
    RadiositySolution, differential_form_factor, element_form_factors, final_gather, form_factor_point_polygon,
    form_factor_polygon_polygon, radiosity, render_radiosity)
from .integrators.radiosity import illuminance_at as radiosity_illuminance
from .integrators.radiosity import lux_integrator as radiosity_lux_integrator
from .integrators.radiosity import solve as radiosity_solve
from .geometry import curves as hair_curves  # curve tessellation (particle hair, Curves objects)
from .shading.compiler import Unsupported as UnsupportedNode
from .shading.compiler import compile_output as compile_shader_output
from .shading import PROGRAM_FIELDS

__all__ = [
    "Farm", "FarmError",
    "constants", "lux", "radiosity_solve", "hair_curves", "UnsupportedNode", "compile_shader_output", "PROGRAM_FIELDS",
    "reached_materials",
    "atomic_path", "write_text_atomic", "encode_png", "luminaire_schedule",
    "Scene", "Mesh", "Material", "Light", "Camera", "World", "RenderSettings", "SpectrumTable", "Medium",
    "SceneError", "validate", "load_scene", "save_scene",
    "reflectance_from_rgb", "emission_from_rgb", "reflectance_from_samples", "emission_from_samples",
    "reflectance_to_rgb", "emission_to_rgb",
    "emission_luminance", "area_light_luminance", "emitter_luminance", "EMITTER_UNITS",
    "render", "RenderStats", "kernels_compiled", "warm_up", "Film", "Developed", "develop",
    "InteractiveRender", "Frame", "denoise", "denoise_available", "DenoiseUnavailable",
    "write_exr", "read_exr", "write_png",
    "cornell_box", "load_cornell_box_data",
    "IORTable", "make_params", "lambert_params", "phong_params", "blinn_phong_params", "ward_params",
    "lafortune_params", "mirror_params", "dielectric_params", "conductor_params", "ggx_conductor_params",
    "ggx_dielectric_params", "plastic_params", "conductor_from_colour",
    "wavelength_grid", "reflectance_preset_names", "metal_preset_names", "glass_preset_names",
    "reflectance_preset", "metal_preset", "glass_preset", "tabulate_reflectance",
    "compare_images", "delta_e_image", "side_by_side", "sRGB_decode",
    "LIGHT_UNITS", "light_photometric", "light_emission_coeffs", "light_spectrum_names",
    "point_light_intensity", "spot_solid_angle", "sun_illuminance", "scene_white_xy",
    "Texture",
    "SpectrumFileError", "load_spectrum_file", "spectrum_file_coeffs",
    "Daylight", "blender_sky", "preetham_sky",
    "Profile", "read_profile", "PhotometricError", "photometric_presets",
    "render_illuminance", "illuminance_stats", "illuminance_image", "has_sensors",
    "point_illuminance", "point_luminance", "vertical_illuminance", "cylindrical_illuminance",
    "semicylindrical_illuminance", "unlit_points",
    "radiosity", "RadiositySolution", "radiosity_illuminance", "form_factor_point_polygon",
    "form_factor_polygon_polygon", "element_form_factors", "differential_form_factor", "radiosity_lux_integrator",
    "final_gather", "render_radiosity",
]

# lux and cd/m² at points (core/integrators/illuminance.py), imported on first use: the module
# loads the path kernel's code, which a plain ``import core`` does not need
_POINT_MEASURES = {"point_illuminance": "illuminance", "point_luminance": "luminance",
                   "vertical_illuminance": "vertical_illuminance", "cylindrical_illuminance": "cylindrical_illuminance",
                   "semicylindrical_illuminance": "semicylindrical_illuminance"}


def __getattr__(name):
    if name in _POINT_MEASURES:
        from .integrators import illuminance as point_measures

        return getattr(point_measures, _POINT_MEASURES[name])
    if name == "unlit_points":  # sensor points outside the lit geometry (core/integrators/unlit.py)
        from .integrators.unlit import unlit_points

        return unlit_points
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
