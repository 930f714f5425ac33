"""spectral_gi.core: the renderer. Never imports bpy.

The add-on and the command line use only the names in ``__all__``.
"""
from . import constants
from .film import Developed, Film, develop
from .io.exr import read_channels as read_exr
from .io.exr import write_render as write_exr
from .io.png import write_png
from .presets import load_cornell_box_data
from .renderer import RenderStats, kernels_compiled, render
from .scene import (Camera, Light, Material, Mesh, RenderSettings, Scene, SceneError, SpectrumTable, World,
                    validate)
from .scene import load as load_scene
from .scene import save as save_scene
from .scenes import cornell_box
from .spectra.uplift import (emission_from_rgb, emission_from_samples, emission_to_rgb, reflectance_from_rgb,
                             reflectance_from_samples, reflectance_to_rgb)
from .units import EMITTER_UNITS, area_light_luminance, emission_luminance, emitter_luminance

__all__ = [
    "constants",
    "Scene", "Mesh", "Material", "Light", "Camera", "World", "RenderSettings", "SpectrumTable",
    "SceneError", "validate", "load_scene", "save_scene",
    "reflectance_from_rgb", "emission_from_rgb", "reflectance_from_samples", "emission_from_samples",
    "reflectance_to_rgb", "emission_to_rgb",
    "emission_luminance", "area_light_luminance", "emitter_luminance", "EMITTER_UNITS",
    "render", "RenderStats", "kernels_compiled", "Film", "Developed", "develop",
    "write_exr", "read_exr", "write_png",
    "cornell_box", "load_cornell_box_data",
]
