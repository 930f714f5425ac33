"""Equal-error race against Radiance on the CIE 171:2006 analytical cases (core/lux/cie171.py).

    pip install pyradiance            # or: pip install -e .[bench]
    python benchmarks/radiance_lux.py [--cases 5.2 5.8] [--quick] [--seeds 3] [--ad 16] [--threads 2]

Radiance comes from PyPI's ``pyradiance`` (Radiance 6 binaries: oconv, rtrace, rpict, ...;
no falsecolor); a ``rtrace`` on PATH is used when pyradiance is not installed.

Scene conversion (one Radiance scene per case):

* every triangle becomes a ``polygon`` with a grey ``plastic`` of its material's reflectance ρ
  (``plastic m 0 0 5 ρ ρ ρ 0 0``: specularity 0, roughness 0, so a Lambertian of RGB = ρ);
* a point light of I cd becomes a ``light`` sphere of radius r whose radiance R = G = B is
  ``I / (179 π r²)``: a uniform sphere of luminance L has intensity L π r² in every direction,
  and Radiance's luminance is 179 (0.265 R + 0.670 G + 0.065 B) cd/m², i.e. 179 R for grey;
  the sphere lights a point that sees all of it exactly as a point of I cd would;
* a rectangle light of luminance L becomes a ``light`` polygon of radiance ``L / 179``,
  its vertices ordered so that its normal is the light's emitting side;
* a sun of E lx normal to its direction becomes a ``source`` of angular diameter 0.5° whose
  radiance is ``E / (179 Ω)``, Ω = 2π (1 − cos 0.25°) its solid angle;
* each point is a ``rtrace -I+ -h`` input line ``x y z nx ny nz``, moved 0.1 mm along its
  normal off the surface it lies on; illuminance = 179 (0.265 R + 0.670 G + 0.065 B).

Radiance runs as pure Monte Carlo (``-aa 0``: no irradiance cache), with Russian roulette
(``-lr 0 -lw``), ``-ab`` far above what ρ = 0.95 needs (the kept fraction 1 − ρ^ab of the
inter-reflected light is printed), ``-dj 1`` and ``-ad`` ambient divisions (``--ad``; 64 times
that for 5.7, whose points see their only reflector over a few per cent of the hemisphere).

Error: every case has a per-point reference (the closed forms; for the reflecting cubes the
direct part plus the radiosity solution ``cie171.CUBE_INDIRECT_8X8``, accurate to about 1e-4),
and one run's error is its RMS relative error over the case's points (points whose reference
is 0 — 5.7's J and K — left out). A setting's error is the RMS over independent runs. Radiance
has no seed option: ``-u+`` (its default) seeds its generator with the clock's second, so every
rtrace run here starts in a second of its own (the wait is not timed); this renderer's runs
take seeds 1, 2, ... .

Equal error, per case: Radiance runs ``--seeds`` times at ``-ad`` (error e_R); this renderer
climbs its spp ladder (``--seeds`` runs a rung) to the first rung whose error is at most
``MARGIN`` × e_R (a margin for the noise of both estimates, so that the longer comparison
that follows does not land just above e_R).
Then ``--seeds`` more pairs run interleaved — Radiance, this renderer, Radiance, ... — so both
see the same machine load; the errors printed are over all 2 × ``--seeds`` runs of each, the
times the medians of their wall times, and the ratio the median over the pairs of Radiance's
time over this renderer's (> 1: this renderer is faster). The target is met where this
renderer's error is at most Radiance's and the ratio is above 1. The first calls' compile is
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
SUN_ANGLE_DEG = 0.5  # the sun's angular diameter in Radiance
# this renderer's settings: spp in steps of √2, so the first rung at Radiance's error costs at
# most √2 times the time the error needs exactly
MARGIN = 0.9
SPP_LADDER = tuple(int(round(2 ** (k / 2))) for k in range(4, 27))
# 5.7's points see its only reflector S₂ over a few per cent of their cosine-weighted hemisphere,
# so Radiance's pure Monte Carlo ambient sampling needs many more divisions there
AD_FACTOR = {"5.7": 64}
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
    out = [f"# CIE 171 case {case.name}"]
    for m, mat in enumerate(scene.materials):
        r = 0.0 if mat.reflectance < 0 else rho
        out.append(f"void plastic mat{m} 0 0 5 {r:.6g} {r:.6g} {r:.6g} 0 0")
    k = 0
    for mesh in scene.meshes:
        p = np.asarray(mesh.positions, float)
        for tri, m in zip(mesh.indices, mesh.material):
            v = " ".join(f"{c:.9g}" for c in p[tri].ravel())
            out.append(f"mat{int(m)} polygon t{k} 0 0 9 {v}")
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
        elif light.kind == C.LIGHT_SUN:
            omega = 2 * math.pi * (1 - math.cos(math.radians(SUN_ANGLE_DEG / 2)))
            R = light.illuminance / (RADIANCE_LM_PER_W * omega)
            d = -np.asarray(light.direction, float)
            d /= np.linalg.norm(d)
            out += [f"void light sun{i} 0 0 3 {R:.9g} {R:.9g} {R:.9g}",
                    f"sun{i} source sun{i}s 0 0 4 {d[0]:.9g} {d[1]:.9g} {d[2]:.9g} {SUN_ANGLE_DEG:g}"]
        else:
            raise ValueError(f"light kind {light.kind} is not converted")
    return "\n".join(out) + "\n"


class Radiance:
    def __init__(self, rtrace, oconv, env, workdir):
        self.rtrace, self.oconv, self.env, self.workdir = rtrace, oconv, env, workdir
        self.last_second = -1
        self.waited = 0.0

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
        # rtrace -u+ seeds its generator with time(0): a new second for every run (not timed)
        t_wait = time.time()
        while int(time.time()) <= self.last_second:
            time.sleep(0.02)
        self.waited += time.time() - t_wait
        self.last_second = int(time.time())
        t0 = time.perf_counter()
        res = subprocess.run(args, input=lines, capture_output=True, text=True, check=True, env=self.env)
        dt = time.perf_counter() - t0
        rgb = np.array([[float(v) for v in ln.split()[:3]] for ln in res.stdout.splitlines() if ln.strip()])
        return RADIANCE_LM_PER_W * (rgb @ np.array([0.265, 0.670, 0.065])), dt


# --------------------------------------------------------------------------- errors


def run_errors(case, lux):
    """Relative errors of one run at the case's points with a non-zero reference."""
    exp = case.expected_total
    keep = exp > 1e-6 * exp.max()
    return (lux[keep] - exp[keep]) / exp[keep]


