"""Built-in spectra: blackbody, CIE illuminants, ColorChecker, metals and glasses.

NumPy only (no colour-science at run time): the tabulated data come from the
files in ``presets/`` through :mod:`spectral_gi.core.io.presets`, and everything
here is a pure function of a name and an array of wavelengths in nanometres.

Wavelength arguments may have any shape and any order (they need not be sorted
or evenly spaced); results have the same shape. Tabulated spectra are
interpolated linearly in wavelength. Outside a table's range the value at the
nearest end is held (``extrapolate="constant"``, the CIE 015 recommendation and
colour-science's default), or ``extrapolate="zero"`` gives 0 there. At the
tabulated wavelengths the tabulated values are returned exactly.

Unknown names raise :class:`ValueError` naming the name and listing the
available ones.
"""

from __future__ import annotations

import functools
import math
import numbers
import re

import numpy as np

from ..io import presets

# --------------------------------------------------------------------------- constants

#: Planck constant, J·s (exact in the SI since 2019; CODATA 2018).
PLANCK_H = 6.62607015e-34
#: Speed of light in vacuum, m/s (exact).
LIGHT_SPEED_C = 299792458.0
#: Boltzmann constant, J/K (exact in the SI since 2019; CODATA 2018).
BOLTZMANN_K = 1.380649e-23
#: First radiation constant for spectral radiance, 2hc², W·m²/sr.
C1L = 2.0 * PLANCK_H * LIGHT_SPEED_C**2
#: Second radiation constant hc/k, m·K.
C2 = PLANCK_H * LIGHT_SPEED_C / BOLTZMANN_K

#: Fraunhofer / spectral lines used for nd and the Abbe number (nm, in air).
LINE_D_NM = 587.5618  # helium d
LINE_F_NM = 486.1327  # hydrogen F
LINE_C_NM = 656.2725  # hydrogen C

_EXTRAPOLATE = ("constant", "zero")

# --------------------------------------------------------------------------- helpers


def _positive(values, what: str, unit: str) -> np.ndarray:
    """``values`` as a float64 array, all finite and > 0 (``ValueError`` naming ``what`` otherwise)."""
    try:
        a = np.asarray(values, dtype=np.float64)
    except (TypeError, ValueError):
        raise ValueError(f"{what} must be numbers, got {values!r}") from None
    if not np.all(np.isfinite(a)) or np.any(a <= 0.0):
        raise ValueError(f"{what} must be finite and positive ({unit})")
    return a


def _wavelengths(wavelengths_nm, what: str = "wavelengths_nm") -> np.ndarray:
    return _positive(wavelengths_nm, what, "nanometres")


def _interp(table_wl: np.ndarray, table_values: np.ndarray, wl: np.ndarray, extrapolate: str) -> np.ndarray:
    if extrapolate not in _EXTRAPOLATE:
        raise ValueError(f"extrapolate must be one of {_EXTRAPOLATE}, got {extrapolate!r}")
    flat = wl.reshape(-1)
    out = np.interp(flat, table_wl, table_values)
    if extrapolate == "zero":
        out[(flat < table_wl[0]) | (flat > table_wl[-1])] = 0.0
    return out.reshape(wl.shape)


def _squash(name: str) -> str:
    """Case-, space-, hyphen- and underscore-insensitive key."""
    return "".join(ch for ch in name.upper() if ch not in " -_")


def _unknown(kind: str, name, available) -> ValueError:
    return ValueError(f"unknown {kind} {name!r}; available: {list(available)}")


def _frozen(a: np.ndarray) -> np.ndarray:
    a = np.ascontiguousarray(a, dtype=np.float64)
    a.setflags(write=False)
    return a


def _resolve(kind: str, name, names, aliases: dict) -> str:
    """The shipped name among ``names`` for ``name`` (matched by ``_squash``), or an alias's
    target; ``ValueError`` naming the choices otherwise."""
    if isinstance(name, str):
        key = _squash(name)
        by_key = {_squash(n): n for n in names}
        if key in by_key:
            return by_key[key]
        alias = aliases.get(key)
        if alias in names:
            return alias
    raise _unknown(kind, name, names)


# --------------------------------------------------------------------------- blackbody


