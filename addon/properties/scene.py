"""Scene settings: ``bpy.types.Scene.spectral_gi``."""
import bpy
from bpy.props import IntProperty


class SpectralGISceneSettings(bpy.types.PropertyGroup):
    """Render settings of the Spectral GI path tracer, stored in the scene."""

    samples: IntProperty(
        name="Samples",
        description="Samples per pixel (spp, a count): camera paths traced through every pixel. "
                    "Noise falls as 1/√samples",
        default=64, min=1, soft_max=4096, max=1 << 24,
    )
    max_bounces: IntProperty(
        name="Max Bounces",
        description="Maximum number of scattering events on a path (a count). Russian roulette "
                    "ends most paths earlier without bias; this is only a hard limit",
        default=16, min=1, max=1024,
    )
    seed: IntProperty(
        name="Seed",
        description="Random seed (an integer, no unit): the same seed, scene and samples give the "
                    "same image, whatever the number of threads",
        default=0, min=0, max=2**31 - 1,
    )
    threads: IntProperty(
        name="Threads",
        description="CPU threads used for rendering (a count); 0 uses all cores",
        default=0, min=0, max=1024,
    )


classes = (SpectralGISceneSettings,)


def register_properties():
    bpy.types.Scene.spectral_gi = bpy.props.PointerProperty(
        type=SpectralGISceneSettings, name="Spectral GI",
        description="Settings of the Spectral GI renderer (samples, bounces, seed, threads)")


def unregister_properties():
    if hasattr(bpy.types.Scene, "spectral_gi"):
        del bpy.types.Scene.spectral_gi
