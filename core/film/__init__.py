"""The film: per-pixel sums of CIE XYZ, and its development into images.

The kernel adds, per sample, X, Y, Z (∫ L x̄ dλ etc., with L in W/(m² sr nm), so Y
times K_m is luminance in cd/m²), the sample count, and Y² for the variance estimate.
Development is NumPy, not kernels.

Observer: X, Y, Z use the colour-matching functions of the render's observer (CIE 1931
2°, the default, or CIE 1964 10°). Photometric quantities always use V(λ) = the 1931 ȳ:
with the 1964 observer the film has a sixth channel, the photometric Y (V-weighted), and
channel 4 holds its square (so luminance, its variance and the noise target do not depend
on the observer). With the 1931 observer channel 1 is both, and the film keeps 5 channels.

Colour output (``develop(colour_space=...)``): ``rec709`` (linear Rec.709, Blender's
scene-linear), ``acescg`` (ACES AP1 linear, ACES S-2014-004; D65-referred XYZ is adapted
to the ACES white with Bradford), ``xyz`` (the film's CIE XYZ unchanged).
"""
from dataclasses import dataclass

import numpy as np

from .. import constants as C
from ..colour import XYZ_to_Lab, XYZ_to_Luv, XYZ_to_RGB, XYZ_to_sRGB_linear, XYZ_to_xyY, chromatic_adaptation_Bradford
from ..colour.illuminants import CCS_ILLUMINANTS
from ..io.atomic import write_bytes

D65_XY = (0.3127, 0.3290)

# Colour outputs and observers (RenderSettings.colour_space / .observer).
COLOUR_SPACES = ("rec709", "acescg", "xyz")
OBSERVERS = ("1931", "1964")
PHOTOMETRIC_Y = 5  # film channel of the photometric Y when the observer is not CIE 1931
# OpenEXR ``chromaticities`` of each output: the CIE xy of the pixel values (1,0,0), (0,1,0),
# (0,0,1) and (1,1,1) (ImfChromaticities.h). ACEScg: AP1 and the ACES white (ACES
# S-2014-004); XYZ data: X=1 → (1, 0), Y=1 → (0, 1), Z=1 → (0, 0), X=Y=Z → (1/3, 1/3).
CHROMATICITIES = {
    "rec709": (0.64, 0.33, 0.30, 0.60, 0.15, 0.06, 0.3127, 0.3290),
    "acescg": (0.713, 0.293, 0.165, 0.830, 0.128, 0.044, 0.32168, 0.33767),
    "xyz": (1.0, 0.0, 0.0, 1.0, 0.0, 0.0, 1.0 / 3.0, 1.0 / 3.0),
}


def check_colour_space(colour_space):
    """The normalised name of an output colour space; ValueError naming the choices otherwise."""
    cs = str(colour_space).strip().lower()
    if cs not in COLOUR_SPACES:
        raise ValueError(f"colour space {colour_space!r}: expected one of {', '.join(COLOUR_SPACES)}")
    return cs


def check_observer(observer):
    """'1931' or '1964' (also accepts 2/10 and the colour-science names); ValueError otherwise."""
    o = str(observer).strip().lower()
    if o in ("1931", "2", "cie 1931 2 degree standard observer"):
        return "1931"
    if o in ("1964", "10", "cie 1964 10 degree standard observer"):
        return "1964"
    raise ValueError(f"observer {observer!r}: expected '1931' (CIE 1931 2°) or '1964' (CIE 1964 10°)")


def film_channels(observer="1931"):
    """Channels of a film for ``observer``: 5, plus the photometric Y for the 10° observer."""
    return C.FILM_CHANNELS + (0 if check_observer(observer) == "1931" else 1)


def photometric_y_sums(sums):
    """Per-pixel sums of the photometric (V(λ)-weighted) Y: channel 5 if present, else Y."""
    return sums[..., PHOTOMETRIC_Y] if sums.shape[-1] > PHOTOMETRIC_Y else sums[..., 1]


