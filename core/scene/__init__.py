"""The scene contract: what Blender's exporter and the command line both hand to the renderer.

A :class:`Scene` is a versioned set of typed, contiguous arrays plus a few small
records. :func:`validate` checks every field and raises :class:`SceneError` with a
message naming the field. :func:`save` / :func:`load` write and read the portable
format described in ``docs/reference/scene-format.md``: one JSON file for the records and one
``.npz`` beside it for the arrays (never pickle).

Units: lengths in metres, world space with Blender's axes (+Z up). Spectra are
Fourier-basis (trigonometric-moment) coefficients, see :mod:`.spectra.moments`.
Emitters carry the *shape* of their spectrum and one photometric number, their
luminance in cd/m², as pbrt-v4 does: the spectrum sets the colour, the number the
brightness.
"""
from __future__ import annotations

import dataclasses
import hashlib
import io
import json
import math
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from .. import constants as C
from ..io.atomic import atomic_paths, fsync_write
from ..io.npz import NpzError, NpzReader
from .checks import SceneError
from .checks import MAX_COORDINATE, MAX_PHOTOMETRIC, MIN_LENGTH
from .checks import check_array as _check_array
from .checks import check_bool as _check_bool
from .checks import check_number as _check_number
from .checks import check_str as _check_str
from .checks import check_vec3 as _check_vec3
from .checks import fail as _fail
from ..lux.grids import CalculationSurface
from ..lux.points import LuxError
from .textures import Texture
from ..shading.program import Program, check_scene as _check_programs
from .textures import check as _check_textures
from ..spectra import moments
from ..film import COLOUR_SPACES, OBSERVERS


@dataclass
class Mesh:
    """A triangle mesh in world space."""

    name: str
    positions: np.ndarray  # float32 (N, 3), metres
    indices: np.ndarray  # int32 (T, 3), into positions
    material: np.ndarray  # int32 (T,), into Scene.materials
    normals: np.ndarray | None = None  # float32 (N, 3) shading normals, or None (flat)
    uvs: np.ndarray | None = None  # float32 (N, 2), or None
    corner_uvs: np.ndarray | None = None  # float32 (T*3, 2): UVs per triangle corner (wins over uvs), or None
    # corner attributes shader programs read (core/shading/program.py): name -> float32 (T*3, 3)
    attributes: dict | None = None
    sensor: bool = False  # an illuminance sensor (core.sensors.render_illuminance measures on it)
    holdout: bool = False  # camera rays that reach it first see a hole (alpha 0); other rays its material
    # ray visibility (Cycles' Object > Visibility > Ray Visibility): False, rays of that kind pass through it
    # (a hidden emitter also gives no light to them; see docs/reference/scene-format.md)
    visible_camera: bool = True
    visible_diffuse: bool = True
    visible_glossy: bool = True
    visible_transmission: bool = True
    visible_volume: bool = True  # rays scattered in a medium
    visible_shadow: bool = True  # False: casts no shadow
    # light and shadow linking of an emissive mesh (as ``Light.receivers`` / ``Light.blockers``)
    receivers: list | None = None
    blockers: list | None = None


VISIBILITY_FLAGS = ("visible_camera", "visible_diffuse", "visible_glossy", "visible_transmission", "visible_volume",
                    "visible_shadow")
MESH_FLAGS = ("sensor", "holdout") + VISIBILITY_FLAGS
LINK_FIELDS = ("receivers", "blockers")


@dataclass
class SpectrumTable:
    """All spectra of a scene as Fourier-basis coefficients, one row per spectrum."""

    coeffs: np.ndarray  # float64 (S, M)
    kind: np.ndarray  # int32 (S,): SPECTRUM_BOUNDED or SPECTRUM_UNBOUNDED
    names: list[str] = field(default_factory=list)

    @classmethod
    def empty(cls, n_coeffs=C.N_COEFFS_DEFAULT):
        return cls(np.zeros((0, n_coeffs)), np.zeros(0, np.int32), [])

    def add(self, name, coeffs, kind):
        coeffs = np.asarray(coeffs, dtype=np.float64).reshape(1, -1)
        if self.coeffs.shape[0] == 0:
            self.coeffs = np.zeros((0, coeffs.shape[1]))
        self.coeffs = np.concatenate([self.coeffs, coeffs])
        self.kind = np.concatenate([self.kind, np.array([kind], np.int32)])
        self.names.append(str(name))
        return len(self.names) - 1

    def __len__(self):
        return len(self.names)


@dataclass
class IORTable:
    """Refractive-index curves on the renderer's 1 nm grid (η or κ of glasses and metals).

    Not light or reflectance spectra, so not stored as moments: a dispersion curve must
    be exact to a few 1e-4 for the colours of dispersion to be right.
    """

    values: np.ndarray  # float32 (T, N_LAMBDA), 360..830 nm in 1 nm steps
    names: list[str] = field(default_factory=list)

    @classmethod
    def empty(cls):
        return cls(np.zeros((0, C.N_LAMBDA), np.float32), [])

    def add(self, name, values):
        v = np.asarray(values, dtype=np.float32).reshape(1, C.N_LAMBDA)
        self.values = np.concatenate([self.values, v])
        self.names.append(str(name))
        return len(self.names) - 1

    def __len__(self):
        return len(self.names)


@dataclass
class Material:
    """A surface: a BSDF model (``model``, a MAT_* tag, with its parameter row ``params``,
    see core/bsdfs/params.py), its spectral inputs and an optional emission.

    MAT_MIX / MAT_ADD combine two other materials: params[0] is the mix weight of the
    first (MIX; ``mix_program`` gives it per shading point instead), params[1] and
    params[2] the indices of the two materials.
    """

    name: str
    model: int = C.MAT_LAMBERT
    reflectance: int = -1  # index of a bounded spectrum (the model's ``ra``); -1 = black
    emission: int = -1  # index of an unbounded spectrum (shape only); -1 = none
    emission_luminance: float = 0.0  # cd/m² of the emitted radiance
    two_sided: bool = True  # emits from both sides (Blender's Emission shader); False: front only
    params: list | None = None  # float64[16] row of the model; None: the model's defaults
    specular: int = -1  # index of a bounded spectrum (the model's ``rb``); -1 = white
    ior: float = 1.5  # constant relative index when ``eta_table`` is -1
    eta_table: int = -1  # index into Scene.ior_tables for η(λ); -1 = constant ``ior``
    kappa_table: int = -1  # index into Scene.ior_tables for κ(λ); -1 = 0
    interior: int = -1  # index into Scene.media of the medium behind the surface (its back side); -1 = none
    # image textures (core/textures.py): indices into Scene.textures, -1 = none
    base_colour_texture: int = -1  # replaces ``reflectance`` (the model's ra), uplifted per texel
    roughness_texture: int = -1  # one channel: Blender roughness r, GGX α = r² (GGX and plastic models)
    normal_texture: int = -1  # tangent-space normal map (three channels, OpenGL +Y)
    normal_strength: float = 1.0  # the Normal Map node's strength
    # shader programs (core/shading/program.py): indices into Scene.programs, -1 = none
    base_colour_program: int = -1  # rgb → ρa (uplifted per evaluation); wins over base_colour_texture
    roughness_program: int = -1  # x: Blender roughness r, GGX α = r² (GGX and plastic models)
    emission_program: int = -1  # rgb radiance (Blender colour × strength) added to the emission
    normal_program: int = -1  # the shading normal (world space, Bump / Normal Map nodes)
    mix_program: int = -1  # MAT_MIX only: x clamped to [0, 1] is the first's weight in place of params[0]
    holdout: bool = False  # Cycles' Holdout shader: a hole (alpha 0) for camera rays, black and absorbing for others


@dataclass
class Medium:
    """A homogeneous participating medium (compendium item 54), filling the inside of the
    closed meshes whose material names it as ``interior``.

    Its coefficients, per metre, are a density times a spectral shape:
    σa(λ) = ``absorption_density`` · A(λ) and σs(λ) = ``scattering_density`` · S(λ), where
    A and S are rows of Scene.spectra (``absorption``, ``scattering``) or 1 at every
    wavelength when the index is -1 (a grey medium). A bounded spectrum gives a shape in
    [0, 1] (a colour, as Blender's volume colours); an unbounded one any positive curve
    (e.g. a measured σ(λ) in 1/m with density 1). Extinction σt = σa + σs, single-scattering
    albedo σs/σt. The phase function is Henyey–Greenstein with asymmetry ``anisotropy``
    g in (-1, 1): 0 isotropic, > 0 forward scattering (Blender's Anisotropy).
    """

    name: str
    absorption: int = -1  # spectrum index (bounded or unbounded shape); -1 = flat 1
    absorption_density: float = 0.0  # 1/m
    scattering: int = -1  # spectrum index (bounded or unbounded shape); -1 = flat 1
    scattering_density: float = 0.0  # 1/m
    anisotropy: float = 0.0  # Henyey–Greenstein g in (-1, 1)