def blackbody(temperature_K, wavelengths_nm) -> np.ndarray:
    """Planck's law: spectral radiance of a blackbody in W/(m²·sr·nm).

    ``B(λ, T) = 2hc² / λ⁵ / (exp(c₂ / (λT)) − 1)`` with CODATA 2018 h, c, k_B and
    c₂ = hc/k_B (radiation into vacuum, refractive index 1). ``temperature_K``
    and ``wavelengths_nm`` broadcast against each other (NumPy rules), e.g. a
    scalar temperature with an array of wavelengths, or ``T[:, None]`` with
    ``wl[None, :]`` for a table.
    """
    t = _positive(temperature_K, "temperature_K", "kelvin")
    lam = _wavelengths(wavelengths_nm) * 1e-9  # metres
    with np.errstate(over="ignore"):  # exp overflows to inf far in the Wien tail: B -> 0
        per_metre = C1L / lam**5 / np.expm1(C2 / (lam * t))
    return per_metre * 1e-9  # W/(m²·sr·m) -> W/(m²·sr·nm)


# --------------------------------------------------------------------------- illuminants


@functools.lru_cache(maxsize=None)
def _illuminant_table(canonical: str):
    wl, values = presets.illuminant(canonical)
    return _frozen(wl), _frozen(values)


def _natural_key(name: str):
    return [(0, int(part), "") if part.isdigit() else (1, 0, part) for part in re.split(r"(\d+)", name)]


def illuminant_names() -> list[str]:
    """Names of the shipped illuminants (colour-science's names: ``"D65"``, ``"FL11"``, ``"LED-B1"`` ...).

    In natural order: A, D50 ... D75, E, FL1 ... FL12, LED-B1 ... LED-V2.
    """
    return sorted(presets.illuminant_names(), key=_natural_key)


def led_names() -> list[str]:
    """Names of the shipped CIE LED illuminants (``"LED-B1"`` ... ``"LED-V2"``)."""
    return [n for n in illuminant_names() if n.startswith("LED-")]


def resolve_illuminant_name(name: str) -> str:
    """Shipped name for ``name``, accepting friendly aliases.

    Matching ignores case, spaces, hyphens and underscores, and a leading
    ``"CIE"`` or ``"Illuminant"``; ``"F1"`` ... ``"F12"`` mean ``"FL1"`` ... ``"FL12"``
    (so ``"F11"``, ``"cie f11"``, ``"fl11"`` → ``"FL11"``; ``"led_b1"`` → ``"LED-B1"``).
    """
    names = illuminant_names()
    if not isinstance(name, str) or not name.strip():
        raise _unknown("illuminant", name, names)
    by_key = {_squash(n): n for n in names}
    key = _squash(name)
    for prefix in ("ILLUMINANT", "CIE"):
        if key.startswith(prefix) and key not in by_key:
            key = key[len(prefix):]
    if key not in by_key and key.startswith("F") and key[1:].isdigit():
        key = "FL" + key[1:]
    if key not in by_key:
        raise _unknown("illuminant", name, names)
    return by_key[key]


def illuminant(name: str, wavelengths_nm, extrapolate: str = "constant") -> np.ndarray:
    """Relative spectral power of a CIE illuminant at ``wavelengths_nm`` (as tabulated, e.g. 100 at 560 nm for D65)."""
    wl_table, values = _illuminant_table(resolve_illuminant_name(name))
    return _interp(wl_table, values, _wavelengths(wavelengths_nm), extrapolate)


# --------------------------------------------------------------------------- ColorChecker


@functools.lru_cache(maxsize=None)
def _colorchecker_table():
    wl, values, names = presets.colorchecker_table()
    return _frozen(wl), _frozen(values), tuple(names)


def colorchecker_names() -> list[str]:
    """The 24 ColorChecker patch names in the chart's standard order (row by row, dark skin first)."""
    return list(_colorchecker_table()[2])


def _colorchecker_index(patch) -> int:
    names = _colorchecker_table()[2]
    if isinstance(patch, numbers.Integral) and not isinstance(patch, bool):
        if 0 <= int(patch) < len(names):
            return int(patch)
        raise ValueError(
            f"ColorChecker index {patch!r} out of range: 0..{len(names) - 1} (0 = dark skin, 23 = black 2)"
        )
    if isinstance(patch, str):
        wanted = " ".join(patch.lower().split())
        lowered = [n.lower() for n in names]
        if wanted in lowered:
            return lowered.index(wanted)
        # Short forms of the neutral patches: "white", "neutral 8", "black 2", "black".
        hits = [i for i, n in enumerate(lowered) if wanted and n.startswith(wanted + " ")]
        if len(hits) == 1:
            return hits[0]
    raise _unknown("ColorChecker patch", patch, names)


