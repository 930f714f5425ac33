"""Constants shared by the whole core: wavelength range, type tags, photometric constants.

Type tags are stored in scene files: never reorder or reuse a number.
"""

# Wavelength range sampled by the path tracer and covered by the CIE tables (nm).
LAMBDA_MIN = 360.0
LAMBDA_MAX = 830.0
# Spectra are reconstructed once per render onto this grid (1 nm) and looked up in kernels.
LAMBDA_STEP = 1.0
N_LAMBDA = int(round((LAMBDA_MAX - LAMBDA_MIN) / LAMBDA_STEP)) + 1  # 471
# Wavelengths carried by one path (hero wavelength + equally offset companions).
N_WAVELENGTHS = 4

# Maximum luminous efficacy of radiation for photopic vision (lm/W), from the SI
# definition of the candela (540 THz ~ 555.016 nm in air). The compendium (item 36)
# quotes 680 lm/W, an older rounded value; we use 683 as CIE and SI do.
K_M = 683.0

# Scene file format version (core/scene.py).
SCENE_FORMAT_VERSION = 1

# Fourier-basis (trigonometric-moment) spectra: number of stored coefficients.
N_COEFFS_DEFAULT = 12  # chosen by measurement: see core/spectra/moments.py
N_COEFFS_MIN = 3
N_COEFFS_MAX = 16

# Spectrum kinds.
SPECTRUM_BOUNDED = 0  # reflectance / transmittance in [0, 1]: bounded MESE reconstruction
SPECTRUM_UNBOUNDED = 1  # emission >= 0: maximum-entropy (Burg) reconstruction

# Material model tags (BSDF models of core/bsdfs; parameter rows documented in
# core/bsdfs/params.py).
MAT_LAMBERT = 0  # item 47
MAT_PHONG = 1  # item 48a: modified Phong, lobe around the mirror direction
MAT_BLINN_PHONG = 2  # item 48b: modified Phong, half-vector form
MAT_WARD = 3  # item 49: Ward, isotropic or anisotropic
MAT_LAFORTUNE = 4  # item 50: up to 3 generalised cosine lobes + diffuse
MAT_MIRROR = 5  # item 37: perfect mirror
MAT_DIELECTRIC = 6  # items 38-42: smooth dielectric (Fresnel, Snell, TIR)
MAT_CONDUCTOR = 7  # item 42: smooth conductor, complex index
MAT_GGX_CONDUCTOR = 8  # rough conductor, GGX (Walter et al. 2007)
MAT_GGX_DIELECTRIC = 9  # rough dielectric, GGX reflection + transmission (Walter et al. 2007)
MAT_MIX = 10  # params [w, a, b]: material a with probability w, else b (Blender's Mix Shader)
MAT_ADD = 11  # params [-, a, b]: the sum of materials a and b (Blender's Add Shader)
MAT_PLASTIC = 12  # rough dielectric coat (GGX, Fresnel) over a Lambert base (Principled, metallic 0)
MAT_NULL = 13  # no surface: rays pass straight through; only bounds a medium (Blender's volume-only objects)
MATERIAL_MODELS = tuple(range(14))
MATERIAL_PARAMS = 16  # length of a material's parameter row
MIX_DEPTH = 8  # deepest nesting of mixes the kernel follows

# Light tags (analytic lights; emissive triangles are handled by the material).
LIGHT_RECT = 0
LIGHT_ELLIPSE = 1
LIGHT_POINT = 2  # sphere of ``radius`` (0: a point), luminous intensity ``intensity`` cd
LIGHT_SPOT = 3  # point/sphere light restricted to a cone (Blender's spot size and blend)
LIGHT_SUN = 4  # distant light: ``illuminance`` lux normal to ``direction``, angular diameter ``angle``
LIGHT_KINDS = (LIGHT_RECT, LIGHT_ELLIPSE, LIGHT_POINT, LIGHT_SPOT, LIGHT_SUN)

# Camera projection tags.
CAM_PERSPECTIVE = 0
CAM_ORTHOGRAPHIC = 1
CAM_EQUIRECTANGULAR = 2  # panoramic, Cycles' equirectangular (latitude/longitude ranges)
CAM_FISHEYE_EQUIDISTANT = 3  # panoramic, Cycles' equidistant fisheye (field of view over the image)
CAM_FISHEYE_EQUISOLID = 4  # panoramic, Cycles' equisolid fisheye (lens, field of view, sensor)
CAM_PANORAMIC = (CAM_EQUIRECTANGULAR, CAM_FISHEYE_EQUIDISTANT, CAM_FISHEYE_EQUISOLID)
CAM_PROJECTIONS = (CAM_PERSPECTIVE, CAM_ORTHOGRAPHIC) + CAM_PANORAMIC

# Pixel filters (RenderSettings.filter).
FILTER_BOX = 0
FILTER_BLACKMAN_HARRIS = 1  # Cycles' default, width 1.5 px
FILTER_GAUSSIAN = 2

# Samplers (RenderSettings.sampler); the same numbers as core.sampling's SAMPLER_* tags.
SAMPLER_INDEPENDENT = 0
SAMPLER_HALTON = 1
SAMPLER_HAMMERSLEY = 2
SAMPLER_STRATIFIED = 3  # Sobol (0,2) pixel positions (digitally shifted per pixel), random numbers elsewhere

# Sensor fit (as Blender's Camera.sensor_fit).
FIT_AUTO = 0
FIT_HORIZONTAL = 1
FIT_VERTICAL = 2

# Film channels accumulated per pixel: X, Y, Z, sample count, Y^2.
FILM_CHANNELS = 5
