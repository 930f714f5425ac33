"""Scene settings (``bpy.types.Scene.spectral_gi``) and render passes (``bpy.types.ViewLayer.spectral_gi``)."""
import bpy
from bpy.props import BoolProperty, EnumProperty, FloatProperty, IntProperty, StringProperty

SAMPLERS = (
    ("INDEPENDENT", "Independent", "Independent uniform random numbers per dimension (unbiased, slowest to converge)"),
    ("HALTON", "Halton", "Scrambled Halton sequence (quasi-Monte Carlo): less noise at the same samples"),
    ("HAMMERSLEY", "Hammersley", "Scrambled Hammersley points (quasi-Monte Carlo) for a fixed sample count"),
    ("STRATIFIED", "Stratified", "Stratified pixel positions (shifted Sobol), random numbers elsewhere: "
     "cheap, and edges of bright lights converge much faster"),
)
FILTERS = (
    ("BLACKMAN_HARRIS", "Blackman-Harris", "Blackman-Harris pixel filter (Cycles' default)"),
    ("GAUSSIAN", "Gaussian", "Gaussian pixel filter"),
    ("BOX", "Box", "Box pixel filter: each sample counts only in its own pixel"),
)
WHITE_BALANCE = (
    ("NONE", "None", "RGB is the spectrum's colour seen under a D65-adapted eye (Blender's convention)"),
    ("LIGHT", "Brightest Light",
     "Adapt the RGB output (Combined pass) from the brightest light's white to D65 (Bradford), as a camera's "
     "white balance would. XYZ, Luminance and Lab are never adapted"),
)

COLOUR_SPACES = (
    ("REC709", "Linear Rec.709", "Blender's scene-linear space (sRGB primaries, D65): the Combined pass"),
    ("ACESCG", "ACEScg", "ACES AP1 primaries, linear, ACES white (D65 adapted with Bradford): written to the "
                         "Colour Output pass and to EXR files; Combined stays Rec.709 for Blender's display"),
    ("XYZ", "CIE XYZ", "The film's CIE XYZ (of the chosen observer), unchanged: written to the Colour Output "
                       "pass and to EXR files; Combined stays Rec.709 for Blender's display"),
)
OBSERVERS = (
    ("CIE1931", "CIE 1931 2°", "CIE 1931 2° standard observer (the colorimetric default)"),
    ("CIE1964", "CIE 1964 10°", "CIE 1964 10° standard observer for the film's XYZ and colours; luminance, "
                                "lux and the noise target still use V(λ) (the 1931 ȳ)"),
)
COLOUR_OUTPUT_PASS = "Colour Output"  # render pass holding the image in an output space other than Rec.709

# Layout of the settings the add-on stores in a .blend file; addon/versioning.py brings older files up to it.
SCHEMA_VERSION = 2


def _denoise_update(settings, context):
    from ..denoise import sync_compositor

    scene = settings.id_data
    sync_compositor(scene)


