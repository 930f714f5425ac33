"""Spectral representation: accuracy on the 24 ColorChecker spectra, and evaluation speed.

    python benchmarks/spectra_bench.py

For each reconstruction method and number of coefficients m = 3, 4, 6, 8, 12 it prints
the spectral RMS error (380–730 nm) and the CIEDE2000 colour difference of the
reconstruction against the measured spectrum under CIE D65, A and F11 (a narrow-band
fluorescent lamp, where metamerism shows), each with its own white point:

* "MESE (bounded)": Peters et al. 2019's bounded maximum-entropy reconstruction of the
  moments (the renderer's method for reflectances);
* "Fourier series": the truncated Fourier series of the same moments, clipped to [0, 1]
  as a renderer must (the compendium's item 65 basis extended to m terms);
* "Glassner 1989 (item 65)": three Fourier basis functions solved from the XYZ under
  D65 (m = 3 only), clipped to [0, 1].

Then it measures nanoseconds per evaluation of a prepared spectrum inside a Numba
kernel (bounded and unbounded), for the default m.
"""
import time

import numpy as np

import results  # benchmarks/results.py: the JSON record of this run

from spectral_gi.core import constants as C
from spectral_gi.core.colour import XYZ_to_Lab, XYZ_to_xy, delta_E_CIE2000, sd_to_XYZ
from spectral_gi.core.spectra import kernel as K
from spectral_gi.core.spectra import fit
from spectral_gi.core.spectra import library as L
from spectral_gi.core.spectra import moments as M

MS = (3, 4, 6, 8, 12)
LIGHTS = ("D65", "A", "FL11")


def lab_under(wl, refl, light):
    ill = (wl, L.illuminant(light, wl))
    XYZ = sd_to_XYZ(wl, refl, illuminant=ill, interpolation="linear")
    white = sd_to_XYZ(wl, np.ones_like(wl), illuminant=ill, interpolation="linear")
    return XYZ_to_Lab(XYZ / white[1], XYZ_to_xy(white))


def accuracy():
    g = M.grid()
    names = L.colorchecker_names()
    truth = np.stack([L.colorchecker(n, g) for n in names])
    band = (g >= 380) & (g <= 730)
    ref_lab = {light: np.stack([lab_under(g, t, light) for t in truth]) for light in LIGHTS}
    rows = []
    for method in ("MESE (bounded)", "Fourier series", "Glassner 1989 (item 65)"):
        for m in MS:
            if method.startswith("Glassner") and m != 3:
                continue
            rec = []
            for t in truth:
                if method.startswith("Glassner"):
                    # item 65 solved against D65-weighted CMFs so the spectrum is a reflectance
                    XYZ = fit.reflectance_XYZ(M.moments_from_samples(g, t, 16))
                    c = fit.reflectance_from_XYZ(XYZ, n_coeffs=16, method="Glassner 1989")
                    rec.append(M.reconstruct_bounded(c, g))
                    continue
                c = M.moments_from_samples(g, t, m)
                if method.startswith("MESE"):
                    rec.append(M.reconstruct_bounded(c, g))
                else:
                    rec.append(np.clip(M.reconstruct_fourier(c, g), 0.0, 1.0))
            rec = np.array(rec)
            rms = np.sqrt(np.mean((rec - truth)[:, band] ** 2, axis=1))
            de = {light: delta_E_CIE2000(ref_lab[light], np.stack([lab_under(g, r, light) for r in rec]))
                  for light in LIGHTS}
            rows.append((method, m, rms, de))
    print("ColorChecker (24 patches): spectral RMS (380-730 nm) and ΔE00 mean/max per light")
    print(f"{'method':26s} {'m':>3s} {'RMS mean':>9s} " + " ".join(f"{l + ' mean/max':>16s}" for l in LIGHTS))
    for method, m, rms, de in rows:
        print(f"{method:26s} {m:3d} {rms.mean():9.4f} "
              + " ".join(f"{de[l].mean():7.3f}/{de[l].max():7.3f}" for l in LIGHTS))
    default = [r for r in rows if r[0].startswith("MESE") and r[1] == C.N_COEFFS_DEFAULT]
    if default:
        _, m, _, de = default[0]
        ok = all(de[l].mean() <= 0.5 and de[l].max() <= 1.5 for l in LIGHTS)
        print(f"default m = {m}: target mean ΔE00 ≤ 0.5 and max ≤ 1.5 under each light: {'met' if ok else 'NOT met'}")
    return results.table(
        "ColorChecker (24 patches): spectral RMS (380–730 nm) and ΔE00 mean / max under each light",
        ["method", "m", "RMS mean"] + [f"{l} ΔE00 mean / max" for l in LIGHTS],
        [[method, m, round(float(rms.mean()), 4)] + [f"{de[l].mean():.2f} / {de[l].max():.2f}" for l in LIGHTS]
         for method, m, rms, de in rows])


