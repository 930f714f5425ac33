"""Loaders for the data tables shipped in ``presets/``.

Everything here uses the standard library and numpy only: Blender's bundled
Python has no colour-science, so the shipped CSV files are the single source
of spectral data at render time.  The files themselves are produced by
:func:`spectral_gi.core.io.tables.generate_tables` (colour-science tables) or
were transcribed by hand (the Cornell box, metal optical constants, glass
dispersion formulas); ``presets/README.md`` documents every file.

CSV convention used by every table in ``presets/``:

* first line is a header; its first field is ``wavelength_nm``;
* one row per wavelength, comma separated, all fields parse as finite floats;
* wavelengths are strictly increasing;
* blank lines and lines starting with ``#`` are ignored.
"""

from __future__ import annotations

import functools
import math
import tomllib
from pathlib import Path

import numpy as np

PRESETS_DIR: Path = Path(__file__).resolve().parents[2] / "presets"

WAVELENGTH_COLUMN = "wavelength_nm"

CMFS_FILES = {
    "CIE 1931 2 Degree Standard Observer": "cie/cie1931_2deg.csv",
    "CIE 1964 10 Degree Standard Observer": "cie/cie1964_10deg.csv",
}

_OBSERVER_ALIASES = {
    "cie 1931 2 degree standard observer": "CIE 1931 2 Degree Standard Observer",
    "1931": "CIE 1931 2 Degree Standard Observer",
    "2": "CIE 1931 2 Degree Standard Observer",
    "cie 1964 10 degree standard observer": "CIE 1964 10 Degree Standard Observer",
    "1964": "CIE 1964 10 Degree Standard Observer",
    "10": "CIE 1964 10 Degree Standard Observer",
}

ILLUMINANTS_DIR = "illuminants"
MALLETT2019_FILE = "uplift/mallett2019_srgb.csv"
COLORCHECKER_FILE = "colorchecker/colorchecker_n_ohta.csv"
METALS_DIR = "metals"
GLASSES_FILE = "glasses.toml"

GLASS_FORMULAS = {
    "sellmeier": ("B1", "B2", "B3", "C1", "C2", "C3"),
    "cauchy": ("A", "B_nm2"),
}

CORNELL_BOX_DIR = "scenes/cornell_box"
CORNELL_MATERIALS = ("white", "red", "green", "light")


def _resolve(relpath: str | Path) -> Path:
    """Absolute paths are used as given; relative ones are taken under PRESETS_DIR."""
    path = Path(relpath)
    if not path.is_absolute():
        path = PRESETS_DIR / path
    return path


def read_table(relpath: str | Path) -> tuple[np.ndarray, np.ndarray, list[str]]:
    """Read one spectral CSV table.

    ``relpath`` is relative to :data:`PRESETS_DIR`, or an absolute path.

    Returns ``(wavelengths[N], values[N, K], column_names)`` where
    ``column_names`` holds the K value-column names (the wavelength column is
    not included).  Raises ``ValueError`` naming the file on malformed content,
    and ``FileNotFoundError`` if the file does not exist.
    """
    path = _resolve(relpath)
    st = path.stat()
    wl, values, names = _read_table_cached(str(path), st.st_mtime_ns, st.st_size)
    return wl.copy(), values.copy(), list(names)


@functools.lru_cache(maxsize=64)
def _read_table_cached(path_text, mtime_ns, size):
    """The parsed table of one file version (keyed by its modification time and size): the
    shipped tables are read once a process, not once a render."""
    path = Path(path_text)
    text = path.read_text(encoding="utf-8")

    def fail(msg: str, line_no: int | None = None) -> ValueError:
        where = f"{path}" if line_no is None else f"{path}, line {line_no}"
        return ValueError(f"malformed spectral table {where}: {msg}")

    header: list[str] | None = None
    rows: list[list[float]] = []
    for line_no, raw in enumerate(text.splitlines(), start=1):
        line = raw.strip()
        if not line or line.startswith("#"):
            continue
        fields = [f.strip() for f in line.split(",")]
        if header is None:
            header = fields
            if header[0] != WAVELENGTH_COLUMN:
                raise fail(
                    f"header must start with {WAVELENGTH_COLUMN!r}, got {header[0]!r}",
                    line_no,
                )
            if len(header) < 2:
                raise fail("header has no value columns", line_no)
            if any(not name for name in header) or len(set(header)) != len(header):
                raise fail(f"empty or duplicate column name in header {header}", line_no)
            continue
        if len(fields) != len(header):
            raise fail(f"expected {len(header)} fields, got {len(fields)}", line_no)
        try:
            row = [float(f) for f in fields]
        except ValueError:
            raise fail(f"non-numeric field in {fields}", line_no) from None
        if not all(math.isfinite(v) for v in row):
            raise fail(f"non-finite value in {fields}", line_no)
        if rows and row[0] <= rows[-1][0]:
            raise fail(
                f"wavelengths must be strictly increasing ({row[0]} after {rows[-1][0]})",
                line_no,
            )
        rows.append(row)

    if header is None:
        raise fail("file is empty (no header)")
    if not rows:
        raise fail("no data rows")

    data = np.asarray(rows, dtype=np.float64)
    return data[:, 0].copy(), data[:, 1:].copy(), header[1:]


