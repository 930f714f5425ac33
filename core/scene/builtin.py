"""Built-in scenes, built from the data in presets/."""
import numpy as np

from .. import constants as C
from ..io import presets
from . import Camera, Light, Material, Mesh, RenderSettings, Scene, SpectrumTable
from ..spectra import library, uplift

# The published light spectrum is relative. We scale it to this luminance (cd/m²),
# which exposes the box at 0 EV in the preview (white walls around 0.5 in linear
# Rec.709); a luminaire with an opal diffuser is of this order (10^4 cd/m²).
CORNELL_LIGHT_LUMINANCE = 17000.0
# The light quad lies in the ceiling plane as published; lower it by this much (mm)
# so it does not coincide with the ceiling.
CORNELL_LIGHT_DROP_MM = 0.1
# Reflectance of the light's diffuser (a constant, as the Cornell page lists it).
CORNELL_LIGHT_REFLECTANCE = 0.78

# Cornell frame (+y up, camera looking along +z, millimetres) → Blender frame (+Z up,
# metres): X = -x, Y = z, Z = y, a proper rotation, so the red wall stays on the left.
_CORNELL_TO_BLENDER = np.array([[-1.0, 0.0, 0.0], [0.0, 0.0, 1.0], [0.0, 1.0, 0.0]]) / 1000.0


def cornell_to_blender(p_mm):
    return np.asarray(p_mm, dtype=np.float64) @ _CORNELL_TO_BLENDER.T


def cornell_box(width=256, height=256, spp=64, max_depth=64, seed=0, n_coeffs=C.N_COEFFS_DEFAULT):
    """The Cornell box from Cornell's published measurements (presets/scenes/cornell_box)."""
    data = presets.load_cornell_box_data()
    spectra = SpectrumTable.empty(n_coeffs)
    materials = []
    index = {}
    for name in ("white", "red", "green"):
        wl, v = data["reflectance"][name]
        s = spectra.add(f"cornell {name}", uplift.reflectance_from_samples(wl, v, n_coeffs), C.SPECTRUM_BOUNDED)
        index[name] = len(materials)
        materials.append(Material(name=name, reflectance=s))
    lwl, lv = data["light"]
    s_light = spectra.add("cornell light", uplift.emission_from_samples(lwl, lv, n_coeffs), C.SPECTRUM_UNBOUNDED)
    s_diffuser = spectra.add("cornell light diffuser",
                             uplift.reflectance_from_samples([C.LAMBDA_MIN, C.LAMBDA_MAX],
                                                             [CORNELL_LIGHT_REFLECTANCE] * 2, n_coeffs),
                             C.SPECTRUM_BOUNDED)
    index["light"] = len(materials)
    materials.append(Material(name="light", reflectance=s_diffuser, emission=s_light,
                              emission_luminance=CORNELL_LIGHT_LUMINANCE, two_sided=False))

    meshes = []
    for surf in data["surfaces"]:
        quads = np.array(surf["quads"], dtype=np.float64)
        if surf["material"] == "light":
            quads[..., 1] -= CORNELL_LIGHT_DROP_MM
        pos = cornell_to_blender(quads.reshape(-1, 3)).astype(np.float32)
        q = np.arange(quads.shape[0])[:, None] * 4
        tris = np.concatenate([q + [0, 1, 2], q + [0, 2, 3]]).astype(np.int32)
        meshes.append(Mesh(name=surf["name"], positions=pos, indices=tris,
                           material=np.full(tris.shape[0], index[surf["material"]], np.int32)))

    cam = data["camera"]
    pos = cornell_to_blender(cam["position"])
    fwd = cornell_to_blender(cam["direction"])
    up = cornell_to_blender(cam["up"])
    fwd /= np.linalg.norm(fwd)
    right = np.cross(fwd, up)
    right /= np.linalg.norm(right)
    up = np.cross(right, fwd)
    to_world = np.eye(4)
    to_world[:3, 0] = right
    to_world[:3, 1] = up
    to_world[:3, 2] = -fwd
    to_world[:3, 3] = pos
    camera = Camera(to_world=to_world, width=int(width), height=int(height),
                    lens_mm=float(cam["focal_length_mm"]), sensor_width_mm=float(cam["film_width_mm"]),
                    sensor_height_mm=float(cam["film_height_mm"]), sensor_fit=C.FIT_AUTO)
    return Scene(meshes=meshes, spectra=spectra, materials=materials, camera=camera,
                 settings=RenderSettings(spp=int(spp), max_depth=int(max_depth), seed=int(seed)),
                 metadata={"name": "Cornell box",
                           "source": "Cornell Box Data, Program of Computer Graphics, Cornell University"})