@dataclass
class Light:
    """An analytic light (``kind``, a LIGHT_* tag).

    * LIGHT_RECT / LIGHT_ELLIPSE: a rectangle or ellipse spanned by two half-axes,
      emitting from the side of ``cross(axis_u, axis_v)`` (both sides if
      ``two_sided``) with uniform radiance of ``luminance`` cd/m².
    * LIGHT_POINT: a sphere of ``radius`` m at ``position`` (0: a point) of luminous
      intensity ``intensity`` cd in every direction (as Blender's point light).
    * LIGHT_SPOT: a point light restricted to a cone around ``direction`` of full angle
      ``spot_angle`` rad, softened by ``spot_blend`` (Blender's smoothstep); ``intensity``
      cd on the axis.
    * LIGHT_SUN: a distant light travelling along ``direction``, giving ``illuminance``
      lux on a surface facing it, with angular diameter ``angle`` rad.
    ``axis_u``/``axis_v`` are unused by point, spot and sun lights (pass zeros), except
    that a point or spot light with a photometric ``profile`` (index into Scene.profiles)
    takes its frame from ``direction`` (the profile's nadir, θ = 0: the light's local −Z)
    and ``axis_u`` (the light's local +X; only its part across ``direction`` counts), with
    C = 0 towards local −Y and C = 90° towards local −X (Cycles' IES convention, see
    :class:`Profile`). ``profile_mode`` sets its brightness: "file" the profile's own
    candela (``intensity`` unused), "peak" the profile scaled to ``intensity`` cd at its
    maximum, "flux" scaled to a total output of ``flux`` lm (a spot's cone included).
    """

    name: str
    kind: int  # LIGHT_* tag
    position: tuple  # centre, metres
    axis_u: tuple  # half-extent vector, metres
    axis_v: tuple  # half-extent vector, metres
    spectrum: int  # index of an unbounded spectrum (shape only)
    luminance: float  # cd/m²
    two_sided: bool = False
    visible: bool = False  # seen directly by camera rays (Blender 5.0's default: no)
    radius: float = 0.0  # point/spot: sphere radius, m
    intensity: float = 0.0  # point/spot: luminous intensity, cd
    direction: tuple = (0.0, 0.0, -1.0)  # spot: cone axis; sun: direction the light travels
    spot_angle: float = math.pi  # spot: full cone angle, rad (Blender's spot_size)
    spot_blend: float = 0.0  # spot: Blender's spot_blend in [0, 1]
    illuminance: float = 0.0  # sun: lux on a surface facing it
    angle: float = 0.0  # sun: angular diameter, rad
    profile: int = -1  # point/spot: index into Scene.profiles (IES / EULUMDAT), -1 = none
    profile_mode: str = "file"  # "file" (its candela), "peak" (max = intensity cd) or "flux" (total = flux lm)
    flux: float = 0.0  # lm: a profiled light's total output when profile_mode is "flux"
    # ray visibility (``visible`` is the camera's): False, rays of that kind do not see the light, and
    # surface points whose scattering is of that kind get no light from it
    visible_diffuse: bool = True
    visible_glossy: bool = True
    visible_transmission: bool = True
    visible_volume: bool = True
    cast_shadow: bool = True  # False: nothing occludes it (Blender's light "Cast Shadow")
    # light linking: the meshes (indices into Scene.meshes) it lights, None: all
    receivers: list | None = None
    # shadow linking: the meshes that cast its shadows, None: every mesh with visible_shadow
    blockers: list | None = None


PROFILE_MODES = ("file", "peak", "flux")


@dataclass
class Profile:
    """A photometric (goniometric) profile: luminous intensity in cd over directions in a
    light's frame, type C photometry as IES LM-63 and EULUMDAT files give it
    (core/io/photometric.py reads them).

    ``theta``: vertical angles in degrees from the nadir (the light's local −Z), ascending
    in [0, 180]; the intensity is 0 outside [theta[0], theta[-1]]. ``phi``: C angles in
    degrees, ascending from 0 to 360 (symmetries already expanded), C = 0 towards the
    light's local −Y, 90 towards −X, 180 towards +Y, 270 towards +X (C grows clockwise
    seen from above, as Cycles' IES texture and Radiance's ies2rad read type C data).
    ``candela``: (len(phi), len(theta)), one row per C plane; bilinear in (θ, C) between.
    """

    name: str
    theta: np.ndarray  # float64 (T,), degrees
    phi: np.ndarray  # float64 (P,), degrees, 0 .. 360
    candela: np.ndarray  # float64 (P, T), cd
    source: str = ""  # the file it came from (informative)


@dataclass
class Camera:
    """A perspective, orthographic or panoramic camera with Blender's conventions.

    ``to_world`` maps camera space (looking down -Z, +Y up) to world space. The
    field of view follows Blender: the sensor size along the fitted axis
    (``sensor_fit``; AUTO fits the larger image dimension) over the focal length.
    Panoramic projections (Cycles'): equirectangular over ``latitude_min`` ..
    ``latitude_max`` (bottom to top) and ``longitude_min`` .. ``longitude_max`` (left to
    right; rad, longitude 0 down −Z, positive towards the camera's +X), equidistant fisheye
    of ``fisheye_fov`` across the image, equisolid fisheye of ``fisheye_lens_mm`` and
    ``fisheye_fov`` on the fitted sensor (core/camera/kernel.py).
    """

    to_world: np.ndarray  # float64 (4, 4)
    width: int = 256
    height: int = 256
    lens_mm: float = 50.0
    sensor_width_mm: float = 36.0
    sensor_height_mm: float = 24.0
    sensor_fit: int = C.FIT_AUTO
    shift_x: float = 0.0
    shift_y: float = 0.0
    projection: int = C.CAM_PERSPECTIVE  # CAM_PERSPECTIVE, CAM_ORTHOGRAPHIC or one of C.CAM_PANORAMIC
    ortho_scale: float = 6.0  # orthographic: extent of the fitted axis, m (Blender's ortho_scale)
    fstop: float = 0.0  # thin lens: f-number; 0 = pinhole (no depth of field)
    focus_distance: float = 10.0  # thin lens: distance in focus, m
    latitude_min: float = -0.5 * math.pi  # equirectangular: rad
    latitude_max: float = 0.5 * math.pi
    longitude_min: float = -math.pi
    longitude_max: float = math.pi
    fisheye_fov: float = math.pi  # fisheye: field of view, rad
    fisheye_lens_mm: float = 10.5  # equisolid fisheye: focal length, mm


@dataclass
class World:
    """The background: a constant spectrum, or an equirectangular image.

    ``image`` (float32 (H, W, 3), linear Rec.709, Cycles' equirectangular layout: row 0 at
    the zenith +Z, the image's centre looking along +X) replaces the constant background
    when given. Its texels are uplifted to spectra at render time; RGB 1 is 683 cd/m²
    (Blender's scene-linear 1), times ``image_scale``; ``rotation`` turns the map about +Z
    (counter-clockwise seen from above, as a Mapping node's Z rotation).
    """

    background: int = -1  # index of an unbounded spectrum; -1 = black
    luminance: float = 0.0  # cd/m² of the background radiance
    image: np.ndarray | None = None  # float32 (H, W, 3) linear Rec.709 equirectangular map, or None
    rotation: float = 0.0  # rad about +Z
    image_scale: float = 1.0  # multiplies the image (Blender's Background strength)


# Default solid-angle range (sr) in which emissive triangles are sampled as spherical
# triangles (RenderSettings.tri_solid_angle_min/max; chosen by benchmarks/sphtri_bench.py).
TRI_SOLID_ANGLE_MIN = 0.1
TRI_SOLID_ANGLE_MAX = 6.22


