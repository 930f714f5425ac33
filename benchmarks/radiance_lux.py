"""Equal-error race against Radiance on the CIE 171:2006 analytical cases (core/lux/cie171.py).

    pip install pyradiance            # or: pip install -e .[bench]
    python benchmarks/radiance_lux.py [--cases 5.2 5.8] [--quick] [--threads 2]

Radiance comes from PyPI's ``pyradiance`` (Radiance 6 binaries: oconv, rtrace, rpict, ...;
no falsecolor); a ``rtrace`` on PATH is used when pyradiance is not installed.

Scene conversion (one Radiance scene per case):

* every triangle becomes a ``polygon`` with a grey ``plastic`` of the case's reflectance ρ
  (``plastic m 0 0 5 ρ ρ ρ 0 0``: specularity 0, roughness 0, so a Lambertian of RGB = ρ);
* a point light of I cd becomes a ``light`` sphere of radius r whose radiance R = G = B is
  ``I / (179 π r²)``: a uniform sphere of luminance L has intensity L π r² in every direction,
  and Radiance's luminance is 179 (0.265 R + 0.670 G + 0.065 B) cd/m², i.e. 179 R for grey;
  the sphere lights a point that sees all of it exactly as a point of I cd would;
* a rectangle light of luminance L becomes a ``light`` polygon of radiance ``L / 179``,
  its vertices ordered so that its normal is the light's emitting side;
* each point is a ``rtrace -I+ -h`` input line ``x y z nx ny nz``, moved 0.1 mm along its
  normal off the surface it lies on; illuminance = 179 (0.265 R + 0.670 G + 0.065 B).

Radiance runs as pure Monte Carlo (``-aa 0``: no irradiance cache), with Russian roulette
(``-lr 0 -lw``), ``-ab`` far above what ρ = 0.95 needs (the kept fraction 1 − ρ^ab of the
inter-reflected light is printed), ``-dj 1`` and the ambient samples ``-ad`` swept.

Error per run: the RMS relative error against the closed form over the case's points where
the case has a per-point closed form (5.2, 5.3, 5.4, the black rooms); for the reflecting
rooms (5.6, 5.8 with ρ > 0) the relative error of the area-mean inter-reflected illuminance
``Σ wᵢ (Eᵢ − E_direct,ᵢ) / Σ wᵢ`` against Φρ / (A (1 − ρ)).

Equal error: the target is the error Radiance reaches at its largest ``-ad`` (floored at
``--floor``, 0.1 % by default: both programs' errors below that are float round-off and, for
this renderer, the noise of its wavelength sampling, not a lighting question). This renderer's
time to reach the target comes from its spp sweep, fitted as ``err = a / √t`` (an unbiased
Monte Carlo estimator), so one lucky or unlucky run does not decide it; the ratio printed is
Radiance's time over that time (> 1: this renderer is faster). The first call's compile is
excluded (a warm-up on every kind of case first) and reported on its own.
"""
import argparse
import math
import os
import shutil
import subprocess
import sys
import tempfile
import time

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import results  # noqa: E402

from spectral_gi.core import constants as C  # noqa: E402
from spectral_gi.core.integrators.illuminance import illuminance  # noqa: E402
from spectral_gi.core.lux import cie171  # noqa: E402

RADIANCE_LM_PER_W = 179.0
SPHERE_RADIUS = 0.01  # m, the light sphere standing for a point light
OFFSET = 1e-4  # m, points moved along their normal off their surface
INSTALL_HINT = "Radiance not found: pip install pyradiance   (or: pip install -e .[bench])"


# --------------------------------------------------------------------------- Radiance


def find_radiance():
    """(rtrace, oconv, environment) or None."""
    env = dict(os.environ)
    try:
        import pyradiance  # noqa: F401  (sets PATH and RAYPATH to its binaries and library)
        env = dict(os.environ)
    except ImportError:
        pass
    rtrace, oconv = shutil.which("rtrace", path=env.get("PATH")), shutil.which("oconv", path=env.get("PATH"))
    if not rtrace or not oconv:
        return None
    return rtrace, oconv, env


def case_rho(case):
    return float(case.extra.get("rho", 0.0))


