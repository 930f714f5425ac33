"""Photometric (goniometric) light profiles: IES LM-63 and EULUMDAT files → :class:`core.scene.Profile`.

Both formats tabulate a luminaire's luminous intensity I(θ, C) in candela in type C
photometry: θ (IES "vertical angle", EULUMDAT γ) from the nadir, the luminaire's
downward axis, and C (IES "horizontal angle") around it. A profile keeps the table as
given, with its C symmetry expanded to the full 0–360°; the renderer reads it bilinearly
in (θ, C) and gives 0 outside the tabulated θ range (a 0–90° file lights the lower
hemisphere only). The frame a light puts it in is documented on :class:`Profile`.

IES LM-63 (-1986, -1991, -1995, -2002, -2019): keyword lines, ``TILT=NONE`` (TILT=INCLUDE
or a tilt file is rejected: lamp-tilt tables are not supported), then the numbers: lamps,
lumens per lamp (-1: absolute photometry), candela multiplier, counts of vertical and
horizontal angles, photometric type (only 1, type C, is accepted), units, the three
dimensions, ballast factor, a fifth number (LM-63-1995 and older: the ballast-lamp
photometric factor, applied; -2002: "future use"; -2019: the file generation type; both
ignored), input watts, the angles and the candela values, one run of vertical values per
horizontal angle. Vertical angles run 0–90, 0–180 or 90–180; horizontal ones are a single
0 (rotationally symmetric), 0–90 (symmetric in each quadrant), 0–180 (symmetric about the
C0–C180 plane), 90–270 (symmetric about the C90–C270 plane) or 0–360. The candela values
are multiplied by the multiplier and the ballast factor.

EULUMDAT (.ldt): the line-based format of the German lighting industry. Fields 1–26f
(header, symmetry indicator Isym, the counts Mc and Ng of C planes and γ angles,
conversion factor CFLI, lamp sets with their number of lamps and total flux), 10 direct
ratios, the Mc C angles, the Ng γ angles, then the intensities in cd per 1000 lm of lamp
flux for the planes the symmetry needs: Isym 0 all Mc planes, 1 one plane (rotational
symmetry), 2 the planes 0–180°, 3 the planes 90–270°, 4 the planes 0–90°. Candela =
value × CFLI × Φ / 1000 with Φ the lamp flux: the sum over lamp sets of field 26c,
which EULUMDAT defines as the *total* luminous flux of the set's lamps (so it is not
multiplied again by field 26a, the number of lamps). A negative number of lamps marks
absolute photometry in some files; the values are then taken as candela as they stand
(times CFLI).

Errors: :class:`PhotometricError` (a ValueError) naming the file and the problem.
"""
from __future__ import annotations

import math
import re
from pathlib import Path

import numpy as np
from ..scene import Profile
from ..scene.checks import MAX_PHOTOMETRIC
from ..io.strict import is_number_text
from ..io.presets import PRESETS_DIR

PROFILE_SUFFIXES = (".ies", ".ldt")


class PhotometricError(ValueError):
    """A photometric file is malformed or unsupported; the message names the file and the problem."""


def _fail(path, problem):
    raise PhotometricError(f"{path}: {problem}")


MAX_FILE_BYTES = 1 << 24  # 16 MiB: far above any photometric file


def _read_text(path):
    path = Path(path)
    if not path.is_file():
        _fail(path, "no such file")
    try:
        if path.stat().st_size > MAX_FILE_BYTES:
            _fail(path, f"{path.stat().st_size} bytes, more than a photometric file holds ({MAX_FILE_BYTES})")
        data = path.read_bytes()
    except OSError as e:
        _fail(path, f"cannot read ({e.strerror or e})")
    try:
        return data.decode("utf-8-sig")
    except UnicodeDecodeError:
        return data.decode("latin-1")  # older files carry Windows code-page text in their keywords


def _number(path, tok, what):
    if not is_number_text(tok):
        _fail(path, f"{what}: {tok[:40]!r} is not a number")
    v = float(tok)
    if not math.isfinite(v):
        _fail(path, f"{what}: {tok!r} is not a finite number")
    return v


# --------------------------------------------------------------------------- symmetry