class SpectralGISceneSettings(bpy.types.PropertyGroup):
    """Render settings of the Spectral GI path tracer, stored in the scene."""

    samples: IntProperty(
        name="Samples",
        description="Samples per pixel (spp, a count): camera paths traced through every pixel. "
                    "Noise falls as 1/√samples",
        default=64, min=1, soft_max=4096, max=1 << 24,
    )
    viewport_samples: IntProperty(
        name="Viewport Samples",
        description="Samples per pixel (a count) the Rendered viewport refines to before it stops; "
                    "the first passes are coarse (one sample on blocks of 4×4, then 2×2 pixels)",
        default=256, min=1, soft_max=4096, max=1 << 24,
    )
    use_denoise: BoolProperty(
        name="Denoise",
        description="Denoise the Combined pass of final renders with OpenImageDenoise (Blender's compositor "
                    "Denoise node, guided by the Albedo and Normal passes). Luminance, XYZ, illuminance and "
                    "the colour-science passes are never denoised: they stay measurements",
        default=False, update=lambda self, context: _denoise_update(self, context),
    )
    max_bounces: IntProperty(
        name="Max Bounces",
        description="Maximum number of scattering events on a path (a count). Russian roulette "
                    "ends most paths earlier without bias; this is only a hard limit",
        default=64, min=0, max=1024,
    )
    seed: IntProperty(
        name="Seed",
        description="Random seed (an integer, no unit): the same seed, scene and samples give the "
                    "same image, whatever the number of threads",
        default=0, min=0, max=2**31 - 1,
    )
    use_animated_seed: BoolProperty(
        name="Animate Seed",
        description="Add the frame number to the seed, so the noise differs from frame to frame",
        default=False,
    )
    threads: IntProperty(
        name="Threads",
        description="CPU threads used for rendering (a count); 0 uses all cores",
        default=0, min=0, max=1024,
    )
    sampler: EnumProperty(
        name="Sampler", items=SAMPLERS, default="STRATIFIED",
        description="How the random numbers of the samples are drawn (no unit)",
    )
    pixel_filter: EnumProperty(
        name="Pixel Filter", items=FILTERS, default="BLACKMAN_HARRIS",
        description="Reconstruction filter spreading every sample over nearby pixels",
    )
    filter_width: FloatProperty(
        name="Filter Width",
        description="Width of the pixel filter in pixels, as Cycles reads it (default 1.5 px)",
        default=1.5, min=0.01, soft_max=10.0, max=32.0, subtype="PIXEL",
    )
    time_limit: FloatProperty(
        name="Time Limit",
        description="Stop after this many seconds of rendering (0: no limit); the image keeps the "
                    "samples done so far",
        default=0.0, min=0.0, soft_max=3600.0, subtype="TIME_ABSOLUTE", unit="TIME_ABSOLUTE",
    )
    noise_target: FloatProperty(
        name="Noise Target",
        description="Adaptive sampling: after Cycles' minimum samples, a pixel stops receiving samples once "
                    "its relative standard error of luminance is below this fraction (0: off; 0.01 = 1 %)",
        default=0.0, min=0.0, max=1.0, soft_max=0.1, precision=4,
    )
    white_balance: EnumProperty(
        name="White Balance", items=WHITE_BALANCE, default="NONE",
        description="White balance of the Combined (RGB) pass",
    )
    colour_space: EnumProperty(
        name="Colour Output", items=COLOUR_SPACES, default="REC709",
        description="Colour space of the rendered image: Combined is always linear Rec.709 (what Blender "
                    "displays); ACEScg or XYZ add the Colour Output pass in that space",
    )
    observer: EnumProperty(
        name="Observer", items=OBSERVERS, default="CIE1931",
        description="CIE standard observer whose colour-matching functions give the film's XYZ",
    )
    fourier_order: IntProperty(
        name="Fourier Order",
        description="Fourier (trigonometric-moment) coefficients per spectrum (a count) when colours are "
                    "uplifted and spectra fitted: more follow measured spectra more closely, at some memory "
                    "and speed cost",
        default=12, min=3, max=16,
    )
    hair_sides: IntProperty(
        name="Hair Sides",
        description="Faces around each round hair strand (particle hair, Curves objects) when it is "
                    "tessellated into a tube (a count): more follow the round silhouette more closely, at "
                    "two triangles per face and segment of memory and build time",
        default=6, min=3, max=64,
    )
    use_sensors: BoolProperty(
        name="Sensors",
        description="After the image, render the illuminance (lux) on the objects marked as Illuminance "
                    "Sensor (Object properties) into an Illuminance pass: a second render of the same "
                    "samples, with the sensors' first hits measured by a white Lambertian surface",
        default=False,
    )

    schema_version: IntProperty(
        name="Settings Version",
        description="Layout version of the Spectral GI settings stored in this file (a count): written when the "
                    "file is saved, used to update files saved by an older version of the add-on",
        default=SCHEMA_VERSION, min=0, options={"HIDDEN"},
    )

    # ------------------------------------------------------------------ Cycles comparison (last result)
    compare_output_dir: StringProperty(
        name="Comparison Folder",
        description="Folder for the comparison's report (JSON) and images (EXR); empty: beside the "
                    ".blend file, or the temporary folder for an unsaved file",
        default="", subtype="DIR_PATH",
    )
    compare_valid: BoolProperty(name="Comparison Available", default=False,
                                description="True once a Cycles comparison has run in this session")
    compare_luminance_ratio: FloatProperty(
        name="Luminance Ratio", default=0.0, precision=4,
        description="Mean luminance of Spectral GI over Cycles' (no unit; 1 = equal)")
    compare_relative_rmse: FloatProperty(
        name="Relative RMSE", default=0.0, precision=4,
        description="Root-mean-square luminance difference over Cycles' mean luminance (no unit)")
    compare_delta_e_mean: FloatProperty(
        name="Mean ΔE00", default=0.0, precision=3,
        description="Mean CIEDE2000 colour difference per pixel (ΔE00 units; about 1 is just noticeable)")
    compare_delta_e_p95: FloatProperty(
        name="95th Percentile ΔE00", default=0.0, precision=3,
        description="95th percentile of the per-pixel CIEDE2000 difference (ΔE00 units)")
    compare_report_path: StringProperty(
        name="Report", default="", subtype="FILE_PATH",
        description="JSON file of the last comparison")


