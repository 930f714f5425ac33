"""Calculation surfaces: ``bpy.types.Object.spectral_gi_lux`` (settings and the last result, kept in the .blend)."""
import bpy
from bpy.props import BoolProperty, EnumProperty, FloatProperty, IntProperty, PointerProperty, StringProperty

KINDS = (
    ("GRID", "Grid", "A regular grid over the planar mesh (EN 12464-1 spacing), shown as a new grid object"),
    ("VERTICES", "Vertices", "One point at every mesh vertex, coloured per vertex"),
    ("FACES", "Faces", "One point at every triangle's centre, coloured per face"),
)
SPACING = (
    ("AUTO", "EN 12464-1", "Spacing p = 0.2 · 5^log10(d) m from the area's size d (EN 12464-1:2021)"),
    ("USER", "User", "The spacing given below, in metres"),
)


class SpectralGILuxSurface(bpy.types.PropertyGroup):
    """A mesh marked as a calculation surface, and the statistics of its last calculation."""

    enabled: BoolProperty(name="Calculation Surface", default=False,
                          description="Calculate the illuminance (lx) on this mesh (on/off, no unit)")
    kind: EnumProperty(name="Points", items=KINDS, default="GRID",
                       description="Where the calculation points lie on the mesh (no unit)")
    spacing_mode: EnumProperty(name="Spacing", items=SPACING, default="AUTO",
                               description="How the grid spacing (m) is chosen")
    spacing: FloatProperty(name="Spacing", default=0.5, min=0.01, soft_max=10.0, unit="LENGTH",
                           description="Grid spacing in metres (User spacing)")
    band: FloatProperty(name="Band", default=0.0, min=0.0, soft_max=5.0, unit="LENGTH",
                        description="Strip along the outline left out of the grid, in metres")
    maintenance_factor: FloatProperty(name="Maintenance Factor", default=1.0, min=0.01, max=1.0,
                                      description="CIE 97 maintenance factor (no unit, 0 to 1): reported values "
                                                  "are MF × initial illuminance")
    samples: IntProperty(name="Samples", default=64, min=1, soft_max=4096,
                         description="Samples per point (a count): the most taken per point")
    rel_error: FloatProperty(name="Relative Error", default=0.0, min=0.0, max=1.0,
                             description="Stop a point's sampling at this relative standard error "
                                         "(a fraction, 0: off, always take all samples)")
    workplane: BoolProperty(name="Work Plane", default=False,
                            description="Report this grid as a work plane (EN 12464-1); set by Add Work Plane "
                                        "(on/off, no unit)")
    # the false-colour overlay (viewport colours, plan, report page)
    scale_auto: BoolProperty(name="Automatic Range", default=True,
                             description="Scale the false colours from the lowest to the highest value of the "
                                         "result (on/off, no unit); off: the fixed range below")
    scale_fixed_min: FloatProperty(name="Range Minimum", default=0.0, min=0.0, soft_max=10000.0,
                                   description="Lowest value of a fixed false-colour range, in lx (above 0 for a "
                                               "logarithmic scale)")
    scale_fixed_max: FloatProperty(name="Range Maximum", default=1000.0, min=0.0, soft_max=10000.0,
                                   description="Highest value of a fixed false-colour range, in lx")
    scale_log: BoolProperty(name="Logarithmic", default=False,
                            description="Space the false colours logarithmically in lx (on/off, no unit)")
    scale_steps: IntProperty(name="Steps", default=8, min=0, max=64,
                             description="Number of colour bands of the false-colour scale (a count; 0: "
                                         "continuous)")
    unlit_points: IntProperty(name="Points Outside", default=0,
                              description="Points of the last result that look outside the lit geometry: read "
                                          "0 lx with no light reaching them, or inside a solid (a count)")
    # the last result
    valid: BoolProperty(name="Result Available", default=False,
                        description="True once the illuminance was calculated (no unit)")
    mean: FloatProperty(name="Ē", default=0.0, description="Area-weighted mean maintained illuminance in lx")
    minimum: FloatProperty(name="Emin", default=0.0, description="Smallest maintained illuminance in lx")
    maximum: FloatProperty(name="Emax", default=0.0, description="Largest maintained illuminance in lx")
    u0: FloatProperty(name="U0", default=0.0, description="Uniformity Emin / Ē (no unit; 0 when Ē = 0)")
    ud: FloatProperty(name="Ud", default=0.0, description="Uniformity Emin / Emax (no unit; 0 when Emax = 0)")
    n_points: IntProperty(name="Points", default=0, description="Number of calculation points (a count)")
    grid_cols: IntProperty(name="Grid Columns", default=0, description="Grid points along u (a count; 0: no grid)")
    grid_rows: IntProperty(name="Grid Rows", default=0, description="Grid points along v (a count; 0: no grid)")
    area: FloatProperty(name="Area", default=0.0, description="Area the points stand for, in m²")
    spacing_u: FloatProperty(name="Spacing U", default=0.0, description="Grid spacing used along u, in metres")
    spacing_v: FloatProperty(name="Spacing V", default=0.0, description="Grid spacing used along v, in metres")
    band_used: FloatProperty(name="Band Used", default=0.0, description="Band used, in metres")
    mf_used: FloatProperty(name="MF Used", default=1.0, description="Maintenance factor used (no unit)")
    samples_used: IntProperty(name="Samples Used", default=0, description="Most samples taken at a point (a count)")
    max_rel_error: FloatProperty(name="Max Relative Error", default=0.0,
                                 description="Largest relative standard error over the points (a fraction)")
    mean_rel_error: FloatProperty(name="Mean Relative Error", default=0.0,
                                  description="Mean relative standard error over the points (a fraction)")
    scale_min: FloatProperty(name="Scale Minimum", default=0.0,
                             description="Lowest value of the false-colour scale, in lx")
    scale_max: FloatProperty(name="Scale Maximum", default=0.0,
                             description="Highest value of the false-colour scale, in lx")
    plan_image: PointerProperty(type=bpy.types.Image, name="Plan Image",
                                description="The false-colour plan of the last result (a packed image)")
    report_image: PointerProperty(type=bpy.types.Image, name="Report Image",
                                  description="The one-page report of the last export (a packed image)")
    result_object: StringProperty(name="Result Object", default="",
                                  description="Name of the object carrying the false colours (no unit)")