@dataclass
class RenderSettings:
    spp: int = 64
    max_depth: int = 64  # maximum bounces, as Cycles' Max Bounces (0: direct light only)
    rr_depth: int = 3  # Russian roulette starts after this many bounces
    seed: int = 0
    sampler: int = C.SAMPLER_STRATIFIED  # SAMPLER_* (independent, Halton, Hammersley, stratified: the default)
    filter: int = C.FILTER_BLACKMAN_HARRIS  # FILTER_* (pixel filter, Cycles' default)
    filter_width: float = 1.5  # pixels
    time_limit: float = 0.0  # seconds; 0 = none
    noise_target: float = 0.0  # adaptive sampling: a pixel stops once its relative error of luminance is below
    next_event: bool = True  # False: the naive reference integrator (BSDF sampling only, no NEE, no MIS)
    colour_space: str = "rec709"  # output colour space of the image: 'rec709', 'acescg' or 'xyz' (core.film)
    observer: str = "1931"  # CIE observer of the film's XYZ: '1931' (2°) or '1964' (10°); photometry is V(λ)
    film_transparent: bool = False  # Cycles' Film > Transparent: camera rays that miss give alpha 0, no world
    # emissive triangles seen under a solid angle in [min, max] sr are sampled uniformly in that
    # solid angle (compendium item 22), others by area; min > max: always by area
    tri_solid_angle_min: float = TRI_SOLID_ANGLE_MIN
    tri_solid_angle_max: float = TRI_SOLID_ANGLE_MAX


@dataclass
class Scene:
    meshes: list[Mesh] = field(default_factory=list)
    spectra: SpectrumTable = field(default_factory=SpectrumTable.empty)
    materials: list[Material] = field(default_factory=list)
    lights: list[Light] = field(default_factory=list)
    ior_tables: IORTable = field(default_factory=IORTable.empty)
    media: list[Medium] = field(default_factory=list)
    textures: list[Texture] = field(default_factory=list)  # image textures, core/scene/textures.py
    programs: list[Program] = field(default_factory=list)  # shader programs, core/shading/program.py
    profiles: list[Profile] = field(default_factory=list)
    camera: Camera = field(default_factory=lambda: Camera(np.eye(4)))
    world: World = field(default_factory=World)
    settings: RenderSettings = field(default_factory=RenderSettings)
    # where a lighting analysis reports illuminance (core/lux/grids.py): grids, work planes, mesh points
    calculation_surfaces: list[CalculationSurface] = field(default_factory=list)
    metadata: dict = field(default_factory=dict)
    version: int = C.SCENE_FORMAT_VERSION

    @property
    def n_triangles(self):
        return sum(int(m.indices.shape[0]) for m in self.meshes)


# --------------------------------------------------------------------------- validation

MAX_UV = 1e6  # largest texture coordinate magnitude (the lookups scale it by the texture size)


def validate(scene: Scene) -> Scene:
    """Check every field of ``scene``; raise SceneError naming the first bad one."""
    if not isinstance(scene, Scene):
        _fail("scene", f"expected a Scene, got {type(scene).__name__}")
    if scene.version != C.SCENE_FORMAT_VERSION:
        _fail("version", f"unknown scene format version {scene.version!r} "
                         f"(this build reads version {C.SCENE_FORMAT_VERSION})")

    if not isinstance(scene.metadata, dict):
        _fail("metadata", f"expected a dict, got {type(scene.metadata).__name__}")
    for key in ("meshes", "materials", "lights", "media", "textures", "profiles", "programs"):
        if not isinstance(getattr(scene, key), list):
            _fail(key, f"expected a list, got {type(getattr(scene, key)).__name__}")
        for i, rec in enumerate(getattr(scene, key)):
            _check_str(f"{key}[{i}].name", getattr(rec, "name", None))
    _validate_spectra(scene)
    spec_ref = _spectrum_reference(scene)
    _validate_media(scene)
    _validate_materials(scene, spec_ref)
    _validate_meshes(scene)
    _check_textures(scene, _fail)
    _check_programs(scene, _fail)
    _validate_profiles(scene)
    _validate_lights(scene, spec_ref)
    _validate_camera(scene.camera)
    _validate_world(scene, spec_ref)
    _validate_settings(scene.settings)
    _validate_calculation_surfaces(scene.calculation_surfaces)
    return scene


def _validate_spectra(scene):

    sp = scene.spectra
    if not isinstance(sp.names, list):
        _fail("spectra.names", f"expected a list, got {type(sp.names).__name__}")
    for i, name in enumerate(sp.names):
        _check_str(f"spectra.names[{i}]", name)
    n_spec = len(sp)
    _check_array("spectra.coeffs", sp.coeffs, np.float64, (n_spec, None))
    _check_array("spectra.kind", sp.kind, np.int32, (n_spec,))
    if n_spec and not C.N_COEFFS_MIN <= sp.coeffs.shape[1] <= C.N_COEFFS_MAX:
        _fail("spectra.coeffs", f"number of coefficients must be in [{C.N_COEFFS_MIN}, "
                                f"{C.N_COEFFS_MAX}], got {sp.coeffs.shape[1]}")
    for i in range(n_spec):
        nm = f"spectra[{i}] ({sp.names[i]!r})"
        if sp.kind[i] not in (C.SPECTRUM_BOUNDED, C.SPECTRUM_UNBOUNDED):
            _fail(f"spectra.kind[{i}]", f"unknown spectrum kind {int(sp.kind[i])}")
        problem = moments.check_coefficients(sp.coeffs[i], int(sp.kind[i]))
        if problem:
            _fail(nm, problem)


def _spectrum_reference(scene):
    """A check of a field that names a spectrum of ``scene``: index in range, right kind."""
    sp = scene.spectra
    n_spec = len(sp)

    def spec_ref(name, idx, kind, allow_none=True):
        _check_number(name, idx, integer=True)
        if idx == -1 and allow_none:
            return
        if not 0 <= idx < n_spec:
            _fail(name, f"spectrum index {idx} out of range [0, {n_spec})")
        if sp.kind[idx] != kind:
            want = "bounded (reflectance)" if kind == C.SPECTRUM_BOUNDED else "unbounded (emission)"
            _fail(name, f"spectrum {idx} ({sp.names[idx]!r}) must be {want}")

    return spec_ref


def _validate_media(scene):
    n_spec = len(scene.spectra)
    for i, md in enumerate(scene.media):
        nm = f"media[{i}] ({md.name!r})"
        for key in ("absorption", "scattering"):
            idx = getattr(md, key)
            _check_number(f"{nm}.{key}", idx, integer=True)
            if not -1 <= idx < n_spec:
                _fail(f"{nm}.{key}", f"spectrum index {idx} out of range [-1, {n_spec})")
        _check_number(f"{nm}.absorption_density", md.absorption_density, lo=0.0, hi=1e9)
        _check_number(f"{nm}.scattering_density", md.scattering_density, lo=0.0, hi=1e9)
        _check_number(f"{nm}.anisotropy", md.anisotropy)
        if not -1.0 < md.anisotropy < 1.0:
            _fail(f"{nm}.anisotropy", f"Henyey–Greenstein g must be in (-1, 1), got {md.anisotropy}")