def radiance_scene(case):
    """The case's scene as Radiance text (see the module text for the conversion)."""
    scene, rho = case.scene, case_rho(case)
    out = [f"# CIE 171 case {case.name}", f"void plastic grey 0 0 5 {rho:.6g} {rho:.6g} {rho:.6g} 0 0"]
    k = 0
    for mesh in scene.meshes:
        p = np.asarray(mesh.positions, float)
        for tri in mesh.indices:
            v = " ".join(f"{c:.9g}" for c in p[tri].ravel())
            out.append(f"grey polygon t{k} 0 0 9 {v}")
            k += 1
    for i, light in enumerate(scene.lights):
        if light.kind == C.LIGHT_POINT:
            R = light.intensity / (RADIANCE_LM_PER_W * math.pi * SPHERE_RADIUS ** 2)
            x, y, z = light.position
            out += [f"void light lamp{i} 0 0 3 {R:.9g} {R:.9g} {R:.9g}",
                    f"lamp{i} sphere bulb{i} 0 0 4 {x:.9g} {y:.9g} {z:.9g} {SPHERE_RADIUS:g}"]
        elif light.kind == C.LIGHT_RECT:
            R = light.luminance / RADIANCE_LM_PER_W
            c, u, w = (np.asarray(a, float) for a in (light.position, light.axis_u, light.axis_v))
            corners = [c - u - w, c + u - w, c + u + w, c - u + w]  # normal along u × w, the emitting side
            v = " ".join(f"{x:.9g}" for x in np.ravel(corners))
            out += [f"void light panel{i} 0 0 3 {R:.9g} {R:.9g} {R:.9g}", f"panel{i} polygon panel{i}p 0 0 12 {v}"]
        else:
            raise ValueError(f"light kind {light.kind} is not converted")
    return "\n".join(out) + "\n"


class Radiance:
    def __init__(self, rtrace, oconv, env, workdir):
        self.rtrace, self.oconv, self.env, self.workdir = rtrace, oconv, env, workdir

    def octree(self, case):
        rad = os.path.join(self.workdir, f"case{case.name.replace(' ', '_')}.rad")
        with open(rad, "w") as f:
            f.write(radiance_scene(case))
        octree = rad[:-4] + ".oct"
        with open(octree, "wb") as f:
            subprocess.run([self.oconv, rad], stdout=f, check=True, env=self.env)
        return octree

    def illuminance(self, octree, points, normals, ad, ab, lw, threads):
        """(lux, seconds): one rtrace run over the points."""
        p = np.asarray(points, float) + OFFSET * np.asarray(normals, float)
        lines = "".join(f"{a:.9g} {b:.9g} {c:.9g} {x:.9g} {y:.9g} {z:.9g}\n"
                        for (a, b, c), (x, y, z) in zip(p, normals))
        args = [self.rtrace, "-h", "-I+", "-aa", "0", "-ad", str(ad), "-as", "0", "-ab", str(ab),
                "-lr", "0", "-lw", f"{lw:g}", "-dj", "1", "-ds", "0.05", "-dc", "1", "-dt", "0",
                "-n", str(threads), octree]
        t0 = time.perf_counter()
        res = subprocess.run(args, input=lines, capture_output=True, text=True, check=True, env=self.env)
        dt = time.perf_counter() - t0
        rgb = np.array([[float(v) for v in ln.split()[:3]] for ln in res.stdout.splitlines() if ln.strip()])
        return RADIANCE_LM_PER_W * (rgb @ np.array([0.265, 0.670, 0.065])), dt


# --------------------------------------------------------------------------- errors


def case_error(case, lux):
    """(error, kind): RMS relative error over the points, or the relative error of the mean
    inter-reflected illuminance for the reflecting rooms."""
    if case.expected_total is not None:
        exp = case.expected_total
        keep = exp > 1e-6 * exp.max()
        return float(np.sqrt(np.mean(((lux[keep] - exp[keep]) / exp[keep]) ** 2))), "RMS per point"
    w = case.weights / case.weights.sum()
    indirect = float(w @ (lux - case.expected_direct))
    return abs(indirect - case.expected_mean_indirect) / case.expected_mean_indirect, "mean indirect"


def fit_constant(runs):
    """a in err = a / √t, least squares in log space over the runs (t, err)."""
    logs = [math.log(e) + 0.5 * math.log(t) for t, e in runs if e > 0]
    return math.exp(sum(logs) / len(logs)) if logs else float("nan")