METHODS = [("PATH", "Path Tracing", "The path tracer at every calculation point (every material)"),
           ("RADIOSITY", "Radiosity", "A radiosity solution of the whole scene (diffuse only: other materials "
                                      "are replaced by their diffuse albedo, with a warning); the points gather "
                                      "direct light exactly and the solution for the rest, and every surface gets a "
                                      "false-colour overlay")]
QUANTITIES = [("ILLUMINANCE", "Illuminance", "Light arriving at each surface, in lx"),
              ("LUMINANCE", "Luminance", "Light leaving each surface towards the eye, in cd/m²")]


class SpectralGIRadiosity(bpy.types.PropertyGroup):
    """The scene's radiosity settings and its overlay on every surface (Scene.spectral_gi_radiosity)."""

    max_edge: FloatProperty(name="Patch Size", default=0.0, min=0.0, soft_max=5.0, unit="LENGTH",
                            description="Longest edge of a radiosity patch, in metres (0: automatic, about 2500 "
                                        "patches)")
    quantity: EnumProperty(name="Overlay", items=QUANTITIES, default="ILLUMINANCE",
                           description="What the radiosity overlay on every surface shows")
    overlay: BoolProperty(name="Show Overlay", default=True,
                          description="Show the radiosity result as false colours on every surface (on/off)")
    patches: IntProperty(name="Patches", default=0, description="Patches of the last radiosity solve (a count)")
    objects: StringProperty(name="Overlay Objects", default="",
                            description="Names of the objects carrying the radiosity overlay, one per line")
    warning: StringProperty(name="Warning", default="",
                            description="What the last radiosity solve approximated (text)")


classes = (SpectralGILuxSurface, SpectralGIRadiosity)
PROPERTY = "spectral_gi_lux"


def register_properties():
    setattr(bpy.types.Object, PROPERTY, bpy.props.PointerProperty(
        type=SpectralGILuxSurface, name="Lighting Analysis",
        description="Calculation surface settings and last result (lx)"))
    bpy.types.Scene.spectral_gi_workplane_height = FloatProperty(
        name="Work Plane Height", default=0.75, min=0.0, soft_max=3.0, unit="LENGTH",
        description="Height of a new work plane above the floor, in metres")
    bpy.types.Scene.spectral_gi_use_band = BoolProperty(
        name="Wall Band", default=True,
        description="Leave a band along the walls out of a new work plane (EN 12464-1; on/off, no unit)")
    bpy.types.Scene.spectral_gi_workplane_band = FloatProperty(
        name="Band", default=0.5, min=0.0, soft_max=2.0, unit="LENGTH",
        description="Width of the band along the walls left out of a new work plane, in metres")
    bpy.types.Scene.spectral_gi_lux_method = EnumProperty(
        name="Method", items=METHODS, default="PATH",
        description="How Calculate Illuminance and Lighting Report compute the illuminance")
    bpy.types.Scene.spectral_gi_radiosity = bpy.props.PointerProperty(
        type=SpectralGIRadiosity, name="Radiosity", description="Radiosity settings and overlay")
    # the overlay's false-colour range: the same settings as a calculation surface's
    bpy.types.Scene.spectral_gi_radiosity_scale = bpy.props.PointerProperty(
        type=SpectralGILuxSurface, name="Radiosity Overlay Range",
        description="False-colour range of the radiosity overlay (lx, or cd/m² for luminance)")
    bpy.types.Scene.spectral_gi_report_dir = StringProperty(
        name="Report Folder", default="", subtype="DIR_PATH",
        description="Folder for the lux reports (a path; empty: beside the .blend file, or the temporary folder)")


def unregister_properties():
    for owner, name in ((bpy.types.Scene, "spectral_gi_lux_method"), (bpy.types.Scene, "spectral_gi_radiosity"),
                        (bpy.types.Scene, "spectral_gi_radiosity_scale"), (bpy.types.Scene, "spectral_gi_report_dir"),
                        (bpy.types.Scene, "spectral_gi_workplane_height"), (bpy.types.Scene, "spectral_gi_use_band"),
                        (bpy.types.Scene, "spectral_gi_workplane_band"),
                        (bpy.types.Object, PROPERTY)):
        if hasattr(owner, name):
            delattr(owner, name)