def _validate_materials(scene, spec_ref):
    n_med = len(scene.media)
    n_mat = len(scene.materials)
    it = scene.ior_tables
    _check_array("ior_tables.values", it.values, np.float32, (len(it), C.N_LAMBDA))
    if len(it) and it.values.min() < 0.0:
        _fail("ior_tables.values", "refractive indices must be ≥ 0")
    for i, m in enumerate(scene.materials):
        nm = f"materials[{i}] ({m.name!r})"
        if m.model not in C.MATERIAL_MODELS:
            _fail(f"{nm}.model", f"unknown material model {m.model}")
        spec_ref(f"{nm}.reflectance", m.reflectance, C.SPECTRUM_BOUNDED)
        spec_ref(f"{nm}.specular", m.specular, C.SPECTRUM_BOUNDED)
        spec_ref(f"{nm}.emission", m.emission, C.SPECTRUM_UNBOUNDED)
        _check_number(f"{nm}.model", m.model, integer=True)
        _check_number(f"{nm}.emission_luminance", m.emission_luminance, lo=0.0, hi=MAX_PHOTOMETRIC)
        _check_bool(f"{nm}.two_sided", m.two_sided)
        _check_number(f"{nm}.ior", m.ior, lo=1e-3, hi=100.0)
        for key in ("eta_table", "kappa_table"):
            idx = getattr(m, key)
            _check_number(f"{nm}.{key}", idx, integer=True)
            if not -1 <= idx < len(it):
                _fail(f"{nm}.{key}", f"index {idx} out of range [-1, {len(it)})")
        _check_number(f"{nm}.interior", m.interior, integer=True)
        if not -1 <= m.interior < n_med:
            _fail(f"{nm}.interior", f"medium index {m.interior} out of range [-1, {n_med})")
        if not isinstance(m.holdout, (bool, np.bool_)):
            _fail(f"{nm}.holdout", f"expected true or false, got {m.holdout!r}")
        if m.model == C.MAT_NULL and m.emission != -1 and m.emission_luminance > 0.0:
            _fail(f"{nm}.emission", "a null surface (model MAT_NULL) cannot emit")
        if m.params is not None:
            if isinstance(m.params, np.ndarray):
                row = m.params
                if row.dtype.kind not in "iuf":
                    _fail(f"{nm}.params", f"expected numbers, got an array of dtype {row.dtype}")
            else:
                if not isinstance(m.params, (list, tuple)) or any(
                        isinstance(x, (bool, np.bool_)) or not isinstance(x, (int, float, np.integer, np.floating))
                        for x in m.params):
                    _fail(f"{nm}.params", f"expected a list of at most {C.MATERIAL_PARAMS} numbers, "
                                          f"got {type(m.params).__name__}")
                try:
                    row = np.asarray(m.params, dtype=np.float64)
                except (OverflowError, ValueError):
                    _fail(f"{nm}.params", "a number out of range")
            if row.ndim != 1 or row.size > C.MATERIAL_PARAMS:
                _fail(f"{nm}.params", f"expected at most {C.MATERIAL_PARAMS} numbers, got shape {row.shape}")
            if not np.all(np.isfinite(row)):
                _fail(f"{nm}.params", "contains NaN or Inf")
            if row.size and np.abs(row).max() > 1e9:
                _fail(f"{nm}.params", f"a parameter of magnitude {np.abs(row).max():.3g} (at most 1e9)")
            if m.model == C.MAT_PLASTIC and row.size > 4:
                layering, multiscatter = float(row[3]), float(row[4])
                if layering not in (0.0, 1.0):
                    _fail(f"{nm}.params", f"plastic layering (entry 3) must be 0 (physical) or 1 (cycles), "
                          f"got {layering:g}")
                if multiscatter not in (0.0, 1.0) or (multiscatter == 1.0 and layering != 1.0):
                    _fail(f"{nm}.params", f"plastic multiscatter (entry 4) must be 0, or 1 with layering 1 (cycles), "
                          f"got {multiscatter:g}")
        if m.model in (C.MAT_MIX, C.MAT_ADD):
            row = list(m.params or [])
            if len(row) < 3:
                _fail(f"{nm}.params", "a mix needs [weight, first material, second material]")
            if m.model == C.MAT_MIX and not 0.0 <= row[0] <= 1.0:
                _fail(f"{nm}.params", f"mix weight must be in [0, 1], got {row[0]}")
            for k in (1, 2):
                if int(row[k]) != row[k] or not 0 <= row[k] < n_mat or int(row[k]) == i:
                    _fail(f"{nm}.params", f"component {row[k]} is not another material's index")
                if scene.materials[int(row[k])].model == C.MAT_NULL:
                    _fail(f"{nm}.params", f"component {int(row[k])} is a null surface, which cannot be mixed")
    # mixes must not form cycles (the kernel follows at most MIX_DEPTH links)
    for i, m in enumerate(scene.materials):
        seen = [i]
        stack = [(i, 0)]
        while stack:
            j, depth = stack.pop()
            mj = scene.materials[j]
            if mj.model in (C.MAT_MIX, C.MAT_ADD):
                if depth >= C.MIX_DEPTH:
                    _fail(f"materials[{i}] ({m.name!r}).params", f"mixes nest deeper than {C.MIX_DEPTH} or loop")
                for k in (1, 2):
                    stack.append((int(mj.params[k]), depth + 1))
        del seen


def _validate_meshes(scene):
    n_mat = len(scene.materials)
    for i, mesh in enumerate(scene.meshes):
        nm = f"meshes[{i}] ({mesh.name!r})"
        _check_array(f"{nm}.positions", mesh.positions, np.float32, (None, 3))
        if mesh.positions.size and np.abs(mesh.positions).max() > MAX_COORDINATE:
            _fail(f"{nm}.positions", f"a coordinate of magnitude {np.abs(mesh.positions).max():.3g} m "
                                     f"(at most {MAX_COORDINATE:g})")
        n_v = mesh.positions.shape[0]
        _check_array(f"{nm}.indices", mesh.indices, np.int32, (None, 3))
        n_t = mesh.indices.shape[0]
        if n_t and (mesh.indices.min() < 0 or mesh.indices.max() >= n_v):
            bad = int(mesh.indices.min()) if mesh.indices.min() < 0 else int(mesh.indices.max())
            _fail(f"{nm}.indices", f"vertex index {bad} out of range [0, {n_v})")
        _check_array(f"{nm}.material", mesh.material, np.int32, (n_t,))
        if n_t and (mesh.material.min() < 0 or mesh.material.max() >= n_mat):
            bad = int(mesh.material.min()) if mesh.material.min() < 0 else int(mesh.material.max())
            _fail(f"{nm}.material", f"material index {bad} out of range [0, {n_mat})")
        if mesh.normals is not None:
            _check_array(f"{nm}.normals", mesh.normals, np.float32, (n_v, 3))
        for key, shape in (("uvs", (n_v, 2)), ("corner_uvs", (3 * n_t, 2))):
            a = getattr(mesh, key)
            if a is not None:
                _check_array(f"{nm}.{key}", a, np.float32, shape)
                if a.size and np.abs(a).max() > MAX_UV:
                    _fail(f"{nm}.{key}", f"a texture coordinate of magnitude {np.abs(a).max():.3g} "
                                         f"(at most {MAX_UV:g})")
        for key in MESH_FLAGS:
            if not isinstance(getattr(mesh, key), (bool, np.bool_)):
                _fail(f"{nm}.{key}", f"expected true or false, got {getattr(mesh, key)!r}")
        _check_links(nm, mesh, len(scene.meshes))


def _check_links(nm, rec, n_meshes):
    """``receivers`` and ``blockers`` of a light or mesh: None or a list of distinct mesh indices."""
    for key in LINK_FIELDS:
        v = getattr(rec, key)
        if v is None:
            continue
        if not isinstance(v, (list, tuple)):
            _fail(f"{nm}.{key}", f"expected null or a list of mesh indices, got {type(v).__name__}")
        for k, idx in enumerate(v):
            _check_number(f"{nm}.{key}[{k}]", idx, integer=True)
            if not 0 <= idx < n_meshes:
                _fail(f"{nm}.{key}[{k}]", f"mesh index {idx} out of range [0, {n_meshes})")
        if len(set(int(i) for i in v)) != len(v):
            _fail(f"{nm}.{key}", "a mesh index is listed twice")


def _validate_profiles(scene):
    for i, pr in enumerate(scene.profiles):
        nm = f"profiles[{i}] ({getattr(pr, 'name', '?')!r})"
        if not isinstance(pr, Profile):
            _fail(f"profiles[{i}]", f"expected a Profile, got {type(pr).__name__}")
        _check_array(f"{nm}.theta", pr.theta, np.float64, (None,))
        _check_array(f"{nm}.phi", pr.phi, np.float64, (None,))
        _check_array(f"{nm}.candela", pr.candela, np.float64, (pr.phi.shape[0], pr.theta.shape[0]))
        if pr.theta.size < 1 or pr.theta[0] < 0.0 or pr.theta[-1] > 180.0 or np.any(np.diff(pr.theta) <= 0):
            _fail(f"{nm}.theta", "expected ascending angles in [0, 180] degrees")
        if pr.phi.size < 2 or pr.phi[0] != 0.0 or pr.phi[-1] != 360.0 or np.any(np.diff(pr.phi) <= 0):
            _fail(f"{nm}.phi", "expected ascending angles from 0 to 360 degrees (symmetries expanded)")
        if pr.candela.size and pr.candela.min() < 0.0:
            _fail(f"{nm}.candela", "negative intensity")
        if pr.candela.size and pr.candela.max() > MAX_PHOTOMETRIC:
            _fail(f"{nm}.candela", f"an intensity of {pr.candela.max():.3g} cd (at most {MAX_PHOTOMETRIC:g})")
        _check_str(f"{nm}.source", pr.source, max_len=1 << 16)