def expand_symmetry(path, c_angles, rows):
    """(phi, table) covering C = 0 … 360 from the planes a file gives.

    ``c_angles`` (degrees, ascending) and ``rows`` (one intensity row per plane) as read.
    """
    c = np.asarray(c_angles, dtype=np.float64)
    rows = np.asarray(rows, dtype=np.float64)
    if c.size == 0:
        _fail(path, "no C (horizontal) angles")
    if np.any(np.diff(c) <= 0):
        _fail(path, "C (horizontal) angles are not strictly increasing")
    first, last = float(c[0]), float(c[-1])
    if c.size == 1:
        if first != 0.0:
            _fail(path, f"a single C plane must be at 0°, got {first:g}°")
        return np.array([0.0, 360.0]), np.stack([rows[0], rows[0]])
    if first == 0.0 and last == 90.0:  # one quadrant: mirror about C90, then about C180
        c, rows = np.concatenate([c, 180.0 - c[-2::-1]]), np.concatenate([rows, rows[-2::-1]])
        first, last = 0.0, 180.0
    if first == 0.0 and last == 180.0:  # mirror about the C0–C180 plane
        return np.concatenate([c, 360.0 - c[-2::-1]]), np.concatenate([rows, rows[-2::-1]])
    if first == 90.0 and last == 270.0:  # mirror about the C90–C270 plane: I(C) = I(180° − C)
        full_c = np.concatenate([180.0 - c[:0:-1], c])  # −90 … 270
        full_rows = np.concatenate([rows[:0:-1], rows])
        neg = full_c < 0.0
        # C < 0 is C + 360; −90 is 270, given already
        c2 = np.concatenate([full_c[~neg], full_c[neg][1:] + 360.0])
        r2 = np.concatenate([full_rows[~neg], full_rows[neg][1:]])
        row0 = np.array([np.interp(0.0, full_c, full_rows[:, k]) for k in range(rows.shape[1])])
        if c2[0] != 0.0:  # C0 falls between two planes: interpolate it
            c2 = np.concatenate([[0.0], c2])
            r2 = np.concatenate([[row0], r2])
        return np.concatenate([c2, [360.0]]), np.concatenate([r2, [row0]])
    if first == 0.0 and last == 360.0:
        return c, rows
    if first == 0.0 and last < 360.0 and math.isclose(360.0 - last, float(c[1] - c[0])):
        # the full circle without the repeated 360° plane
        return np.concatenate([c, [360.0]]), np.concatenate([rows, rows[:1]])
    _fail(path, f"C (horizontal) angles {first:g}°–{last:g}° are not a supported symmetry "
                "(0, 0–90, 0–180, 90–270 or 0–360)")


def _check_theta(path, theta):
    t = np.asarray(theta, dtype=np.float64)
    if t.size < 2:
        _fail(path, "needs at least two vertical (γ) angles")
    if np.any(np.diff(t) <= 0):
        _fail(path, "vertical (γ) angles are not strictly increasing")
    if t[0] < 0.0 or t[-1] > 180.0:
        _fail(path, f"vertical (γ) angles {t[0]:g}°–{t[-1]:g}° leave 0–180°")
    return t


def _check_candela(path, table):
    if not np.all(np.isfinite(table)):
        _fail(path, "candela values contain NaN or Inf (after the file's multipliers)")
    if table.size and table.min() < 0.0:
        _fail(path, f"negative candela value {table.min():g}")
    if table.size and table.max() > MAX_PHOTOMETRIC:
        _fail(path, f"a luminous intensity of {table.max():.3g} cd (after the file's multipliers; at most "
                    f"{MAX_PHOTOMETRIC:g})")
    return table


# --------------------------------------------------------------------------- IES LM-63

_NUM_SPLIT = re.compile(r"[\s,]+")