def _expect_columns(relpath: str | Path, names: list[str], expected: list[str]) -> None:
    if names != expected:
        raise ValueError(f"{_resolve(relpath)}: expected columns {expected}, got {names}")


def cmfs(
    observer: str = "CIE 1931 2 Degree Standard Observer",
) -> tuple[np.ndarray, np.ndarray]:
    """CIE colour-matching functions: ``(wavelengths[N], xyz_bar[N, 3])``.

    ``observer`` is the colour-science name or one of the short forms
    ``"1931"``/``"2"`` or ``"1964"``/``"10"``.  Tables run 360..830 nm in 1 nm steps.
    """
    key = _OBSERVER_ALIASES.get(str(observer).strip().lower())
    if key is None:
        raise ValueError(
            f"unknown observer {observer!r}; expected one of {sorted(CMFS_FILES)} "
            "or '1931' / '1964'"
        )
    relpath = CMFS_FILES[key]
    wl, values, names = read_table(relpath)
    _expect_columns(relpath, names, ["xbar", "ybar", "zbar"])
    return wl, values


def illuminant_names() -> list[str]:
    """Names of the illuminants shipped in ``presets/illuminants``."""
    return sorted(p.stem for p in (PRESETS_DIR / ILLUMINANTS_DIR).glob("*.csv"))


def illuminant(name: str) -> tuple[np.ndarray, np.ndarray]:
    """Relative spectral power distribution of a CIE illuminant: ``(wl[N], values[N])``.

    Sampling is the table's native one (e.g. D65: 300..780 nm, 5 nm).
    """
    relpath = Path(ILLUMINANTS_DIR) / f"{name}.csv"
    if "/" in name or "\\" in name or not _resolve(relpath).is_file():
        raise ValueError(f"unknown illuminant {name!r}; available: {illuminant_names()}")
    wl, values, names = read_table(relpath)
    _expect_columns(relpath, names, ["value"])
    return wl, values[:, 0].copy()


def mallett2019_basis() -> tuple[np.ndarray, np.ndarray]:
    """Mallett & Yuksel (2019) sRGB basis spectra: ``(wl[N], rgb[N, 3])``, 380..780 nm, 5 nm."""
    wl, values, names = read_table(MALLETT2019_FILE)
    _expect_columns(MALLETT2019_FILE, names, ["r", "g", "b"])
    return wl, values


def colorchecker_table() -> tuple[np.ndarray, np.ndarray, list[str]]:
    """ColorChecker reflectances (N. Ohta): ``(wl[N], values[N, 24], patch_names[24])``.

    380..780 nm, 5 nm; columns in the chart's standard order (dark skin ... black 2).
    """
    wl, values, names = read_table(COLORCHECKER_FILE)
    if len(names) != 24:
        raise ValueError(f"{_resolve(COLORCHECKER_FILE)}: expected 24 patch columns, got {len(names)}")
    return wl, values, names


def metal_names() -> list[str]:
    """Names (chemical symbols) of the metals shipped in ``presets/metals``."""
    return sorted(p.stem for p in (PRESETS_DIR / METALS_DIR).glob("*.csv"))