def d65_white_xy(observer="1931"):
    """xy of CIE D65 for ``observer`` (CIE 015:2018; 1931: the rounded (0.3127, 0.3290))."""

    return tuple(float(v) for v in CCS_ILLUMINANTS[check_observer(observer)]["D65"])


def _xy_to_XYZ(xy):
    return np.array([xy[0] / xy[1], 1.0, (1 - xy[0] - xy[1]) / xy[1]])


def XYZ_to_output(XYZ, colour_space="rec709", observer="1931"):
    """The film's XYZ (D65-referred, ``observer``) in an output colour space (see the module doc).

    rec709 and acescg are defined on CIE 1931 XYZ: 10° XYZ is first adapted (Bradford) from
    the 10° D65 white to the 2° one, so that a D65-white surface stays neutral (a convention:
    no matrix maps one observer's XYZ to the other's exactly). xyz returns XYZ unchanged.
    """

    cs = check_colour_space(colour_space)
    if cs == "xyz":
        return np.array(XYZ, dtype=np.float64, copy=True)
    if check_observer(observer) != "1931":
        XYZ = chromatic_adaptation_Bradford(XYZ, _xy_to_XYZ(d65_white_xy(observer)), _xy_to_XYZ(D65_XY))
    if cs == "rec709":
        return XYZ_to_sRGB_linear(XYZ)
    return XYZ_to_RGB(XYZ, "ACEScg", illuminant=np.array(D65_XY), chromatic_adaptation_transform="Bradford")


AOV_CHANNELS = 9  # albedo XYZ, normal xyz, depth sum, number of samples that hit, transparent samples
FILM_FORMAT = "spectral-gi-film"
# 2: the AOVs gained the transparent-sample count (version 1 films load as opaque); 3: the
# samples of an incomplete chunk are stored apart (``tail_*``)
FILM_VERSION = 3
# Samples per chunk: the image is the sum, in order, of the sums of chunks of CHUNK_SPP samples
# (see :class:`Film`). Part of the definition of an image: changing it changes the last bits.
CHUNK_SPP = 16


