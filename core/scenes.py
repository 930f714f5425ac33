"""Built-in scenes, built from the data in presets/."""
import numpy as np

from . import constants as C
from . import presets
from .scene import Camera, Material, Mesh, RenderSettings, Scene, SpectrumTable
from .spectra import uplift

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