def metal_table(name: str) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Complex refractive index of a metal as tabulated: ``(wl[N], eta[N], k[N])``."""
    relpath = Path(METALS_DIR) / f"{name}.csv"
    if "/" in name or "\\" in name or not _resolve(relpath).is_file():
        raise ValueError(f"unknown metal {name!r}; available: {metal_names()}")
    wl, values, names = read_table(relpath)
    _expect_columns(relpath, names, ["eta", "k"])
    return wl, values[:, 0].copy(), values[:, 1].copy()


def glasses() -> dict[str, dict]:
    """Glass dispersion formulas from ``presets/glasses.toml``, validated.

    Returns ``{name: entry}``; each entry is the TOML table with ``formula``
    (``"sellmeier"``: keys ``B1..B3`` and ``C1..C3`` in µm²; ``"cauchy"``: keys
    ``A``, ``B_nm2`` and optional ``C_nm4``, filled with 0.0 when absent), the
    published ``nd`` and ``abbe``, ``range_nm``, ``description`` and ``source``.
    Numbers are returned as floats.
    """
    path = _resolve(GLASSES_FILE)
    try:
        with path.open("rb") as fh:
            doc = tomllib.load(fh)
    except tomllib.TOMLDecodeError as exc:
        raise ValueError(f"{path}: invalid TOML: {exc}") from None
    if doc.get("schema") != 1:
        raise ValueError(f"{path}: unsupported schema {doc.get('schema')!r} (expected 1)")
    table = doc.get("glass")
    if not isinstance(table, dict) or not table:
        raise ValueError(f"{path}: no [glass.<name>] tables")
    out: dict[str, dict] = {}
    for name, entry in table.items():
        formula = entry.get("formula") if isinstance(entry, dict) else None
        if formula not in GLASS_FORMULAS:
            raise ValueError(
                f"{path}: glass {name!r} has formula {formula!r}; expected one of {sorted(GLASS_FORMULAS)}"
            )
        result = dict(entry)
        keys = GLASS_FORMULAS[formula] + ("nd", "abbe")
        if formula == "cauchy":
            result.setdefault("C_nm4", 0.0)
            keys = keys + ("C_nm4",)
        for key in keys:
            value = result.get(key)
            if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
                raise ValueError(f"{path}: glass {name!r}: {key} must be a finite number, got {value!r}")
            result[key] = float(value)
        rng = result.get("range_nm")
        if not (
            isinstance(rng, list)
            and len(rng) == 2
            and all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in rng)
            and 0 < rng[0] < rng[1]
        ):
            raise ValueError(f"{path}: glass {name!r}: range_nm must be [min, max] in nm, got {rng!r}")
        result["range_nm"] = (float(rng[0]), float(rng[1]))
        out[name] = result
    return out


def load_cornell_box_data() -> dict:
    """The Cornell box as published by Cornell's Program of Computer Graphics.

    Returns a dict with keys

    * ``units``: ``"mm"``;
    * ``surfaces``: list of ``{"name", "material", "quads"}`` with ``quads`` a
      float64 array ``[Q, 4, 3]`` in millimetres, vertex order as published;
    * ``camera``: the ``[camera]`` table of ``geometry.toml`` (a dict);
    * ``reflectance``: ``{"white"|"red"|"green": (wl[N], values[N])}``;
    * ``light``: ``(wl[4], values[4])``, relative emission.
    """
    base = PRESETS_DIR / CORNELL_BOX_DIR
    geometry_path = base / "geometry.toml"
    try:
        with geometry_path.open("rb") as fh:
            doc = tomllib.load(fh)
    except tomllib.TOMLDecodeError as exc:
        raise ValueError(f"{geometry_path}: invalid TOML: {exc}") from None

    surfaces = []
    for i, entry in enumerate(doc.get("surface", [])):
        try:
            name = str(entry["name"])
            material = str(entry["material"])
            quads = np.asarray(entry["quads"], dtype=np.float64)
        except (KeyError, TypeError, ValueError) as exc:
            raise ValueError(f"{geometry_path}: surface #{i} is malformed: {exc}") from None
        if material not in CORNELL_MATERIALS:
            raise ValueError(f"{geometry_path}: surface {name!r} has unknown material {material!r}")
        if quads.ndim != 3 or quads.shape[1:] != (4, 3):
            raise ValueError(
                f"{geometry_path}: surface {name!r} quads must have shape [Q, 4, 3], "
                f"got {quads.shape}"
            )
        surfaces.append({"name": name, "material": material, "quads": quads})
    if not surfaces:
        raise ValueError(f"{geometry_path}: no [[surface]] entries")
    if "camera" not in doc:
        raise ValueError(f"{geometry_path}: missing [camera] table")

    spectra_rel = Path(CORNELL_BOX_DIR) / "spectra.csv"
    wl, values, names = read_table(spectra_rel)
    reflectance = {}
    for material in ("white", "red", "green"):
        if material not in names:
            raise ValueError(f"{_resolve(spectra_rel)}: missing column {material!r}")
        reflectance[material] = (wl.copy(), values[:, names.index(material)].copy())

    light_rel = Path(CORNELL_BOX_DIR) / "light.csv"
    lwl, lvalues, lnames = read_table(light_rel)
    _expect_columns(light_rel, lnames, ["value"])

    return {
        "units": doc.get("units", "mm"),
        "surfaces": surfaces,
        "camera": dict(doc["camera"]),
        "reflectance": reflectance,
        "light": (lwl, lvalues[:, 0].copy()),
    }