PASSES = (
    # property, pass name, channels, channel ids, type, description
    ("use_pass_xyz", "XYZ", 3, "XYZ", "COLOR",
     "CIE 1931 XYZ on Blender's scale (Y = 1 is 683 cd/m²)"),
    ("use_pass_luminance", "Luminance", 1, "Y", "VALUE", "Absolute luminance in cd/m²"),
    ("use_pass_lab", "Lab", 3, "LAB", "COLOR",
     "CIE L*a*b* against a D65 white of 683 cd/m² (Blender's RGB 1 is L* = 100)"),
    ("use_pass_variance", "Variance", 1, "V", "VALUE",
     "Variance of each pixel's mean luminance, (cd/m²)²: the noise left in the Luminance pass"),
    ("use_pass_albedo", "Albedo", 3, "RGB", "COLOR",
     "Linear Rec.709 reflectance of the first surface hit (no unit, 0 to 1)"),
    ("use_pass_normal", "Normal", 3, "XYZ", "VECTOR", "World-space shading normal of the first surface hit"),
    ("use_pass_depth", "Depth", 1, "Z", "VALUE", "Distance along the camera ray to the first hit, in metres"),
)


def _pass_props():
    ns = {}
    for prop, name, _n, _chan, _type, desc in PASSES:
        ns[prop] = BoolProperty(name=name, description=desc + " (Spectral GI pass)",
                                default=prop in ("use_pass_luminance",))
    return ns


SpectralGIViewLayerSettings = type(
    "SpectralGIViewLayerSettings", (bpy.types.PropertyGroup,),
    {"__doc__": "Render passes of the Spectral GI engine, per view layer.",
     "__annotations__": _pass_props()})


classes = (SpectralGISceneSettings, SpectralGIViewLayerSettings)


SENSOR_PROPERTY = "spectral_gi_sensor"  # bpy.types.Object: an illuminance sensor


def register_properties():
    setattr(bpy.types.Object, SENSOR_PROPERTY, BoolProperty(
        name="Illuminance Sensor",
        description="Spectral GI measures the illuminance (lux) on this object's surfaces seen by the camera "
                    "(Render properties > Sensors): the Illuminance pass and the Em, Emin, Emax, U0 report",
        default=False))
    bpy.types.Scene.spectral_gi = bpy.props.PointerProperty(
        type=SpectralGISceneSettings, name="Spectral GI",
        description="Settings of the Spectral GI renderer (samples, bounces, seed, threads)")
    bpy.types.ViewLayer.spectral_gi = bpy.props.PointerProperty(
        type=SpectralGIViewLayerSettings, name="Spectral GI",
        description="Render passes of the Spectral GI renderer")


def unregister_properties():
    if hasattr(bpy.types.ViewLayer, "spectral_gi"):
        del bpy.types.ViewLayer.spectral_gi
    if hasattr(bpy.types.Scene, "spectral_gi"):
        del bpy.types.Scene.spectral_gi
    if hasattr(bpy.types.Object, SENSOR_PROPERTY):
        delattr(bpy.types.Object, SENSOR_PROPERTY)