def _validate_lights(scene, spec_ref):
    n_prof = len(scene.profiles)
    for i, li in enumerate(scene.lights):
        nm = f"lights[{i}] ({li.name!r})"
        _check_number(f"{nm}.kind", li.kind, integer=True)
        if li.kind not in C.LIGHT_KINDS:
            _fail(f"{nm}.kind", f"unknown light kind {li.kind} (0 rect, 1 ellipse, 2 point, 3 spot, 4 sun)")
        _check_vec3(f"{nm}.position", li.position)
        u = _check_vec3(f"{nm}.axis_u", li.axis_u, hi=1e6)
        v = _check_vec3(f"{nm}.axis_v", li.axis_v, hi=1e6)
        spec_ref(f"{nm}.spectrum", li.spectrum, C.SPECTRUM_UNBOUNDED, allow_none=False)
        _check_bool(f"{nm}.two_sided", li.two_sided)
        for key in ("visible", "visible_diffuse", "visible_glossy", "visible_transmission", "visible_volume",
                    "cast_shadow"):
            _check_bool(f"{nm}.{key}", getattr(li, key))
        _check_links(nm, li, len(scene.meshes))
        if li.kind in (C.LIGHT_RECT, C.LIGHT_ELLIPSE):
            area = float(np.linalg.norm(np.cross(u, v)))
            if not area > MIN_LENGTH * MIN_LENGTH * 1e6:
                _fail(f"{nm}.axis_u", f"the light's axes span no area (|axis_u × axis_v| = {area:.3g} m²)")
            _check_number(f"{nm}.luminance", li.luminance, lo=0.0, hi=MAX_PHOTOMETRIC)
        else:
            _check_number(f"{nm}.luminance", li.luminance)  # unused by point, spot and sun lights
        if li.kind in (C.LIGHT_POINT, C.LIGHT_SPOT):
            _check_number(f"{nm}.radius", li.radius, lo=0.0, hi=1e6)
            _check_number(f"{nm}.intensity", li.intensity, lo=0.0, hi=MAX_PHOTOMETRIC)
        if li.kind in (C.LIGHT_SPOT, C.LIGHT_SUN):
            d = _check_vec3(f"{nm}.direction", li.direction, hi=1e6)
            if not np.linalg.norm(d) >= MIN_LENGTH:
                _fail(f"{nm}.direction", f"must be a non-zero vector (it is normalised), got length "
                                         f"{np.linalg.norm(d):.3g}")
        if li.kind == C.LIGHT_SPOT:
            _check_number(f"{nm}.spot_angle", li.spot_angle, lo=0.0, hi=math.pi)
            if li.spot_angle <= 0.0:
                _fail(f"{nm}.spot_angle", "must be > 0 (the full cone angle in radians, at most π)")
            _check_number(f"{nm}.spot_blend", li.spot_blend, lo=0.0, hi=1.0)
        _check_number(f"{nm}.profile", li.profile, lo=-1, integer=True)
        if li.profile >= 0:
            if li.kind not in (C.LIGHT_POINT, C.LIGHT_SPOT):
                _fail(f"{nm}.profile", "only point and spot lights take a photometric profile")
            if li.profile >= n_prof:
                _fail(f"{nm}.profile", f"profile index {li.profile} out of range [0, {n_prof})")
            if li.profile_mode not in PROFILE_MODES:
                _fail(f"{nm}.profile_mode", f"unknown mode {li.profile_mode!r} (one of {', '.join(PROFILE_MODES)})")
            _check_number(f"{nm}.flux", li.flux, lo=0.0, hi=MAX_PHOTOMETRIC)
            d = _check_vec3(f"{nm}.direction", li.direction, hi=1e6)
            u = _check_vec3(f"{nm}.axis_u", li.axis_u, hi=1e6)
            dn = float(np.linalg.norm(d))
            if not dn >= MIN_LENGTH:
                _fail(f"{nm}.direction", "a profiled light needs its nadir direction (local −Z), got a zero vector")
            if not np.linalg.norm(u - (u @ d) * d / (dn * dn)) > 1e-9 * max(1.0, float(np.linalg.norm(u))):
                _fail(f"{nm}.axis_u", "a profiled light needs its local +X axis, not zero nor along direction")
        if li.kind == C.LIGHT_SUN:
            _check_number(f"{nm}.illuminance", li.illuminance, lo=0.0, hi=MAX_PHOTOMETRIC)
            _check_number(f"{nm}.angle", li.angle, lo=0.0, hi=math.pi)


def _validate_camera(cam):
    _check_array("camera.to_world", np.asarray(cam.to_world), np.float64, (4, 4))
    _check_number("camera.width", cam.width, lo=1, hi=65536, integer=True)
    _check_number("camera.height", cam.height, lo=1, hi=65536, integer=True)
    _check_number("camera.lens_mm", cam.lens_mm, lo=1e-3, hi=1e6)
    _check_number("camera.sensor_width_mm", cam.sensor_width_mm, lo=1e-3, hi=1e6)
    _check_number("camera.sensor_height_mm", cam.sensor_height_mm, lo=1e-3, hi=1e6)
    _check_number("camera.sensor_fit", cam.sensor_fit, integer=True)
    _check_number("camera.projection", cam.projection, integer=True)
    if cam.sensor_fit not in (C.FIT_AUTO, C.FIT_HORIZONTAL, C.FIT_VERTICAL):
        _fail("camera.sensor_fit", f"unknown sensor fit {cam.sensor_fit}")
    if isinstance(cam.projection, bool) or cam.projection not in C.CAM_PROJECTIONS:
        _fail("camera.projection", f"unknown projection {cam.projection} (0 perspective, 1 orthographic, "
                                   "2 equirectangular, 3 equidistant fisheye, 4 equisolid fisheye)")
    _check_number("camera.latitude_min", cam.latitude_min, lo=-0.5 * math.pi - 1e-6, hi=0.5 * math.pi + 1e-6)
    _check_number("camera.latitude_max", cam.latitude_max, lo=-0.5 * math.pi - 1e-6, hi=0.5 * math.pi + 1e-6)
    _check_number("camera.longitude_min", cam.longitude_min, lo=-math.pi - 1e-6, hi=math.pi + 1e-6)
    _check_number("camera.longitude_max", cam.longitude_max, lo=-math.pi - 1e-6, hi=math.pi + 1e-6)
    _check_number("camera.fisheye_fov", cam.fisheye_fov, lo=1e-6, hi=10.0 * math.pi + 1e-6)
    _check_number("camera.fisheye_lens_mm", cam.fisheye_lens_mm, lo=1e-3, hi=1e6)
    _check_number("camera.ortho_scale", cam.ortho_scale, lo=1e-9, hi=1e9)
    _check_number("camera.fstop", cam.fstop, lo=0.0, hi=1e6)
    _check_number("camera.focus_distance", cam.focus_distance, lo=1e-6, hi=1e12)
    _check_number("camera.shift_x", cam.shift_x, lo=-100, hi=100)
    _check_number("camera.shift_y", cam.shift_y, lo=-100, hi=100)
    m = np.asarray(cam.to_world)
    if np.abs(m).max() > MAX_COORDINATE:
        _fail("camera.to_world", f"an entry of magnitude {np.abs(m).max():.3g} (at most {MAX_COORDINATE:g})")
    rot = m[:3, :3]
    if abs(np.linalg.det(rot)) < 1e-12:
        _fail("camera.to_world", "the rotation part is singular")
    # the frame the camera's rays are built in (core/camera/record.py camera_vector): its
    # normalised columns must be finite and span space
    with np.errstate(all="ignore"):
        norms = np.linalg.norm(rot, axis=0)
        frame = rot / norms[None, :]
        det = float(np.linalg.det(frame)) if np.all(np.isfinite(frame)) else float("nan")
    if not (np.all(np.isfinite(norms)) and norms.min() > 0.0 and np.all(np.isfinite(frame)) and abs(det) >= 1e-6):
        _fail("camera.to_world", f"the rotation part does not give a usable frame (column lengths "
                                 f"{', '.join(f'{n:.3g}' for n in norms)}, normalised determinant {det:.3g})")


def _validate_world(scene, spec_ref):
    spec_ref("world.background", scene.world.background, C.SPECTRUM_UNBOUNDED)
    _check_number("world.luminance", scene.world.luminance, lo=0.0, hi=MAX_PHOTOMETRIC)
    wimg = scene.world.image
    if wimg is not None:
        _check_array("world.image", wimg, np.float32, (None, None, 3))
        if wimg.shape[0] < 1 or wimg.shape[1] < 1:
            _fail("world.image", f"expected at least one texel, got shape {wimg.shape}")
        if wimg.size and wimg.min() < 0.0:
            bad = np.argwhere(wimg < 0.0)[0]
            _fail("world.image", f"negative radiance (first at index {tuple(int(i) for i in bad)})")
    _check_number("world.rotation", scene.world.rotation, lo=-1e6, hi=1e6)
    _check_number("world.image_scale", scene.world.image_scale, lo=0.0, hi=MAX_PHOTOMETRIC)
    if wimg is not None and wimg.size and C.K_M * float(wimg.max()) * scene.world.image_scale > MAX_PHOTOMETRIC:
        _fail("world.image", f"texels of {C.K_M * float(wimg.max()) * scene.world.image_scale:.3g} cd/m² "
                             f"after image_scale (at most {MAX_PHOTOMETRIC:g})")


