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

# Material model tags.
MAT_LAMBERT = 0

# Light tags (analytic lights; emissive triangles are handled by the material).
LIGHT_RECT = 0
LIGHT_ELLIPSE = 1

# Camera projection tags.
CAM_PERSPECTIVE = 0

# Sensor fit (as Blender's Camera.sensor_fit).
FIT_AUTO = 0
FIT_HORIZONTAL = 1
FIT_VERTICAL = 2

# Film channels accumulated per pixel: X, Y, Z, sample count, Y^2.
FILM_CHANNELS = 5