# --------------------------------------------------------------------------- main


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--cases", nargs="*", help="case names or prefixes (5.2, 5.8, '5.8 rho=0.95'); default all")
    ap.add_argument("--quick", action="store_true", help="smaller sweeps (a smoke run, not for the record)")
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--ab", type=int, default=400, help="Radiance -ab (ambient bounces)")
    ap.add_argument("--lw", type=float, default=1e-4, help="Radiance -lw (Russian roulette below this weight)")
    ap.add_argument("--ad", type=int, nargs="*", help="Radiance -ad sweep")
    ap.add_argument("--spp", type=int, nargs="*", help="this renderer's spp sweep")
    ap.add_argument("--floor", type=float, default=1e-3, help="lowest target error (relative)")
    ap.add_argument("--no-write", action="store_true", help="print only; do not write benchmarks/results/")
    args = ap.parse_args(argv)

    found = find_radiance()
    if found is None:
        print(INSTALL_HINT)
        return 0
    ad_sweep = args.ad or ([8, 32] if args.quick else [16, 64])
    spp_sweep = args.spp or ([8, 32] if args.quick else [16, 64, 256])

    cases = cie171.reference_cases()
    if args.cases:
        cases = [c for c in cases if any(c.name == s or c.name.startswith(s) for s in args.cases)]
    print(f"Radiance: {found[0]}; -aa 0 -ab {args.ab} -lr 0 -lw {args.lw:g} -dj 1, -ad {ad_sweep}; "
          f"kept fraction of the indirect at ρ = 0.95: 1 − 0.95^{args.ab} = {1 - 0.95 ** args.ab:.6f}")

    # compile: one tiny call on each kind of case (point light, rectangle light, reflecting room)
    t0 = time.perf_counter()
    for c in {c.name: c for c in cie171.reference_cases() if c.name in ("5.2", "5.3", "5.6")}.values():
        illuminance(c.scene, c.points[:2], c.normals[:2], spp=1, seed=1, threads=args.threads)
    compile_s = time.perf_counter() - t0
    print(f"this renderer's first calls (compile or cache load): {compile_s:.1f} s, excluded below")

    rows, detail = [], []
    with tempfile.TemporaryDirectory(prefix="radiance_lux.") as tmp:
        rad = Radiance(*found, tmp)
        for case in cases:
            octree = rad.octree(case)
            r_runs, o_runs = [], []
            for ad in ad_sweep:
                lux, dt = rad.illuminance(octree, case.points, case.normals, ad, args.ab, args.lw, args.threads)
                err, kind = case_error(case, lux)
                r_runs.append((dt, err))
                detail.append([case.name, "Radiance", f"-ad {ad}", round(dt, 3), err])
                if ad == ad_sweep[0] and case.name == "5.2":
                    exp = case.expected_direct
                    print("5.2 direct check (lx), Radiance / closed form at each point:")
                    print("  " + " ".join(f"{a:.2f}/{b:.2f}" for a, b in zip(lux, exp)))
            for spp in spp_sweep:
                t0 = time.perf_counter()
                lux, _, _ = illuminance(case.scene, case.points, case.normals, spp=spp, seed=7,
                                        threads=args.threads)
                dt = time.perf_counter() - t0
                err, kind = case_error(case, lux)
                o_runs.append((dt, err))
                detail.append([case.name, "spectral-gi", f"{spp} spp", round(dt, 3), err])
            r_time, r_err = r_runs[-1]
            target = max(r_err, args.floor)
            a = fit_constant(o_runs)
            o_time = (a / target) ** 2
            o_time_r = (a / r_err) ** 2 if r_err > 0 else float("inf")
            ratio = r_time / o_time
            rows.append([case.name, kind, r_err, round(r_time, 3), target, round(o_time, 4),
                         round(ratio, 2), round(o_time_r, 3), o_runs[-1][1], round(o_runs[-1][0], 3)])
            print(f"{case.name:14s} {kind:14s} Radiance err {r_err:.2e} in {r_time:7.3f} s | target {target:.2e}"
                  f" | ours {o_time:8.4f} s -> Radiance/ours {ratio:7.2f}"
                  f" | ours at {spp_sweep[-1]} spp: {o_runs[-1][1]:.2e} in {o_runs[-1][0]:.3f} s")

    wins = sum(1 for r in rows if r[6] > 1)
    print(f"this renderer faster at equal error on {wins} of {len(rows)} cases")
    if not args.no_write and not args.quick:
        columns = ["case", "error measure", "Radiance error", "Radiance (s)", "target error",
                   "spectral-gi at target (s)", "Radiance / spectral-gi", "spectral-gi at Radiance's error (s)",
                   f"spectral-gi error at {spp_sweep[-1]} spp", f"spectral-gi (s) at {spp_sweep[-1]} spp"]
        title = (f"CIE 171 cases at equal error: Radiance's error at -ad {ad_sweep[-1]} (floored at "
                 f"{args.floor:g}) as the target; spectral-gi's time from err = a/√t over its spp sweep; "
                 f"{args.threads} threads each")
        tables = [results.table(title, columns, rows),
                  results.table("Every run", ["case", "program", "setting", "wall (s)", "error"], detail)]
        conditions = {"threads": args.threads, "radiance": "pyradiance (Radiance 6.0a)",
                      "radiance_options": f"-aa 0 -as 0 -ab {args.ab} -lr 0 -lw {args.lw:g} -dj 1 -ds 0.05 -dt 0",
                      "ad_sweep": ad_sweep, "spp_sweep": spp_sweep, "floor": args.floor,
                      "compile_s": round(compile_s, 2), "light_sphere_radius_m": SPHERE_RADIUS,
                      "point_offset_m": OFFSET}
        results.write("radiance_lux", tables, conditions)
    return 0


if __name__ == "__main__":
    sys.exit(main())