def _validate_calculation_surfaces(surfaces):
    if not isinstance(surfaces, list):
        _fail("calculation_surfaces", f"expected a list, got {type(surfaces).__name__}")
    names = set()
    for i, s in enumerate(surfaces):
        if not isinstance(s, CalculationSurface):
            _fail(f"calculation_surfaces[{i}]", f"expected a CalculationSurface, got {type(s).__name__}")
        try:
            s.validate()
        except LuxError as e:
            _fail(f"calculation_surfaces[{i}]", str(e))
        if s.name in names:
            _fail(f"calculation_surfaces[{i}]", f"a second surface named {s.name!r} (names name the output files)")
        names.add(s.name)


def _validate_settings(s):
    _check_number("settings.spp", s.spp, lo=1, hi=1 << 24, integer=True)
    _check_number("settings.max_depth", s.max_depth, lo=0, hi=1024, integer=True)
    _check_number("settings.rr_depth", s.rr_depth, lo=1, hi=1024, integer=True)
    _check_number("settings.seed", s.seed, lo=0, hi=2**32 - 1, integer=True)
    _check_number("settings.sampler", s.sampler, integer=True)
    if s.sampler not in (C.SAMPLER_INDEPENDENT, C.SAMPLER_HALTON, C.SAMPLER_HAMMERSLEY, C.SAMPLER_STRATIFIED):
        _fail("settings.sampler", f"unknown sampler {s.sampler} (0 independent, 1 Halton, 2 Hammersley)")
    _check_number("settings.filter", s.filter, integer=True)
    if s.filter not in (C.FILTER_BOX, C.FILTER_BLACKMAN_HARRIS, C.FILTER_GAUSSIAN):
        _fail("settings.filter", f"unknown pixel filter {s.filter} (0 box, 1 Blackman-Harris, 2 Gaussian)")
    _check_number("settings.filter_width", s.filter_width, lo=0.01, hi=64.0)
    _check_number("settings.time_limit", s.time_limit, lo=0.0, hi=1e9)
    _check_number("settings.noise_target", s.noise_target, lo=0.0, hi=1e6)
    if not isinstance(s.next_event, (bool, np.bool_)):
        _fail("settings.next_event", f"expected true or false, got {s.next_event!r}")

    _check_str("settings.colour_space", s.colour_space)
    _check_str("settings.observer", s.observer)
    if s.colour_space not in COLOUR_SPACES:
        _fail("settings.colour_space", f"unknown colour space {s.colour_space!r} (one of {', '.join(COLOUR_SPACES)})")
    if s.observer not in OBSERVERS:
        _fail("settings.observer", f"unknown observer {s.observer!r} ('1931': CIE 1931 2°, '1964': CIE 1964 10°)")
    if not isinstance(s.film_transparent, (bool, np.bool_)):
        _fail("settings.film_transparent", f"expected true or false, got {s.film_transparent!r}")
    _check_number("settings.tri_solid_angle_min", s.tri_solid_angle_min, lo=0.0, hi=4.0 * math.pi)
    _check_number("settings.tri_solid_angle_max", s.tri_solid_angle_max, lo=0.0, hi=4.0 * math.pi)


# --------------------------------------------------------------------------- save / load

_RECORDS = {"materials": Material, "lights": Light, "media": Medium}


def _to_jsonable(obj):
    if isinstance(obj, np.ndarray):
        return obj.tolist()
    if isinstance(obj, (np.integer,)):
        return int(obj)
    if isinstance(obj, (np.floating,)):
        return float(obj)
    if isinstance(obj, (tuple, list)):
        return [_to_jsonable(x) for x in obj]
    if isinstance(obj, dict):
        return {k: _to_jsonable(v) for k, v in obj.items()}
    return obj


def _world_record(world, arrays):
    rec = {f.name: getattr(world, f.name) for f in dataclasses.fields(World) if f.name != "image"}
    rec["image"] = None
    if world.image is not None:
        arrays["world.image"] = world.image
        rec["image"] = "world.image"
    return rec


def _texture_records(textures, arrays):
    recs = []
    for i, tx in enumerate(textures):
        arrays[f"textures.{i}.image"] = tx.image
        recs.append({"name": tx.name, "image": f"textures.{i}.image", "interpolation": tx.interpolation,
                     "extension": tx.extension, "colour": bool(tx.colour)})
    return recs


def _program_records(programs, arrays):
    recs = []
    for i, p in enumerate(programs):
        arrays[f"programs.{i}.ops"] = p.ops
        arrays[f"programs.{i}.consts"] = p.consts
        recs.append({"name": p.name, "ops": f"programs.{i}.ops", "consts": f"programs.{i}.consts",
                     "attributes": list(p.attributes), "n_registers": int(p.n_registers)})
    return recs


def to_dict_and_arrays(scene: Scene):
    """Split a scene into a JSON-able dict and a dict of named arrays."""
    arrays = {"spectra.coeffs": scene.spectra.coeffs, "spectra.kind": scene.spectra.kind,
              "ior_tables.values": scene.ior_tables.values}
    meshes = []
    for i, m in enumerate(scene.meshes):
        rec = {"name": m.name}
        for key in ("positions", "indices", "material", "normals", "uvs", "corner_uvs"):
            a = getattr(m, key)
            if a is not None:
                arrays[f"meshes.{i}.{key}"] = a
                rec[key] = f"meshes.{i}.{key}"
        for key in MESH_FLAGS:  # written when not the default
            if getattr(m, key) != (key in VISIBILITY_FLAGS):
                rec[key] = bool(getattr(m, key))
        for key in LINK_FIELDS:
            if getattr(m, key) is not None:
                rec[key] = [int(i) for i in getattr(m, key)]
        if m.attributes:
            rec["attributes"] = {}
            for j, (an, av) in enumerate(sorted(m.attributes.items())):
                arrays[f"meshes.{i}.attributes.{j}"] = av
                rec["attributes"][an] = f"meshes.{i}.attributes.{j}"
        meshes.append(rec)
    profiles = []
    for i, pr in enumerate(scene.profiles):
        for key in ("theta", "phi", "candela"):
            arrays[f"profiles.{i}.{key}"] = getattr(pr, key)
        profiles.append({"name": pr.name, "source": pr.source, "theta": f"profiles.{i}.theta",
                         "phi": f"profiles.{i}.phi", "candela": f"profiles.{i}.candela"})
    cam = dataclasses.asdict(scene.camera)
    doc = {
        "format": "spectral-gi-scene",
        "version": scene.version,
        "metadata": scene.metadata,
        "spectra": {"names": list(scene.spectra.names), "coeffs": "spectra.coeffs", "kind": "spectra.kind"},
        "materials": [dataclasses.asdict(m) for m in scene.materials],
        "ior_tables": {"names": list(scene.ior_tables.names), "values": "ior_tables.values"},
        "lights": [dataclasses.asdict(li) for li in scene.lights],
        "media": [dataclasses.asdict(md) for md in scene.media],
        "textures": _texture_records(scene.textures, arrays),
        "programs": _program_records(scene.programs, arrays),
        "profiles": profiles,
        "meshes": meshes,
        "camera": cam,
        "world": _world_record(scene.world, arrays),
        "settings": dataclasses.asdict(scene.settings),
        "calculation_surfaces": [s.to_dict() for s in scene.calculation_surfaces],
    }
    return _to_jsonable(doc), arrays