def colorchecker(patch, wavelengths_nm, extrapolate: str = "constant") -> np.ndarray:
    """Spectral reflectance (0..1) of a ColorChecker patch, by name or 0-based index in the standard order.

    Names are those of :func:`colorchecker_names` (case-insensitive); the neutral
    patches may be given by their leading words (``"white"``, ``"neutral 8"``,
    ``"black"``). Index 0 is patch No. 1 (dark skin), 23 is No. 24 (black 2).
    """
    wl_table, values, _ = _colorchecker_table()
    column = values[:, _colorchecker_index(patch)]
    return _interp(wl_table, column, _wavelengths(wavelengths_nm), extrapolate)


# --------------------------------------------------------------------------- metals

_METAL_ALIASES = {
    "GOLD": "Au",
    "SILVER": "Ag",
    "COPPER": "Cu",
    "ALUMINIUM": "Al",
    "ALUMINUM": "Al",
}


@functools.lru_cache(maxsize=None)
def _metal_table(canonical: str):
    wl, eta, k = presets.metal_table(canonical)
    return _frozen(wl), _frozen(eta), _frozen(k)


def metal_names() -> list[str]:
    """Chemical symbols of the shipped metals (``"Ag"``, ``"Al"``, ``"Au"``, ``"Cu"``)."""
    return presets.metal_names()


def resolve_metal_name(name: str) -> str:
    """Shipped name for ``name``: the symbol in any case, or ``"gold"``, ``"silver"``, ``"copper"``, ``"aluminium"``."""
    return _resolve("metal", name, metal_names(), _METAL_ALIASES)


def metal_ior(name: str, wavelengths_nm, extrapolate: str = "constant") -> tuple[np.ndarray, np.ndarray]:
    """Complex refractive index ``(eta, k)`` of a metal (n = eta + i·k), each shaped like ``wavelengths_nm``."""
    wl_table, eta, k = _metal_table(resolve_metal_name(name))
    wl = _wavelengths(wavelengths_nm)
    return _interp(wl_table, eta, wl, extrapolate), _interp(wl_table, k, wl, extrapolate)


# --------------------------------------------------------------------------- glasses

_GLASS_ALIASES = {
    "BK7": "N-BK7",
    "FUSEDSILICA": "fused_silica",
    "SILICA": "fused_silica",
    "FUSEDQUARTZ": "fused_silica",
}


@functools.lru_cache(maxsize=None)
def _glasses():
    return presets.glasses()


def glass_names() -> list[str]:
    """Names of the shipped glasses, in file order (``"N-BK7"``, ..., ``"crown"``, ``"flint"``)."""
    return list(_glasses())


def resolve_glass_name(name: str) -> str:
    """Shipped name for ``name`` (case-, space-, hyphen- and underscore-insensitive; ``"BK7"`` → ``"N-BK7"``)."""
    return _resolve("glass", name, glass_names(), _GLASS_ALIASES)


def glass_info(name: str) -> dict:
    """The glass's entry from ``presets/glasses.toml`` (formula, coefficients, published nd/abbe, source)."""
    return dict(_glasses()[resolve_glass_name(name)])


def _glass_n(entry: dict, wl_nm: np.ndarray) -> np.ndarray:
    if entry["formula"] == "sellmeier":
        l2 = (wl_nm * 1e-3) ** 2  # µm²
        n2 = 1.0
        for i in (1, 2, 3):
            n2 = n2 + entry[f"B{i}"] * l2 / (l2 - entry[f"C{i}"])
        return np.sqrt(n2)
    # cauchy
    inv2 = 1.0 / wl_nm**2
    return entry["A"] + entry["B_nm2"] * inv2 + entry["C_nm4"] * inv2**2


def glass_ior(name: str, wavelengths_nm) -> np.ndarray:
    """Refractive index (real) of a glass from its dispersion formula (Sellmeier or Cauchy, as the file says).

    The formula is evaluated at any positive wavelength; it is only meaningful
    within the glass's ``range_nm`` (see :func:`glass_info`).
    """
    entry = _glasses()[resolve_glass_name(name)]
    return _glass_n(entry, _wavelengths(wavelengths_nm))


def glass_nd(name: str) -> float:
    """Refractive index at the helium d line (587.5618 nm), from the formula."""
    return float(glass_ior(name, LINE_D_NM))


def glass_abbe(name: str) -> float:
    """Abbe number (nd − 1)/(nF − nC) from the formula (F = 486.1327 nm, C = 656.2725 nm)."""
    nd, nf, nc = glass_ior(name, [LINE_D_NM, LINE_F_NM, LINE_C_NM])
    dispersion = nf - nc
    if not math.isfinite(dispersion) or dispersion == 0.0:
        raise ValueError(f"glass {name!r} has no dispersion between the F and C lines")
    return float((nd - 1.0) / dispersion)