def speed():
    g = M.grid()
    m = C.N_COEFFS_DEFAULT
    coeffs = np.stack([M.moments_from_samples(g, L.colorchecker(n, g), m) for n in L.colorchecker_names()]
                      + [M.moments_from_samples(g, L.illuminant("FL11", g), m)])
    kinds = np.array([C.SPECTRUM_BOUNDED] * 24 + [C.SPECTRUM_UNBOUNDED], np.int32)
    prep = M.prepare_table(coeffs, kinds)
    warp = M.warp_table()
    n = 4_000_000
    rng = np.random.default_rng(1)
    lams = rng.uniform(C.LAMBDA_MIN, C.LAMBDA_MAX, n)
    timings = []
    for label, rows in (("bounded (reflectance)", rng.integers(0, 24, n)), ("unbounded (emission)", np.full(n, 24))):
        rows = rows.astype(np.int64)
        K.eval_spectrum_batch(prep, kinds, m, warp, rows[:10], lams[:10])  # compile / load cache
        best = np.inf
        for _ in range(3):
            t0 = time.perf_counter()
            K.eval_spectrum_batch(prep, kinds, m, warp, rows, lams)
            best = min(best, time.perf_counter() - t0)
        import numba
        print(f"evaluation in a Numba kernel, m = {m}, {label}: {best / n * 1e9:.1f} ns per evaluation "
              f"({numba.get_num_threads()} threads; {best / n * 1e9 * numba.get_num_threads():.1f} ns per "
              f"evaluation per thread)")
        timings.append([f"moments evaluated in a kernel, {label}", round(best / n * 1e9, 1)])
    # the renderer's own path: a 1 nm table built once per render, interpolated
    table = M.tabulate(coeffs, kinds)
    rows32 = rng.integers(0, 25, n).astype(np.int64)
    _table_lookups(table, rows32[:10], lams[:10])
    best = np.inf
    for _ in range(3):
        t0 = time.perf_counter()
        _table_lookups(table, rows32, lams)
        best = min(best, time.perf_counter() - t0)
    print(f"1 nm table lookup as the path tracer does it: {best / n * 1e9:.1f} ns per evaluation")
    timings.append(["1 nm table lookup, as the path tracer does it", round(best / n * 1e9, 1)])
    import numba
    return results.table(f"Spectrum evaluation, m = {m}, {numba.get_num_threads()} threads",
                         ["evaluation", "ns per evaluation"], timings)


def _make_lookup_kernel():
    from numba import prange

    from spectral_gi.core.jit import kernel
    from spectral_gi.core.integrators.path import lookup

    @kernel(parallel=True)
    def lookups(table, rows, lams):
        out = np.empty(lams.shape[0])
        for i in prange(lams.shape[0]):
            out[i] = lookup(table, rows[i], lams[i])
        return out

    return lookups


_table_lookups = _make_lookup_kernel()


if __name__ == "__main__":
    tables = [accuracy(), speed()]
    import numba
    results.write("spectra_bench", tables, conditions={"threads": numba.get_num_threads()})