def save(scene: Scene, path) -> Path:
    """Write ``scene`` as ``path`` (JSON) plus ``path`` with suffix ``.npz`` (arrays).

    ``path`` may also name a folder, which then receives ``scene.json`` and
    ``scene.npz``. The scene is validated first. The two files are replaced as one unit
    (core/io/atomic.py ``atomic_paths``: both or neither), and the JSON records the
    SHA-256 of the ``.npz`` it was written with, so that :func:`load` refuses a pair of
    files from two different saves.
    """
    validate(scene)
    path = Path(path)
    if path.suffix.lower() != ".json":
        path = path / "scene.json"
    npz_path = path.with_suffix(".npz")
    doc, arrays = to_dict_and_arrays(scene)
    buf = io.BytesIO()
    np.savez_compressed(buf, **{k: np.ascontiguousarray(v) for k, v in arrays.items()})
    data = buf.getvalue()
    doc["arrays"] = npz_path.name
    doc["arrays_sha256"] = hashlib.sha256(data).hexdigest()
    try:
        text = json.dumps(doc, indent=1, allow_nan=False)
    except (TypeError, ValueError, RecursionError) as e:  # only metadata is free-form
        raise SceneError(f"metadata: cannot be written as JSON ({e})") from None
    with atomic_paths([npz_path, path]) as (tmp_npz, tmp_json):
        with open(tmp_npz, "wb") as f:
            fsync_write(f, data)
        with open(tmp_json, "wb") as f:
            fsync_write(f, text.encode("utf-8"))
    return path


# Limits of a scene file, checked before anything larger is read.
MAX_JSON_BYTES = 1 << 28  # 256 MiB of JSON (the arrays live in the .npz)
MAX_JSON_DEPTH = 64  # nesting of JSON objects and lists
MAX_STRING = 1 << 16  # characters of one JSON string (names, metadata values, keys)


def _json_limits(doc, name):
    """Nesting depth and string lengths of a parsed JSON document (iterative, no recursion)."""
    stack = [(doc, 1, "")]
    while stack:
        v, depth, where = stack.pop()
        if depth > MAX_JSON_DEPTH:
            raise SceneError(f"{where or 'scene file'}: {name} nests deeper than {MAX_JSON_DEPTH} levels")
        if isinstance(v, str):
            if len(v) > MAX_STRING:
                raise SceneError(f"{where or 'scene file'}: a string of {len(v)} characters (at most {MAX_STRING})")
        elif isinstance(v, dict):
            for k, x in v.items():
                if len(k) > MAX_STRING:
                    raise SceneError(f"{where or 'scene file'}: a key of {len(k)} characters (at most {MAX_STRING})")
                stack.append((x, depth + 1, f"{where}.{k}" if where else k))
        elif isinstance(v, list):
            for i, x in enumerate(v):
                stack.append((x, depth + 1, f"{where}[{i}]"))


def _describe(v):
    if isinstance(v, str):
        return f"the string {v[:40]!r}" + ("..." if len(v) > 40 else "")
    if v is None:
        return "null"
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, (int, float)):
        return f"the number {v!r}"
    return {"dict": "an object", "list": "a list"}.get(type(v).__name__, type(v).__name__)


def _is_num(v):
    return type(v) in (int, float)


def _as_float(field_name, v):
    if not _is_num(v):
        raise SceneError(f"{field_name}: expected a number, got {_describe(v)}")
    try:
        return float(v)
    except OverflowError:
        raise SceneError(f"{field_name}: the number {str(v)[:40]}... is out of range") from None


def _typed(field_name, kind, v):
    """A JSON value checked against its field's one type (and converted to the record's)."""
    if kind == "int":
        if type(v) is not int:
            raise SceneError(f"{field_name}: expected an integer, got {_describe(v)}")
        return v
    if kind == "float":
        return _as_float(field_name, v)
    if kind == "bool":
        if type(v) is not bool:
            raise SceneError(f"{field_name}: expected true or false, got {_describe(v)}")
        return v
    if kind == "str":
        if type(v) is not str:
            raise SceneError(f"{field_name}: expected a string, got {_describe(v)}")
        return v
    if kind == "vec3":
        if type(v) is not list or len(v) != 3:
            raise SceneError(f"{field_name}: expected a list of 3 numbers, got {_describe(v)}")
        return tuple(_as_float(f"{field_name}[{k}]", x) for k, x in enumerate(v))
    if kind == "params":
        if v is None:
            return None
        if type(v) is not list or len(v) > C.MATERIAL_PARAMS:
            raise SceneError(f"{field_name}: expected null or a list of at most {C.MATERIAL_PARAMS} numbers, "
                             f"got {_describe(v)}" + (f" of {len(v)}" if type(v) is list else ""))
        return [_as_float(f"{field_name}[{k}]", x) for k, x in enumerate(v)]
    if kind == "matrix4":
        if type(v) is not list or len(v) != 4 or any(type(r) is not list or len(r) != 4 for r in v):
            raise SceneError(f"{field_name}: expected 4 rows of 4 numbers, got {_describe(v)}")
        return np.array([[_as_float(f"{field_name}[{i}][{j}]", x) for j, x in enumerate(r)]
                         for i, r in enumerate(v)], dtype=np.float64)
    if kind == "indices":
        if v is None:
            return None
        if type(v) is not list or any(type(x) is not int for x in v):
            raise SceneError(f"{field_name}: expected null or a list of integers, got {_describe(v)}")
        return list(v)
    if kind == "any":
        return v
    raise AssertionError(kind)  # pragma: no cover


def _kinds(cls, overrides):
    """Field → JSON type of a record class: from its defaults, or ``overrides``."""
    out = {}
    for f in dataclasses.fields(cls):
        if f.name in overrides:
            out[f.name] = overrides[f.name]
            continue
        d = f.default
        kind = {bool: "bool", int: "int", float: "float", str: "str", tuple: "vec3"}.get(type(d))
        if kind is None:
            raise AssertionError(f"{cls.__name__}.{f.name} has no JSON type")  # pragma: no cover
        out[f.name] = kind
    return out


_FIELD_TYPES = {
    Material: _kinds(Material, {"name": "str", "params": "params"}),
    Light: _kinds(Light, {"name": "str", "kind": "int", "position": "vec3", "axis_u": "vec3", "axis_v": "vec3",
                          "spectrum": "int", "luminance": "float", "receivers": "indices", "blockers": "indices"}),
    Medium: _kinds(Medium, {"name": "str"}),
    Camera: _kinds(Camera, {"to_world": "matrix4"}),
    World: _kinds(World, {"image": "any"}),
    RenderSettings: _kinds(RenderSettings, {}),
    Texture: _kinds(Texture, {"name": "str", "image": "any"}),
}


def _safe_array_name(path, name):
    """The ``.npz`` a scene file names: a plain file name in the scene's own folder."""
    if type(name) is not str:
        raise SceneError(f"arrays: expected a file name, got {_describe(name)}")
    if (not name or name in (".", "..") or "/" in name or "\\" in name or "\0" in name
            or Path(name).name != name or not name.lower().endswith(".npz")):
        raise SceneError(f"arrays: {name!r} is not a .npz file name in the scene's folder "
                         "(the arrays must lie beside the scene file)")
    return path.parent / name


def _sha256_file(path):
    h = hashlib.sha256()
    with open(path, "rb") as f:
        for chunk in iter(lambda: f.read(1 << 20), b""):
            h.update(chunk)
    return h.hexdigest()


def load(path) -> Scene:
    """Read a scene written by :func:`save`; raise SceneError with the field on any problem.

    Every field has one JSON type (an integer field takes no ``0.0``, a flag no string);
    the file's size, nesting depth and string lengths and each array's declared and
    decompressed size are checked before they are used; arrays are read only when a
    field refers to them."""
    path = Path(path)
    if path.is_dir():
        path = path / "scene.json"
    if not path.is_file():
        raise SceneError(f"scene file: {path} does not exist")
    try:
        size = path.stat().st_size
        if size > MAX_JSON_BYTES:
            raise SceneError(f"scene file: {path} has {size} bytes, more than {MAX_JSON_BYTES} "
                             "(arrays belong in the .npz)")
        doc = json.loads(path.read_bytes().decode("utf-8"))
    except SceneError:
        raise
    except OSError as e:
        raise SceneError(f"scene file: cannot read {path} ({e.strerror or e})") from None
    except RecursionError:
        raise SceneError(f"scene file: {path} nests deeper than {MAX_JSON_DEPTH} levels") from None
    except (UnicodeDecodeError, ValueError) as e:  # json.JSONDecodeError, int() of a 5000-digit number
        raise SceneError(f"scene file: {path} is not valid JSON ({e})") from None
    _json_limits(doc, path.name)
    if not isinstance(doc, dict) or doc.get("format") != "spectral-gi-scene":
        raise SceneError(f"format: {path} is not a spectral-gi scene file")
    version = doc.get("version")
    if type(version) is not int or version != C.SCENE_FORMAT_VERSION:
        raise SceneError(f"version: unknown scene format version {version!r} "
                         f"(this build reads version {C.SCENE_FORMAT_VERSION})")
    npz_path = _safe_array_name(path, doc.get("arrays", path.with_suffix(".npz").name))
    if not npz_path.is_file():
        raise SceneError(f"arrays: {npz_path} does not exist")
    digest = doc.get("arrays_sha256")
    if digest is not None:
        if type(digest) is not str:
            raise SceneError(f"arrays_sha256: expected a string, got {_describe(digest)}")
        if _sha256_file(npz_path) != digest.lower():
            raise SceneError(f"arrays: {npz_path.name} is not the array file {path.name} was saved with "
                             "(its SHA-256 differs): the two files come from different saves")
    try:
        reader = NpzReader(npz_path)
    except NpzError as e:
        raise SceneError(f"arrays: {e}") from None
    with reader:
        scene = _from_doc(doc, path, reader)
    return validate(scene)


