"""Light settings: ``bpy.types.Light.spectral_gi`` — photometric unit, emission spectrum and
photometric profile (IES / EULUMDAT) of point and spot lights.

By default a light keeps Blender's power and colour, read as Cycles reads them (1
Blender W = 683 lm). A designer can instead give the data-sheet numbers: "1200 lm,
3000 K" is unit Lumens, value 1200, spectrum Blackbody, temperature 3000 K.
"""
import bpy
from bpy.props import EnumProperty, FloatProperty, StringProperty

from .enums import numbered_items

UNITS = (
    ("BLENDER", "Blender Power",
     "Blender's Power (W) or a sun's Strength (W/m²) and the light's colour, as Cycles reads them, "
     "at 683 lm per Blender watt"),
    ("LUMEN", "Lumens", "Luminous flux in lm (a spot: the flux inside its cone)"),
    ("CANDELA", "Candela", "Luminous intensity in cd (a spot: on its axis; an area light: along its normal)"),
    ("LUX", "Lux", "Illuminance in lx on a surface facing the sun"),
    ("NIT", "cd/m²", "Luminance of the area light's surface in cd/m²"),
)
# unit enum → core.LIGHT_UNITS names
UNIT_NAMES = {"BLENDER": "blender_W", "LUMEN": "lm", "CANDELA": "cd", "LUX": "lux", "NIT": "cd/m2"}
UNIT_SYMBOLS = {"LUMEN": "lm", "CANDELA": "cd", "LUX": "lx", "NIT": "cd/m²"}

SPECTRA = (
    ("RGB", "RGB Colour", "The light's colour (and Blender's temperature, if used), turned into a smooth spectrum"),
    ("BLACKBODY", "Blackbody", "Planck's law at the given temperature (incandescent, warm-white approximations)"),
    ("ILLUMINANT", "CIE Illuminant", "A CIE standard illuminant (A, D50, D65, FL1–FL12, …)"),
    ("LED", "CIE LED", "A CIE LED illuminant series (LED-B1 … LED-V2)"),
    ("FILE", "File", "A tabulated emission spectrum file: two columns, wavelength (nm) and relative power, "
                     "covering 380–780 nm (the shape only: the brightness comes from the unit)"),
)
SOURCE_NAMES = {"RGB": "rgb", "BLACKBODY": "blackbody", "ILLUMINANT": "illuminant", "LED": "led", "FILE": "file"}

_NAMES = {}

# Photometric profile (IES / EULUMDAT) of a point or spot light: none, a file, or a shipped sample.
PROFILE_BRIGHTNESS = (
    ("FILE", "Profile's Candela", "The intensities the file gives (absolute photometry); the unit and value "
     "above are not used"),
    ("UNIT", "Light's Unit", "Scale the profile's shape by the light's unit: lumens = the total output "
     "(a spot: inside its cone), candela = the peak intensity, Blender Power = the same output as without "
     "the profile"),
)


def _profile_presets():
    try:
        from ...core import photometric_presets

        return sorted(photometric_presets())
    except Exception:  # core unavailable: only None and File
        return []


# built once: Blender keeps references to the item strings of an enum. None and File are 0 and 1,
# the shipped samples are numbered by identifier (enums.py), so adding a sample keeps saved choices.
PROFILE_ITEMS = tuple(numbered_items(
    [("NONE", "None", "No profile: the light emits equally in every direction (a spot: in its cone)"),
     ("FILE", "File", "An IES LM-63 (.ies) or EULUMDAT (.ldt) file")]
    + [(f"PRESET_{n}", n.replace("_", " ").title(), f"Sample profile presets/ies/{n}") for n in _profile_presets()],
    fixed={"NONE": 0, "FILE": 1}))


def _names(source):
    if source not in _NAMES:
        try:
            from ...core import light_spectrum_names

            _NAMES[source] = list(light_spectrum_names(source))
        except Exception:  # core unavailable: no suggestions, the export reports a bad name
            return []
    return _NAMES[source]


def _search(source):
    def search(self, context, edit_text):
        text = (edit_text or "").lower()
        return [n for n in _names(source) if text in n.lower()]
    return search


def _tag(self, context):
    """Custom properties do not tag their ID by themselves: re-evaluate the light so renders see the change."""
    self.id_data.update_tag()


class SpectralGILightSettings(bpy.types.PropertyGroup):
    """How the Spectral GI renderer reads this light's brightness and colour."""

    unit: EnumProperty(update=_tag, name="Unit", items=UNITS, default="BLENDER",
                       description="What the light's brightness is given in")
    value: FloatProperty(
        update=_tag,
        name="Value", default=1000.0, min=0.0, soft_max=1e6, precision=2,
        description="The light's brightness in the chosen unit (lm, cd, lx or cd/m²)")
    spectrum: EnumProperty(update=_tag, name="Spectrum", items=SPECTRA, default="RGB",
                           description="Where the light's emission spectrum comes from")
    temperature: FloatProperty(
        update=_tag,
        name="Temperature", default=3000.0, min=100.0, max=100000.0, soft_min=1000.0, soft_max=20000.0,
        description="Blackbody temperature in kelvin (K)")
    illuminant: StringProperty(update=_tag, name="Illuminant", default="D65", search=_search("illuminant"),
                               description="Name of a CIE standard illuminant (A, D65, FL11, …)")
    led: StringProperty(update=_tag, name="LED", default="LED-B3", search=_search("led"),
                        description="Name of a CIE LED illuminant (LED-B1 … LED-V2)")
    spectrum_file: StringProperty(
        update=_tag, name="Spectrum File", default="", subtype="FILE_PATH",
        description="Tabulated emission spectrum: CSV or whitespace-separated wavelength (nm), relative power "
                    "lines, optional header; a bad file is reported and the light's RGB colour used")
    profile: EnumProperty(update=_tag, name="Profile", items=PROFILE_ITEMS, default="NONE",
                          description="Photometric (goniometric) profile of a point or spot light: its "
                                      "luminous intensity by direction, C0 towards the light's local −Y, "
                                      "nadir along its local −Z (as Cycles' IES texture)")
    profile_path: StringProperty(update=_tag, name="Profile File", subtype="FILE_PATH", default="",
                                 description="An IES LM-63 (.ies) or EULUMDAT (.ldt) file")
    profile_brightness: EnumProperty(update=_tag, name="Profile Brightness", items=PROFILE_BRIGHTNESS,
                                     default="FILE", description="What sets the profiled light's brightness")


classes = (SpectralGILightSettings,)


def register_properties():
    bpy.types.Light.spectral_gi = bpy.props.PointerProperty(
        type=SpectralGILightSettings, name="Spectral GI",
        description="Photometric unit and emission spectrum of the light for the Spectral GI renderer")


def unregister_properties():
    if hasattr(bpy.types.Light, "spectral_gi"):
        del bpy.types.Light.spectral_gi
