"""OpenEXR output (OpenEXR 3.x Python bindings), written atomically.

Channels of a render:
* ``R, G, B``            the developed film's colour output (Developed.output): linear
                         Rec.709 (Blender's scene-linear, the default), ACEScg (AP1) or CIE
                         XYZ; the standard ``chromaticities`` attribute names its primaries
                         and white (for XYZ the OpenEXR convention (1,0), (0,1), (0,0),
                         (1/3,1/3)), ``spectralgi.colourSpace`` its name; RGB (1,1,1) is
                         683 cd/m² (the standard ``whiteLuminance`` attribute says so)
* ``XYZ.X, XYZ.Y, XYZ.Z`` CIE XYZ of the render's observer (``spectralgi.observer``: CIE
                         1931 2° by default) on the same scale (Y = 1 is 683 cd/m²)
* ``Luminance.Y``        absolute luminance, cd/m²
* ``Variance.Y``         variance of the pixel's mean luminance, (cd/m²)²
* ``xyY.x, xyY.y, xyY.Y`` chromaticity and luminance (cd/m²)
* ``Lab.L/a/b``, ``Luv.L/u/v`` CIE 1976 L*a*b* and L*u*v* against a D65 white of the
                         luminance in the ``spectralgi.referenceWhite`` attribute
* ``S0.<λ>nm``           optional spectral radiance per wavelength bin, W/(m²·sr·nm), in
                         the layout of Fichet, Pacanowski and Wilkie (JCGT 10(3), 2021)
"""
import numpy as np

from .atomic import atomic_path
from .. import constants as C
from ..film import CHROMATICITIES

try:  # OpenEXR is a declared dependency; import lazily so core imports without it.
    import OpenEXR as _exr
except ImportError:  # pragma: no cover
    _exr = None


def _require():
    if _exr is None:
        raise RuntimeError("the OpenEXR package is not installed (pip install OpenEXR)")
    return _exr


def write_channels(path, channels, attributes=None):
    """Write float32 channels ``{name: (H, W) array}`` to ``path`` atomically."""
    exr = _require()
    chans = {}
    shape = None
    for name, a in channels.items():
        arr = np.ascontiguousarray(a, dtype=np.float32)  # a strided view would be written wrong
        if arr.ndim != 2:
            raise ValueError(f"channel {name!r}: expected a 2-D array, got {arr.shape}")
        if shape is None:
            shape = arr.shape
        elif arr.shape != shape:
            raise ValueError(f"channel {name!r}: shape {arr.shape} differs from {shape}")
        chans[name] = arr
    header = {"compression": exr.ZIP_COMPRESSION, "type": exr.scanlineimage}
    for k, v in (attributes or {}).items():
        header[k] = v
    with atomic_path(path) as tmp:
        with exr.File(header, chans) as f:
            f.write(str(tmp))
    return path


def read_channels(path):
    """Read every channel of a single-part EXR: ({name: (H, W) float32}, header dict)."""
    exr = _require()
    with exr.File(str(path), separate_channels=True) as f:
        header = dict(f.header())
        chans = {name: np.array(ch.pixels) for name, ch in f.channels().items()}
    return chans, header


def spectral_channel_name(wavelength_nm, stokes=0):
    """Channel name of Fichet, Pacanowski and Wilkie's spectral layout (JCGT 10(3), 2021):
    ``S0.<wavelength>nm`` with a comma as the decimal separator (a dot separates layers)."""
    text = f"{float(wavelength_nm):.6f}".rstrip("0").rstrip(".")
    return f"S{int(stokes)}.{text.replace('.', ',')}nm"


def write_render(path, developed, attributes=None, spectral=None):
    """Write a developed film (see core.film.Developed) with the channels listed above.

    spectral: optional (wavelengths_nm[B], radiance[H, W, B]) written as emissive
    channels of the Fichet et al. 2021 layout (spectral radiance, W/(m² sr nm)).
    """

    space = getattr(developed, "colour_space", "rec709")
    rgb = developed.output if getattr(developed, "output", None) is not None else developed.rgb
    xyz = developed.XYZ
    var = np.where(np.isfinite(developed.variance), developed.variance, -1.0)
    channels = {
        "R": rgb[..., 0], "G": rgb[..., 1], "B": rgb[..., 2],
        "XYZ.X": xyz[..., 0], "XYZ.Y": xyz[..., 1], "XYZ.Z": xyz[..., 2],
        "Luminance.Y": developed.luminance,
        "Variance.Y": var,
    }
    for layer, arr, names in (("xyY", developed.xyY, "xyY"), ("Lab", developed.Lab, "Lab"),
                              ("Luv", developed.Luv, "Luv")):
        if arr is not None:
            for k, nm in enumerate(names):
                channels[f"{layer}.{nm}"] = arr[..., k]
    attrs = {
        "whiteLuminance": float(C.K_M),
        "chromaticities": tuple(float(v) for v in CHROMATICITIES[space]),
        "spectralgi.colourSpace": {"rec709": "linear Rec.709", "acescg": "ACEScg (AP1, linear)",
                                   "xyz": "CIE XYZ"}[space],
        "spectralgi.observer": {"1931": "CIE 1931 2 degree", "1964": "CIE 1964 10 degree"}[
            getattr(developed, "observer", "1931")],
        "software": "spectral-gi",
        "spectralgi.referenceWhite": f"CIE D65 (x={developed.white_xy[0]}, y={developed.white_xy[1]}), "
                                     f"{developed.white_luminance:g} cd/m^2 (L* = 100)",
        "spectralgi.units": "R,G,B,XYZ: relative, 1 = 683 cd/m^2; Luminance.Y, xyY.Y: cd/m^2; "
                            "Variance.Y: (cd/m^2)^2",
    }
    if spectral is not None:
        wls, rad = spectral
        for k, w in enumerate(wls):
            channels[spectral_channel_name(w)] = rad[..., k]
        attrs["spectralLayoutVersion"] = "1.0"
        attrs["emissiveUnits"] = "W.m^-2.sr^-1"
        attrs["polarisationHandedness"] = "right"
    attrs.update(attributes or {})
    return write_channels(path, channels, attrs)