def chunk_spans(s0, s1, chunk=CHUNK_SPP):
    """The pieces [a, b) of the samples [s0, s1), cut at the multiples of ``chunk``."""
    out = []
    a = int(s0)
    while a < s1:
        b = min(int(s1), (a // chunk + 1) * chunk)
        out.append((a, b))
        a = b
    return out


class Film:
    """Per-pixel sums. ``spectral_bins`` > 0 also keeps the spectral radiance in that many
    equal bins of [LAMBDA_MIN, LAMBDA_MAX] (for spectral OpenEXR output). ``aov`` holds
    the sums of the albedo, normal and depth passes (see :func:`develop`).

    The order of the additions: floating-point addition is not associative, so the image
    is defined by the order its samples are summed in. The samples of a pixel are grouped
    in chunks of CHUNK_SPP consecutive sample indices (aligned on multiples of CHUNK_SPP);
    the samples of a chunk are summed one by one from zero, and the chunk sums are added
    to the image in chunk order (the first one taken as it is). Renders on one machine and
    on a farm (one task per chunk, merged in chunk order) give the same bits, whatever the
    pass lengths, threads or workers. While the last chunk is incomplete the film holds it
    apart (``open_chunk``) from the whole chunks before it; ``sums``, ``spectral`` and
    ``aov`` are then the two added, formed when first read after a change (memory: up to
    three copies of the arrays mid-chunk)."""

    def __init__(self, width, height, spectral_bins=0, observer="1931"):
        self.width = int(width)
        self.height = int(height)
        self.observer = check_observer(observer)
        n = int(spectral_bins)
        # the whole chunks: samples [0, spp - tail_spp)
        self._sums = np.zeros((self.height, self.width, film_channels(self.observer)), dtype=np.float64)
        self._spectral = np.zeros((self.height, self.width, n) if n > 0 else (1, 1, 0), dtype=np.float64)
        self._aov = np.zeros((self.height, self.width, AOV_CHANNELS), dtype=np.float64)
        self._tail = None  # a Film: the incomplete chunk's samples [spp - tail_spp, spp), summed from zero
        self.tail_spp = 0
        self._view = None  # (sums, spectral, aov) of the whole chunks plus the tail, once formed
        self._spare = None  # a tail's arrays kept for the next chunk
        self.spp = 0
        # samples of the spp × pixels that adaptive sampling did not take (pixels that had
        # converged: core/integrators/render.py adaptive_mask); each pixel's count is sums[..., 3]
        self.skipped_samples = 0

    # ------------------------------------------------------------------ the image's arrays

    def _image(self):
        if self._tail is None:
            return self._sums, self._spectral, self._aov
        t = self._tail
        if self.spp == self.tail_spp:  # no whole chunk yet: the chunk's sums are the image
            return t._sums, t._spectral, t._aov
        if self._view is None:
            self._view = (np.add(self._sums, t._sums), np.add(self._spectral, t._spectral),
                          np.add(self._aov, t._aov))
        return self._view

    def _plain(self):
        """Make the film one set of arrays (its image), dropping the chunk structure."""
        if self._tail is not None:
            self._sums, self._spectral, self._aov = (a.copy() for a in self._image())
            self._tail = self._view = None
            self.tail_spp = 0

    @property
    def sums(self):
        return self._image()[0]

    @sums.setter
    def sums(self, value):
        self._plain()
        self._sums = value

    @property
    def spectral(self):
        return self._image()[1]

    @spectral.setter
    def spectral(self, value):
        self._plain()
        self._spectral = value

    @property
    def aov(self):
        return self._image()[2]

    @aov.setter
    def aov(self, value):
        self._plain()
        self._aov = value

    # ------------------------------------------------------------------ accumulation

    @property
    def chunk_start(self):
        """The first sample of the incomplete chunk (spp at a chunk boundary)."""
        return self.spp - self.tail_spp

    def dropped_samples(self):
        """How many of the samples taken (spp × pixels, less the ``skipped_samples`` of adaptive
        sampling) the film does not hold: the path kernel leaves out a sample that is not finite
        (NaN or Inf, which validated input cannot produce)."""
        taken = self.spp * self.width * self.height - self.skipped_samples
        return int(round(taken - float(self.sums[..., 3].sum())))

    def _blank(self):
        f = Film(self.width, self.height, self.spectral_bins, observer=self.observer)
        return f

    def open_chunk(self):
        """The film that the next samples [spp, ...) of the current chunk are added to, from
        the kernel: the incomplete chunk, or a zero film at a chunk boundary. Hand it back to
        :meth:`merge_chunk` once samples were added."""
        self._view = None
        if self._tail is None:
            spare, self._spare = self._spare, None
            if spare is None:
                spare = self._blank()
            else:
                for a in (spare._sums, spare._spectral, spare._aov):
                    a.fill(0.0)
            spare.spp = 0
            return spare
        return self._tail

    def merge_chunk(self, part, end):
        """Take ``part``, the sums from zero of the samples [chunk_start, end) of one chunk
        (from :meth:`open_chunk`, or a farm task's result), as this film's current chunk; a
        chunk that is complete (end on a multiple of CHUNK_SPP) is added to the whole chunks."""
        end = int(end)
        start = self.chunk_start
        if not start < end <= (start // CHUNK_SPP + 1) * CHUNK_SPP:
            raise ValueError(f"film: samples [{start}, {end}) are not part of one chunk")
        if part.width != self.width or part.height != self.height or part._sums.shape != self._sums.shape \
                or part._spectral.shape != self._spectral.shape:
            raise ValueError("film: the chunk's arrays do not match the film's")
        self._view = None
        if end % CHUNK_SPP:
            self._tail, self.tail_spp, self.spp = part, end - start, end
            return
        if start == 0:  # the first chunk is the image
            self._sums, self._spectral, self._aov = part._sums, part._spectral, part._aov
        else:
            np.add(self._sums, part._sums, out=self._sums)
            np.add(self._spectral, part._spectral, out=self._spectral)
            np.add(self._aov, part._aov, out=self._aov)
            self._spare = part
        self._tail = None
        self.tail_spp = 0
        self.spp = end

    # ------------------------------------------------------------------

    @property
    def spectral_bins(self):
        return self._spectral.shape[2]

    def bin_centres(self):
        """Centre wavelength (nm) of each spectral bin."""
        n = self.spectral_bins
        w = (C.LAMBDA_MAX - C.LAMBDA_MIN) / max(n, 1)
        return C.LAMBDA_MIN + w * (np.arange(n) + 0.5)

    def spectral_radiance(self):
        """(H, W, B) mean spectral radiance per bin, W/(m² sr nm)."""
        n = np.maximum(self.sums[..., 3], 1.0)
        return self.spectral / n[..., None]

    def copy(self):
        f = Film(self.width, self.height, observer=self.observer)
        f._sums = self._sums.copy()
        f._spectral = self._spectral.copy()
        f._aov = self._aov.copy()
        f.spp = self.spp
        f.skipped_samples = self.skipped_samples
        if self._tail is not None:
            f._tail = self._tail.copy()
            f.tail_spp = self.tail_spp
        return f

    def develop(self, white_luminance=C.K_M, white_balance=None, colour_space="rec709"):
        return develop(self.sums, white_luminance, white_balance, aov=self.aov, colour_space=colour_space,
                       observer=self.observer)

    def save(self, path):
        """Write the film (a checkpoint to resume from) as one .npz, atomically: ``sums``,
        ``spectral`` and ``aov`` hold the whole chunks, ``tail_*`` an incomplete chunk's sums."""
        import io
        from pathlib import Path

        buf = io.BytesIO()
        tail = {}
        if self._tail is not None:
            tail = {"tail_spp": np.array(self.tail_spp, np.int64), "tail_sums": self._tail._sums,
                    "tail_spectral": self._tail._spectral, "tail_aov": self._tail._aov}
        np.savez_compressed(buf, format=np.array(FILM_FORMAT), version=np.array(FILM_VERSION),
                            spp=np.array(self.spp, np.int64), observer=np.array(self.observer), sums=self._sums,
                            spectral=self._spectral, aov=self._aov,
                            skipped=np.array(self.skipped_samples, np.int64), **tail)
        write_bytes(Path(path), buf.getvalue())
        return Path(path)

    @classmethod
    def load(cls, path):
        """Read a film written by :meth:`save`; ValueError naming the problem otherwise.

        A checkpoint is validated as a scene is: each member has one type and shape (sums
        (H, W, channels of its observer), aov (H, W, 9), spectral (1, 1, 0) or (H, W, B)
        with 1 ≤ B ≤ MAX_SPECTRAL_BINS, all float64 and finite; spp an integer), its
        resolution is at most 65536² and members are read only when needed, within the
        size their header declares (core/io/npz.py)."""
        from ..io.npz import NpzError, NpzReader

        def bad(problem):
            return ValueError(f"film {path}: {problem}")

        try:
            with NpzReader(path) as z:
                def get(key):
                    if key not in z:
                        raise bad(f"{key}: missing")
                    return z.get(key)

                fmt = _npz_text(z, "format")
                version = get("version")
                if fmt != FILM_FORMAT or version.shape != () or version.dtype.kind not in "iu" or \
                        int(version) not in (1, 2, FILM_VERSION):
                    raise bad(f"not a spectral-gi film of version 1 to {FILM_VERSION}")
                version = int(version)
                observer = _npz_text(z, "observer") if "observer" in z else "1931"  # older films: CIE 1931
                try:
                    observer = check_observer(observer)
                except ValueError as e:
                    raise bad(str(e)) from None
                spp = get("spp")
                if spp.shape != () or spp.dtype.kind not in "iu" or not 0 <= int(spp) <= MAX_SPP:
                    got = f"{spp.item()!r}" if spp.shape == () and spp.dtype.kind in "biuf" else \
                        f"an array of shape {spp.shape} and dtype {spp.dtype}"
                    raise bad(f"spp: expected an integer in [0, {MAX_SPP}], got {got}")
                sums = get("sums")
                _check_film_array(bad, "sums", sums, (None, None, film_channels(observer)))
                h, w = sums.shape[:2]
                if not (1 <= h <= MAX_RESOLUTION and 1 <= w <= MAX_RESOLUTION):
                    raise bad(f"sums: a {w}x{h} film (each side 1 to {MAX_RESOLUTION})")
                aov = get("aov")
                if version == 1 and aov.ndim == 3 and aov.shape[2] == AOV_CHANNELS - 1:
                    aov = np.concatenate([aov, np.zeros(aov.shape[:2] + (1,))], axis=2)  # no transparent samples
                _check_film_array(bad, "aov", aov, (h, w, AOV_CHANNELS))
                spectral = get("spectral")
                if spectral.shape != (1, 1, 0):
                    _check_film_array(bad, "spectral", spectral, (h, w, None))
                    if not 1 <= spectral.shape[2] <= MAX_SPECTRAL_BINS:
                        raise bad(f"spectral: {spectral.shape[2]} bins (1 to {MAX_SPECTRAL_BINS})")
                elif spectral.dtype != np.float64:
                    raise bad(f"spectral: expected float64, got {spectral.dtype}")
                skipped = 0
                if "skipped" in z:  # samples adaptive sampling did not take (absent: none)
                    k = get("skipped")
                    if k.shape != () or k.dtype.kind not in "iu" or not 0 <= int(k) <= int(spp) * h * w:
                        raise bad("skipped: expected an integer in [0, spp × pixels]")
                    skipped = int(k)
                tail = None
                if "tail_sums" in z:  # the incomplete chunk, summed apart (see the class)
                    n = get("tail_spp")
                    if n.shape != () or n.dtype.kind not in "iu" or not 0 < int(n) <= min(int(spp), CHUNK_SPP):
                        raise bad(f"tail_spp: expected an integer in [1, min(spp, {CHUNK_SPP})]")
                    tail = [int(n)]
                    for key, a in (("tail_sums", sums), ("tail_spectral", spectral), ("tail_aov", aov)):
                        t = get(key)
                        _check_film_array(bad, key, t, a.shape)
                        tail.append(t)
        except NpzError as e:
            raise bad(str(e)) from None
        def film(arrays):
            g = cls(1, 1, observer=observer)  # arrays of its own replaced below: no allocation at full size
            g.width, g.height = int(w), int(h)
            g._sums, g._spectral, g._aov = (np.ascontiguousarray(x, np.float64) for x in arrays)
            return g

        f = film((sums, spectral, aov))
        f.spp = int(spp)
        f.skipped_samples = skipped
        if tail is not None:
            f._tail, f.tail_spp = film(tail[1:]), tail[0]
        return f


MAX_SPP = 1 << 24  # as RenderSettings.spp
MAX_RESOLUTION = 65536  # pixels a side, as Camera.width / height
MAX_SPECTRAL_BINS = C.N_LAMBDA  # one bin per nanometre of the renderer's grid


def _npz_text(z, key):
    """A string member (format, observer) of a film archive, or '' when it is not one."""
    if key not in z:
        return ""
    from ..io.npz import NpzError

    try:
        with z.zf.open(z.names[key]) as fh:
            version = np.lib.format.read_magic(fh)
            shape, _, dtype = (np.lib.format.read_array_header_1_0(fh) if version == (1, 0)
                               else np.lib.format.read_array_header_2_0(fh))
            if dtype.kind != "U" or shape != () or dtype.itemsize > 4 * 64:
                return ""
            return np.frombuffer(fh.read(dtype.itemsize), dtype=dtype, count=1)[0].item()
    except (NpzError, ValueError, OSError, EOFError) as e:
        raise NpzError(f"member {key!r}: cannot read ({e})") from None
    except Exception as e:  # zlib.error, zipfile.BadZipFile
        raise NpzError(f"member {key!r}: cannot read ({type(e).__name__}: {e})") from None


def _check_film_array(bad, name, a, shape):
    if a.dtype != np.float64:
        raise bad(f"{name}: expected float64, got {a.dtype}")
    if a.ndim != len(shape) or any(s is not None and s != d for s, d in zip(shape, a.shape)):
        want = "(" + ", ".join("N" if s is None else str(s) for s in shape) + ")"
        raise bad(f"{name}: expected shape {want}, got {a.shape}")
    if not np.all(np.isfinite(a)):
        raise bad(f"{name}: contains NaN or Inf")


def check_film(film, width, height, observer, where="film"):
    """Raise ValueError unless ``film`` is a Film whose arrays the path kernel may add to for a
    ``width`` × ``height`` render with ``observer`` (shapes, dtypes, contiguity)."""
    if not isinstance(film, Film):
        raise ValueError(f"{where}: expected a Film, got {type(film).__name__}")
    if (film.width, film.height) != (width, height):
        raise ValueError(f"{where}: the film is {film.width}x{film.height}, the scene renders {width}x{height}")
    if film.observer != observer:
        raise ValueError(f"{where}: the film was rendered with the CIE {film.observer} observer, the scene asks "
                         f"for {observer}")
    for name, a, shape in (("sums", film.sums, (height, width, film_channels(observer))),
                           ("aov", film.aov, (height, width, AOV_CHANNELS))):
        if not isinstance(a, np.ndarray) or a.dtype != np.float64 or a.shape != shape or not a.flags.c_contiguous:
            raise ValueError(f"{where}: {name} must be a C-contiguous float64 array of shape {shape}")
    sp = film.spectral
    if not isinstance(sp, np.ndarray) or sp.dtype != np.float64 or sp.ndim != 3 or not sp.flags.c_contiguous or \
            not (sp.shape == (1, 1, 0) or (sp.shape[:2] == (height, width) and 1 <= sp.shape[2] <= MAX_SPECTRAL_BINS)):
        raise ValueError(f"{where}: spectral must be a C-contiguous float64 array of shape (1, 1, 0) or "
                         f"({height}, {width}, B) with 1 ≤ B ≤ {MAX_SPECTRAL_BINS}")
    if isinstance(film.spp, bool) or not isinstance(film.spp, (int, np.integer)) or not 0 <= film.spp <= MAX_SPP:
        raise ValueError(f"{where}: spp must be an integer in [0, {MAX_SPP}], got {film.spp!r}")


@dataclass
class Developed:
    XYZ: np.ndarray  # (H, W, 3) mean CIE XYZ per pixel; Y = 1 is 683 cd/m²
    rgb: np.ndarray  # (H, W, 3) linear Rec.709 (Blender's scene-linear), same scale as XYZ
    luminance: np.ndarray  # (H, W) cd/m²
    variance: np.ndarray  # (H, W) variance of the pixel's mean luminance, (cd/m²)²
    count: np.ndarray  # (H, W) samples per pixel
    xyY: np.ndarray = None  # (H, W, 3) chromaticity x, y and luminance Y in cd/m²
    Lab: np.ndarray = None  # (H, W, 3) CIE L*a*b* against the reference white below
    Luv: np.ndarray = None  # (H, W, 3) CIE L*u*v* against the reference white below
    white_luminance: float = C.K_M  # cd/m² of the reference white (L* = 100)
    white_xy: tuple = D65_XY  # chromaticity of the reference white
    albedo: np.ndarray = None  # (H, W, 3) linear Rec.709 reflectance of the first non-delta hit (under D65)
    normal: np.ndarray = None  # (H, W, 3) mean world shading normal of the first hit, facing the camera
    depth: np.ndarray = None  # (H, W) mean camera-ray distance to the first hit (m), inf where nothing was hit
    # (H, W) film alpha: the fraction of samples not left transparent (holdout, transparent film)
    alpha: np.ndarray = None
    output: np.ndarray = None  # (H, W, 3) the image in ``colour_space`` (white-balanced as rgb, except xyz)
    colour_space: str = "rec709"  # 'rec709', 'acescg' or 'xyz' (see core.film)
    observer: str = "1931"  # CIE observer of XYZ (and of xyY, Lab, Luv): '1931' (2°) or '1964' (10°)


def develop(sums, white_luminance=C.K_M, white_balance=None, aov=None, colour_space="rec709", observer=None):
    """Turn film sums into images.

    white_luminance: luminance (cd/m²) of the white that L* = 100 refers to; the default
    683 cd/m² is Blender's RGB (1, 1, 1). The reference white's chromaticity is D65.
    white_balance: None, or the xy chromaticity of the scene's light: then ``rgb`` (and
    only ``rgb``) is adapted from that white to D65 with Bradford's transform, as a
    camera's white balance would; XYZ, xyY, Lab and Luv stay unadapted.
    aov: the film's AOV sums (Film.aov); then ``albedo``, ``normal`` (sums over the sample
    count), ``depth`` (over the samples that hit; inf if none did) and ``alpha`` (1 minus
    the fraction of samples that saw a holdout or, with a transparent film, nothing; 0
    where the pixel has no samples) are filled in. ``XYZ``/``rgb`` are then premultiplied
    by alpha, as Blender's Combined pass: transparent samples carry no radiance.
    colour_space: 'rec709' (default), 'acescg' or 'xyz': the space of ``output`` (``rgb``
    is always linear Rec.709, what Blender displays).
    observer: the film's CIE observer ('1931' or '1964'; None: 1931 for a 5-channel film,
    1964 for a 6-channel one). XYZ, xyY, Lab and Luv are the observer's, against its D65
    white; luminance and variance are photometric (V(λ)) whatever the observer.
    """
    if observer is None:
        observer = "1931" if sums.shape[-1] <= PHOTOMETRIC_Y else "1964"
    observer = check_observer(observer)
    colour_space = check_colour_space(colour_space)
    if sums.shape[-1] != film_channels(observer):
        raise ValueError(f"film sums with {sums.shape[-1]} channels do not match the {observer} observer")
    white_xy = D65_XY if observer == "1931" else d65_white_xy(observer)
    n = sums[..., 3]
    safe = np.maximum(n, 1.0)
    XYZ = sums[..., :3] / safe[..., None]
    XYZ[n == 0] = 0.0
    mean_y = photometric_y_sums(sums) / safe
    mean_y = np.where(n == 0, 0.0, mean_y)
    mean_y2 = sums[..., 4] / safe
    var_sample = np.maximum(mean_y2 - mean_y * mean_y, 0.0) * safe / np.maximum(safe - 1.0, 1.0)
    variance = (C.K_M ** 2) * var_sample / safe
    variance[n < 2] = np.inf
    rgb_xyz = XYZ
    d65 = _xy_to_XYZ(white_xy)
    if white_balance is not None:
        wx, wy = float(white_balance[0]), float(white_balance[1])
        src = np.array([wx / wy, 1.0, (1 - wx - wy) / wy])
        rgb_xyz = chromatic_adaptation_Bradford(XYZ, src, d65)
    scale = C.K_M / float(white_luminance)  # film units → units of the reference white
    xyY = XYZ_to_xyY(XYZ, illuminant=np.array(white_xy))
    xyY[..., 2] *= C.K_M
    albedo = normal = depth = alpha = None
    if aov is not None:
        albedo = XYZ_to_output(aov[..., 0:3] / safe[..., None], "rec709", observer)
        albedo[n == 0] = 0.0
        normal = aov[..., 3:6] / safe[..., None]
        hits = aov[..., 7]
        depth = np.full(hits.shape, np.inf)
        np.divide(aov[..., 6], hits, out=depth, where=hits > 0)
        if aov.shape[2] > 8:
            alpha = np.where(n > 0, 1.0 - aov[..., 8] / safe, 0.0)
    rgb = XYZ_to_output(rgb_xyz, "rec709", observer)
    if colour_space == "rec709":
        output = rgb
    else:
        output = XYZ_to_output(XYZ if colour_space == "xyz" else rgb_xyz, colour_space, observer)
    return Developed(XYZ=XYZ, rgb=rgb, luminance=C.K_M * mean_y,
                     variance=variance, count=n.copy(), xyY=xyY,
                     Lab=XYZ_to_Lab(XYZ * scale, np.array(white_xy)), Luv=XYZ_to_Luv(XYZ * scale, np.array(white_xy)),
                     white_luminance=float(white_luminance), white_xy=white_xy, albedo=albedo, normal=normal,
                     depth=depth, alpha=alpha, output=output, colour_space=colour_space, observer=observer)