def read_ies(path):
    """Parse an IES LM-63 file: returns a dict with theta, phi (expanded), candela and metadata."""
    path = Path(path)
    text = _read_text(path)
    lines = text.replace("\r\n", "\n").replace("\r", "\n").split("\n")
    if not lines or not lines[0].strip():
        _fail(path, "empty file (not an IES LM-63 file)")
    head = lines[0].strip().upper()
    version = "LM-63-1986"
    if head.startswith("IESNA:LM-63-1995"):
        version = "LM-63-1995"
    elif head.startswith("IESNA:LM-63-2002"):
        version = "LM-63-2002"
    elif head.startswith("IES:LM-63-2019") or head.startswith("IESNA:LM-63-2019"):
        version = "LM-63-2019"
    elif head.startswith("IESNA91"):
        version = "LM-63-1991"
    elif head.startswith("IES"):
        version = head.split()[0]
    keywords = {}
    tilt_at = None
    for k, ln in enumerate(lines):
        s = ln.strip()
        if s.upper().startswith("TILT"):
            tilt_at = k
            break
        m = re.match(r"\[([^\]]+)\]\s*(.*)", s)
        if m:
            keywords.setdefault(m.group(1).upper(), m.group(2))
    if tilt_at is None:
        _fail(path, "no TILT= line (not an IES LM-63 file)")
    tilt = lines[tilt_at].strip()[4:].lstrip(" =").strip()
    if tilt.upper() != "NONE":
        _fail(path, f"TILT={tilt} is not supported (only TILT=NONE: lamp-tilt tables are not read)")
    toks = [t for t in _NUM_SPLIT.split(" ".join(lines[tilt_at + 1:])) if t]
    pos = [0]

    def take(what):
        if pos[0] >= len(toks):
            _fail(path, f"truncated: {what} missing")
        v = _number(path, toks[pos[0]], what)
        pos[0] += 1
        return v

    n_lamps = take("number of lamps")
    lumens = take("lumens per lamp")
    multiplier = take("candela multiplier")
    n_v = take("number of vertical angles")
    n_h = take("number of horizontal angles")
    ptype = take("photometric type")
    take("units type")
    for what in ("width", "length", "height"):
        take(what)
    ballast = take("ballast factor")
    fifth = take("ballast-lamp factor / file generation type")
    watts = take("input watts")
    for what, n in (("number of vertical angles", n_v), ("number of horizontal angles", n_h)):
        if n != int(n) or n < 1:
            _fail(path, f"{what} must be a positive integer, got {n:g}")
    n_v, n_h = int(n_v), int(n_h)
    if ptype != 1:
        name = {2: "B", 3: "A"}.get(int(ptype), str(ptype))
        _fail(path, f"photometric type {name} is not supported (only type C, 1)")
    theta = np.array([take(f"vertical angle {i + 1} of {n_v}") for i in range(n_v)])
    c = np.array([take(f"horizontal angle {i + 1} of {n_h}") for i in range(n_h)])
    vals = np.array([take(f"candela value {i + 1} of {n_h * n_v}") for i in range(n_h * n_v)])
    if pos[0] < len(toks):
        _fail(path, f"{len(toks) - pos[0]} numbers more than the {n_v} × {n_h} candela values announced")
    theta = _check_theta(path, theta)
    if not (theta[0] in (0.0, 90.0) and theta[-1] in (90.0, 180.0)):
        _fail(path, "vertical angles must run 0–90, 0–180 or 90–180 degrees (type C), "
                    f"got {theta[0]:g}–{theta[-1]:g}")
    factor = multiplier * ballast * (fifth if version in ("LM-63-1986", "LM-63-1991", "LM-63-1995") else 1.0)
    if not factor > 0.0:
        _fail(path, f"candela multiplier × ballast factor must be positive, got {factor:g}")
    with np.errstate(over="ignore", invalid="ignore"):
        table = _check_candela(path, vals.reshape(n_h, n_v)) * factor
    table = _check_candela(path, table)
    if not math.isfinite(lumens * n_lamps):
        _fail(path, "the lamps' luminous flux (lumens per lamp × number of lamps) overflows")
    phi, table = expand_symmetry(path, c, table)
    return {"format": "IES " + version, "theta": theta, "phi": phi, "candela": _check_candela(path, table),
            "lamp_lumens": None if lumens < 0 else lumens * n_lamps, "absolute": lumens < 0,
            "watts": watts, "keywords": keywords}


# --------------------------------------------------------------------------- EULUMDAT