def _from_doc(doc, path, reader):
    npz_name = Path(reader.path).name

    def arr(key, field_name):
        if key is None:
            return None
        if type(key) is not str:
            raise SceneError(f"{field_name}: expected the name of an array, got {_describe(key)}")
        if key not in reader:
            raise SceneError(f"{field_name}: array {key!r} missing from {npz_name}")
        try:
            return reader.get(key)
        except NpzError as e:
            raise SceneError(f"{field_name}: {e}") from None

    def obj(d, field_name):
        if type(d) is not dict:
            raise SceneError(f"{field_name}: expected an object, got {_describe(d)}")
        return d

    def lst(d, field_name, allow_none=False):
        if d is None and allow_none:
            return []
        if type(d) is not list:
            raise SceneError(f"{field_name}: expected a list, got {_describe(d)}")
        return d

    def names(d, field_name):
        out = lst(d, field_name)
        for k, x in enumerate(out):
            if type(x) is not str:
                raise SceneError(f"{field_name}[{k}]: expected a string, got {_describe(x)}")
        return list(out)

    def need(d, key, field_name):
        if key not in d:
            raise SceneError(f"{field_name}.{key}: missing from {path.name}")
        return d[key]

    def record(cls, d, field_name, converted=()):
        obj(d, field_name)
        types = _FIELD_TYPES[cls]
        unknown = set(d) - set(types)
        if unknown:
            raise SceneError(f"{field_name}: unknown keys {sorted(unknown)}")
        kw = {k: (v if k in converted else _typed(f"{field_name}.{k}", types[k], v)) for k, v in d.items()}
        try:
            return cls(**kw)
        except TypeError as e:
            raise SceneError(f"{field_name}: {e}") from None

    known = {"format", "version", "metadata", "spectra", "materials", "ior_tables", "lights", "media", "textures",
             "programs", "profiles", "meshes", "camera", "world", "settings", "calculation_surfaces", "arrays",
             "arrays_sha256"}
    unknown = set(doc) - known
    if unknown:
        raise SceneError(f"scene file: unknown keys {sorted(unknown)}")
    for key in ("spectra", "materials", "lights", "meshes", "camera", "world", "settings"):
        if key not in doc:
            raise SceneError(f"{key}: missing from {path.name}")
    sp = obj(doc["spectra"], "spectra")
    spectra = SpectrumTable(arr(need(sp, "coeffs", "spectra"), "spectra.coeffs"),
                            arr(need(sp, "kind", "spectra"), "spectra.kind"), names(need(sp, "names", "spectra"),
                                                                                  "spectra.names"))
    meshes = []
    mesh_keys = {"name", "positions", "indices", "material", "normals", "uvs", "corner_uvs", "attributes", *MESH_FLAGS,
                 *LINK_FIELDS}
    for i, m in enumerate(lst(doc["meshes"], "meshes")):
        nm = f"meshes[{i}]"
        obj(m, nm)
        unknown = set(m) - mesh_keys
        if unknown:
            raise SceneError(f"{nm}: unknown keys {sorted(unknown)}")
        for key in ("positions", "indices", "material"):
            if m.get(key) is None:
                raise SceneError(f"{nm}.{key}: missing from {path.name}")
        meshes.append(Mesh(
            name=_typed(f"{nm}.name", "str", need(m, "name", nm)),
            positions=arr(m["positions"], f"{nm}.positions"),
            indices=arr(m["indices"], f"{nm}.indices"),
            material=arr(m["material"], f"{nm}.material"),
            normals=arr(m.get("normals"), f"{nm}.normals"),
            uvs=arr(m.get("uvs"), f"{nm}.uvs"),
            corner_uvs=arr(m.get("corner_uvs"), f"{nm}.corner_uvs"),
            **{key: _typed(f"{nm}.{key}", "bool", m.get(key, key in VISIBILITY_FLAGS)) for key in MESH_FLAGS},
            **{key: _typed(f"{nm}.{key}", "indices", m.get(key)) for key in LINK_FIELDS},
            attributes={str(an): arr(ak, f"{nm}.attributes.{an}")
                        for an, ak in obj(m.get("attributes") or {}, f"{nm}.attributes").items()} or None,
        ))
    materials = [record(Material, d, f"materials[{i}]") for i, d in enumerate(lst(doc["materials"], "materials"))]
    itd = doc.get("ior_tables")
    if itd is None:
        ior_tables = IORTable.empty()
    else:
        obj(itd, "ior_tables")
        ior_tables = IORTable(arr(need(itd, "values", "ior_tables"), "ior_tables.values"),
                              names(need(itd, "names", "ior_tables"), "ior_tables.names"))
    lights = [record(Light, d, f"lights[{i}]") for i, d in enumerate(lst(doc["lights"], "lights"))]
    media = [record(Medium, d, f"media[{i}]") for i, d in enumerate(lst(doc.get("media"), "media", True))]
    programs = []
    for i, d in enumerate(lst(doc.get("programs"), "programs", True)):
        d = dict(obj(d, f"programs[{i}]"))
        try:
            programs.append(Program(name=str(d["name"]), ops=arr(d["ops"], f"programs[{i}].ops"),
                                    consts=arr(d["consts"], f"programs[{i}].consts"),
                                    attributes=[str(a) for a in d.get("attributes", [])],
                                    n_registers=int(d.get("n_registers", 0))))
        except (KeyError, TypeError, ValueError) as e:
            raise SceneError(f"programs[{i}]: {e}") from None
    textures = []
    for i, d in enumerate(lst(doc.get("textures"), "textures", True)):
        d = dict(obj(d, f"textures[{i}]"))
        d["image"] = arr(need(d, "image", f"textures[{i}]"), f"textures[{i}].image")
        textures.append(record(Texture, d, f"textures[{i}]", converted=("image",)))
    profiles = []
    for i, d in enumerate(lst(doc.get("profiles"), "profiles", True)):
        nm = f"profiles[{i}]"
        obj(d, nm)
        unknown = set(d) - {"name", "source", "theta", "phi", "candela"}
        if unknown:
            raise SceneError(f"{nm}: unknown keys {sorted(unknown)}")
        profiles.append(Profile(name=_typed(f"{nm}.name", "str", need(d, "name", nm)),
                                source=_typed(f"{nm}.source", "str", d.get("source", "")),
                                theta=arr(need(d, "theta", nm), f"{nm}.theta"),
                                phi=arr(need(d, "phi", nm), f"{nm}.phi"),
                                candela=arr(need(d, "candela", nm), f"{nm}.candela")))
    camera = record(Camera, doc["camera"], "camera")
    if not isinstance(getattr(camera, "to_world", None), np.ndarray):
        raise SceneError("camera.to_world: missing from " + path.name)
    wd = dict(obj(doc["world"], "world"))
    wd["image"] = arr(wd.get("image"), "world.image")
    world = record(World, wd, "world", converted=("image",))
    settings = record(RenderSettings, doc["settings"], "settings")
    surfaces = []
    for i, d in enumerate(lst(doc.get("calculation_surfaces"), "calculation_surfaces", True)):
        try:
            surfaces.append(CalculationSurface.from_dict(d))
        except (LuxError, TypeError, ValueError) as e:
            raise SceneError(f"calculation_surfaces[{i}]: {e}") from None
    metadata = doc.get("metadata")
    if metadata is None:
        metadata = {}
    if type(metadata) is not dict:
        raise SceneError(f"metadata: expected an object, got {_describe(metadata)}")
    return Scene(meshes=meshes, spectra=spectra, materials=materials, lights=lights, ior_tables=ior_tables,
                 media=media, profiles=profiles, textures=textures, programs=programs, camera=camera, world=world,
                 settings=settings,
                 calculation_surfaces=surfaces, metadata=dict(metadata), version=doc["version"])