def rms(errors):
    """RMS over every point of every run (a list of arrays)."""
    e = np.concatenate(errors)
    return float(np.sqrt(np.mean(e * e)))


# --------------------------------------------------------------------------- main


def main(argv=None):
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--cases", nargs="*", help="case names or prefixes (5.2, 5.8, '5.8 rho=0.95'); default all")
    ap.add_argument("--quick", action="store_true", help="2 seeds, -ad 8 (a smoke run, not for the record)")
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--seeds", type=int, default=None, help="independent runs per setting and phase (default 3)")
    ap.add_argument("--ad", type=int, default=None, help="Radiance -ad (default 16)")
    ap.add_argument("--ab", type=int, default=400, help="Radiance -ab (ambient bounces)")
    ap.add_argument("--lw", type=float, default=1e-4, help="Radiance -lw (Russian roulette below this weight)")
    ap.add_argument("--no-write", action="store_true", help="print only; do not write benchmarks/results/")
    args = ap.parse_args(argv)

    found = find_radiance()
    if found is None:
        print(INSTALL_HINT)
        return 0
    K = args.seeds or (2 if args.quick else 3)
    ad = args.ad or (8 if args.quick else 16)

    cases = cie171.reference_cases()
    if args.cases:
        cases = [c for c in cases if any(c.name == s or c.name.startswith(s) for s in args.cases)]
    print(f"Radiance: {found[0]}; -aa 0 -ab {args.ab} -lr 0 -lw {args.lw:g} -dj 1 -ad {ad}; {K} runs a setting "
          f"and phase; kept fraction of the indirect at ρ = 0.95: 1 − 0.95^{args.ab} = {1 - 0.95 ** args.ab:.6f}")

    t0 = time.perf_counter()
    warm = {c.name: c for c in cie171.reference_cases() if c.name in ("5.2", "5.3", "5.6", "5.7")}
    for c in warm.values():
        illuminance(c.scene, c.points[:2], c.normals[:2], spp=1, seed=1, threads=args.threads)
    compile_s = time.perf_counter() - t0
    print(f"this renderer's first calls (compile or cache load): {compile_s:.1f} s, excluded below")

    def ours(case, spp, seed):
        t = time.perf_counter()
        lux, _, _ = illuminance(case.scene, case.points, case.normals, spp=spp, seed=seed, threads=args.threads)
        return lux, time.perf_counter() - t

    rows, detail = [], []
    t_start = time.perf_counter()
    with tempfile.TemporaryDirectory(prefix="radiance_lux.") as tmp:
        rad = Radiance(*found, tmp)

        def radiance(case, octree):
            return rad.illuminance(octree, case.points, case.normals, case_ad(case), args.ab, args.lw, args.threads)

        def case_ad(case):
            return ad * AD_FACTOR.get(case.name, 1)

        for case in cases:
            octree = rad.octree(case)
            # phase 1: Radiance's error, then this renderer's ladder up to it
            r_err, r_t = [], []
            for _ in range(K):
                lux, dt = radiance(case, octree)
                r_err.append(run_errors(case, lux))
                r_t.append(dt)
            target = rms(r_err)
            seed = 1
            for spp in SPP_LADDER:
                o_err, o_t = [], []
                for _ in range(K):
                    lux, dt = ours(case, spp, seed)
                    seed += 1
                    o_err.append(run_errors(case, lux))
                    o_t.append(dt)
                e = rms(o_err)
                detail.append([case.name, f"{spp} spp", K, e, round(float(np.median(o_t)), 4)])
                if e <= MARGIN * target:
                    break
            # phase 2: interleaved pairs at the two settings
            ratios = []
            for _ in range(K):
                lux, dr = radiance(case, octree)
                r_err.append(run_errors(case, lux))
                r_t.append(dr)
                lux, do = ours(case, spp, seed)
                seed += 1
                o_err.append(run_errors(case, lux))
                o_t.append(do)
                ratios.append(dr / do)
            e_r, e_o = rms(r_err), rms(o_err)
            t_r, t_o, ratio = float(np.median(r_t)), float(np.median(o_t)), float(np.median(ratios))
            met = e_o <= e_r and ratio > 1
            rows.append([case.name, f"-ad {case_ad(case)}", e_r, round(t_r, 4), f"{spp} spp", e_o, round(t_o, 4),
                         round(ratio, 2), "yes" if met else "no"])
            print(f"{case.name:14s} Radiance -ad {case_ad(case):4d}: RMS {e_r:.2e} in {t_r:7.3f} s | "
                  f"ours {spp:5d} spp: "
                  f"RMS {e_o:.2e} in {t_o:7.4f} s | Radiance/ours {ratio:7.2f} | {'met' if met else 'NOT met'}",
                  flush=True)
        waited = rad.waited
    wall = time.perf_counter() - t_start
    wins = sum(1 for r in rows if r[-1] == "yes")
    print(f"target met on {wins} of {len(rows)} cases; {wall:.0f} s in all ({waited:.0f} s waiting for "
          f"rtrace's clock seed)")
    if not args.no_write and not args.quick:
        columns = ["case", "Radiance setting", "Radiance RMS error", "Radiance (s)", "spectral-gi setting",
                   "spectral-gi RMS error", "spectral-gi (s)", "Radiance / spectral-gi", "target met"]
        title = (f"CIE 171 cases at equal error: RMS relative error over the points and {2 * K} independent runs "
                 f"each, median wall time, median time ratio over {K} interleaved pairs; {args.threads} threads "
                 f"each (Radiance -aa 0 -ab {args.ab} -ad {ad}; spectral-gi's first spp rung at or below "
                 f"Radiance's error)")
        tables = [results.table(title, columns, rows),
                  results.table(f"spectral-gi's spp ladder ({K} runs a rung, seeds apart)",
                                ["case", "setting", "runs", "RMS error", "median (s)"], detail)]
        conditions = {"threads": args.threads, "radiance": "pyradiance (Radiance 6.0a)",
                      "radiance_options": f"-aa 0 -as 0 -ab {args.ab} -ad {ad} -lr 0 -lw {args.lw:g} -dj 1 "
                                          f"-ds 0.05 -dc 1 -dt 0 -u+",
                      "runs_per_setting_and_phase": K, "spp_ladder": list(SPP_LADDER),
                      "compile_s": round(compile_s, 2), "light_sphere_radius_m": SPHERE_RADIUS,
                      "sun_angle_deg": SUN_ANGLE_DEG, "point_offset_m": OFFSET, "wall_s": round(wall, 1)}
        results.write("radiance_lux", tables, conditions)
    return 0


if __name__ == "__main__":
    sys.exit(main())