def read_ldt(path):
    """Parse a EULUMDAT file: returns a dict with theta, phi (expanded), candela and metadata."""
    path = Path(path)
    text = _read_text(path)
    lines = [ln.strip() for ln in text.replace("\r\n", "\n").replace("\r", "\n").split("\n")]
    while lines and lines[-1] == "":
        lines.pop()
    pos = [0]

    def line(what):
        if pos[0] >= len(lines):
            _fail(path, f"truncated: {what} missing (line {pos[0] + 1})")
        s = lines[pos[0]]
        pos[0] += 1
        return s

    def num(what):
        k = pos[0] + 1
        s = line(what)
        t = s.replace(",", ".")
        if not is_number_text(t):
            _fail(path, f"line {k}, {what}: {s[:40]!r} is not a number")
        v = float(t)
        if not math.isfinite(v):
            _fail(path, f"line {k}, {what}: {s!r} is not a finite number")
        return v

    def count(what, lo=0):
        v = num(what)
        if v != int(v) or v < lo:
            _fail(path, f"line {pos[0]}, {what}: expected a whole number ≥ {lo}, got {v:g}")
        return int(v)

    company = line("company identification")
    count("type indicator Ityp")
    isym = count("symmetry indicator Isym")
    if isym > 4:
        _fail(path, f"line 3, symmetry indicator Isym must be 0–4, got {isym}")
    mc = count("number of C planes Mc", 1)
    num("distance between C planes Dc")
    ng = count("number of intensities per C plane Ng", 2)
    num("distance between intensities Dg")
    for what in ("measurement report", "luminaire name", "luminaire number", "file name", "date/user"):
        line(what)
    for what in ("luminaire length", "luminaire width", "luminaire height", "luminous area length",
                 "luminous area width", "luminous area height C0", "luminous area height C90",
                 "luminous area height C180", "luminous area height C270", "downward flux fraction",
                 "light output ratio"):
        num(what)
    cfli = num("conversion factor CFLI")
    num("tilt of luminaire")
    n_sets = count("number of standard sets of lamps", 1)
    flux = 0.0
    absolute = False
    for k in range(n_sets):
        n_l = num(f"lamp set {k + 1}: number of lamps")
        line(f"lamp set {k + 1}: type of lamps")
        f = num(f"lamp set {k + 1}: total luminous flux")
        line(f"lamp set {k + 1}: colour")
        line(f"lamp set {k + 1}: colour rendering")
        num(f"lamp set {k + 1}: wattage")
        if n_l < 0:
            absolute = True
        flux += f
    for k in range(10):
        num(f"direct ratio {k + 1}")
    c = np.array([num(f"C angle {i + 1} of {mc}") for i in range(mc)])
    theta = np.array([num(f"γ angle {i + 1} of {ng}") for i in range(ng)])
    if np.any(np.diff(c) <= 0) or c[0] != 0.0 or c[-1] >= 360.0:
        _fail(path, "C angles must increase from 0 to below 360 degrees")
    theta = _check_theta(path, theta)
    sel = {0: (c >= 0.0), 1: (c == 0.0), 2: (c <= 180.0), 3: (c >= 90.0) & (c <= 270.0), 4: (c <= 90.0)}[isym]
    planes = c[sel]
    want = {0: mc, 1: 1, 2: mc // 2 + 1, 3: mc // 2 + 1, 4: mc // 4 + 1}[isym]
    if planes.size != want:
        _fail(path, f"symmetry Isym={isym} needs {want} C planes among the C angles, found {planes.size}")
    n_vals = planes.size * ng
    vals = np.array([num(f"intensity {i + 1} of {n_vals}") for i in range(n_vals)])
    if pos[0] < len(lines):
        _fail(path, f"{len(lines) - pos[0]} lines more than the {n_vals} intensities announced")
    if absolute:
        factor = cfli
    else:
        if not flux > 0.0:
            _fail(path, "the lamps' total luminous flux must be positive to scale cd/klm to candela")
        factor = cfli * flux / 1000.0
    if not factor > 0.0:
        _fail(path, f"conversion factor CFLI must be positive, got {cfli:g}")
    with np.errstate(over="ignore", invalid="ignore"):
        table = _check_candela(path, vals.reshape(planes.size, ng)) * factor
    table = _check_candela(path, table)
    if not math.isfinite(flux):
        _fail(path, "the lamps' total luminous flux overflows")
    if isym == 0:  # all planes below 360°: close the circle
        planes, table = np.concatenate([planes, [360.0]]), np.concatenate([table, table[:1]])
    phi, table = expand_symmetry(path, planes, table)
    return {"format": "EULUMDAT", "theta": theta, "phi": phi, "candela": table,
            "lamp_lumens": None if absolute else flux, "absolute": absolute, "company": company}


# --------------------------------------------------------------------------- public

def read_profile(path, name=None):
    """A :class:`core.scene.Profile` from an ``.ies`` or ``.ldt`` file (by its suffix)."""

    path = Path(path)
    suffix = path.suffix.lower()
    if suffix == ".ies":
        d = read_ies(path)
    elif suffix == ".ldt":
        d = read_ldt(path)
    else:
        _fail(path, f"unknown photometric file type {suffix!r} (expected .ies or .ldt)")
    return Profile(name=name or path.stem, theta=np.ascontiguousarray(d["theta"], np.float64),
                   phi=np.ascontiguousarray(d["phi"], np.float64),
                   candela=np.ascontiguousarray(d["candela"], np.float64), source=path.name)


def evaluate(profile, theta_deg, c_deg):
    """I(θ, C) in cd, bilinear in (θ, C) as the renderer reads it; 0 outside the θ range."""
    th = np.asarray(theta_deg, dtype=np.float64)
    cc = np.mod(np.asarray(c_deg, dtype=np.float64), 360.0)
    th, cc = np.broadcast_arrays(th, cc)
    t, p, tab = profile.theta, profile.phi, profile.candela
    rows = np.stack([np.interp(th, t, tab[j]) for j in range(p.size)])  # (P, ...)
    j = np.clip(np.searchsorted(p, cc, side="right") - 1, 0, p.size - 2)
    f = (cc - p[j]) / (p[j + 1] - p[j])
    idx = np.indices(th.shape)
    lo = rows[(j,) + tuple(idx)]
    hi = rows[(j + 1,) + tuple(idx)]
    out = lo * (1.0 - f) + hi * f
    return np.where((th < t[0]) | (th > t[-1]), 0.0, out)


def flux(profile, mask=None, n=20000):
    """Luminous flux Φ = ∫ I dω (lm) of the bilinear profile.

    Without ``mask`` the integral is exact: the C integral of a piecewise-linear function
    is the trapezoid rule over the planes, leaving a piecewise-linear g(θ) whose product
    with sin θ integrates in closed form. ``mask(cos θ)`` (e.g. a spot's falloff around
    the nadir axis) is integrated numerically with ``n`` midpoints in θ.
    """
    t = np.radians(profile.theta)
    c = np.radians(profile.phi)
    w = np.zeros(c.size)
    dc = np.diff(c)
    w[:-1] += 0.5 * dc
    w[1:] += 0.5 * dc
    g = w @ profile.candela  # ∫ I(θ_i, C) dC at each θ node
    if t.size == 1:
        return 0.0
    if mask is None:
        a, b = t[:-1], t[1:]
        h = b - a
        area = np.cos(a) - np.cos(b)  # ∫ sin θ dθ
        first = (np.sin(b) - b * np.cos(b)) - (np.sin(a) - a * np.cos(a)) - a * area  # ∫ (θ − a) sin θ dθ
        return float(np.sum(g[:-1] * area + (g[1:] - g[:-1]) / h * first))
    edges = np.linspace(t[0], t[-1], n + 1)
    mid = 0.5 * (edges[:-1] + edges[1:])
    gm = np.interp(mid, t, g)
    return float(np.sum(gm * np.asarray(mask(np.cos(mid)), dtype=np.float64) * np.sin(mid)) * (edges[1] - edges[0]))


def preset_profiles():
    """{name: path} of the sample profiles shipped in presets/ies (sorted by name)."""

    folder = PRESETS_DIR / "ies"
    if not folder.is_dir():
        return {}
    return {p.stem: p for p in sorted(folder.iterdir()) if p.suffix.lower() in PROFILE_SUFFIXES}