def light_spectrum(spec, wavelengths):
    """Emission shape for a light named ``blackbody:<K>`` (e.g. ``blackbody:3000``) or a CIE
    illuminant (``D65``, ``A``, ``F11``/``FL11``, ``LED-B3``, …)."""

    text = str(spec).strip()
    if text.lower().startswith("blackbody:"):
        try:
            t = float(text.split(":", 1)[1].lower().rstrip("k"))
        except ValueError:
            raise ValueError(f"light {spec!r}: expected blackbody:<temperature in K>") from None
        if not 100.0 <= t <= 1e5:
            raise ValueError(f"light {spec!r}: temperature must be in [100, 100000] K")
        return library.blackbody(t, wavelengths)
    return library.illuminant(text, wavelengths)


def colorchecker(light="blackbody:3000", width=360, height=240, spp=64, max_depth=4, seed=0,
                 n_coeffs=16, luminance=3000.0):
    """The 24 ColorChecker patches (N. Ohta's spectra) on a black board, lit by one light.

    The light is a large rectangle beside the camera with the emission spectrum ``light``
    (see :func:`light_spectrum`) at ``luminance`` cd/m². Sixteen coefficients keep narrow
    lines such as F11's (ΔE00 under F11 0.07 with 16, 0.34 with 12).
    """

    g = np.arange(C.LAMBDA_MIN, C.LAMBDA_MAX + 1.0)
    spectra = SpectrumTable.empty(n_coeffs)
    materials = []
    meshes = []
    size, gap = 0.06, 0.012
    names = library.colorchecker_names()
    for i, name in enumerate(names):
        s = spectra.add(name, uplift.reflectance_from_samples(g, library.colorchecker(name, g), n_coeffs),
                        C.SPECTRUM_BOUNDED)
        materials.append(Material(name=name, reflectance=s))
        row, col = divmod(i, 6)
        x0 = (col - 3) * (size + gap) + gap / 2
        z0 = (1 - row) * (size + gap) + gap / 2
        quad = np.array([[x0, 0, z0], [x0 + size, 0, z0], [x0 + size, 0, z0 + size], [x0, 0, z0 + size]], np.float32)
        meshes.append(Mesh(name=name, positions=quad, indices=np.array([[0, 1, 2], [0, 2, 3]], np.int32),
                           material=np.full(2, i, np.int32)))
    s_light = spectra.add(f"light {light}", uplift.emission_from_samples(g, light_spectrum(light, g), n_coeffs),
                          C.SPECTRUM_UNBOUNDED)
    # a 1 m × 1 m light 1.2 m in front of the chart, emitting towards it (+Y)
    lights = [Light(name="light", kind=C.LIGHT_RECT, position=(0.0, -1.2, 0.3), axis_u=(0.0, 0.0, 0.5),
                    axis_v=(0.5, 0.0, 0.0), spectrum=s_light, luminance=float(luminance))]
    to_world = np.eye(4)
    to_world[:3, 0] = (1, 0, 0)
    to_world[:3, 1] = (0, 0, 1)
    to_world[:3, 2] = (0, -1, 0)
    to_world[:3, 3] = (0, -1.0, 0.0)
    camera = Camera(to_world=to_world, width=int(width), height=int(height), lens_mm=50.0, sensor_width_mm=36.0)
    return Scene(meshes=meshes, spectra=spectra, materials=materials, lights=lights, camera=camera,
                 settings=RenderSettings(spp=int(spp), max_depth=int(max_depth), seed=int(seed)),
                 metadata={"name": f"ColorChecker under {light}",
                           "source": "ColorChecker spectra: N. Ohta, via colour-science (presets/colorchecker)"})


BUILTIN_SCENES = {"cornell": cornell_box, "colorchecker": colorchecker}
