"""Inter-reflected illuminance in a cube with an isotropic source at its centre, by a radiosity
solution with exact point-to-patch configuration factors (the oracle behind
``core.lux.cie171.CUBE_INDIRECT_8X8``).

Exitance is constant on N × N patches of a face and equal on the six faces and under the
face's symmetries (the source at the centre), so the unknowns are one eighth of a face's
patches; each patch's equation is collocated at its centre. The factor from a floor point
(facing +z) to a ceiling patch is the parallel corner formula applied at the patch's four
corners, to a wall patch the perpendicular corner formula at its two bottom and two top
corners (form factor algebra), both exact."""
import math

import numpy as np


def _par_corner(a, b, c):
    X, Y = np.abs(a) / c, np.abs(b) / c
    sx, sy = np.sqrt(1 + X * X), np.sqrt(1 + Y * Y)
    return np.sign(a) * np.sign(b) * (X / sx * np.arctan(Y / sx) + Y / sy * np.arctan(X / sy)) / (2 * math.pi)


def _perp_corner(a, b, c):
    A = np.abs(a)
    with np.errstate(divide="ignore", invalid="ignore"):
        X, Y = b / A, c / A
        r = np.sqrt(X * X + Y * Y)
        f = (np.arctan(1.0 / Y) - Y / r * np.arctan(1.0 / r)) / (2 * math.pi)
    return np.where((A > 0) & (b > 0), np.sign(a) * f, 0.0)


def _floor_to_rects(px, py, kind, s, r):
    """(P, Q) factors from floor points to rectangles r = (u1, u2, v1, v2) of face ``kind``."""
    P, Q = px[:, None], py[:, None]
    u1, u2, v1, v2 = (r[None, :, k] for k in range(4))
    if kind == "ceiling":
        return (_par_corner(u2 - P, v2 - Q, s) - _par_corner(u1 - P, v2 - Q, s)
                - _par_corner(u2 - P, v1 - Q, s) + _par_corner(u1 - P, v1 - Q, s))
    along, dist = {"y0": (P, Q), "ys": (P, s - Q), "x0": (Q, P), "xs": (Q, s - P)}[kind]

    def g(z):
        return _perp_corner(u2 - along, z, dist) - _perp_corner(u1 - along, z, dist)
    return g(v2) - g(v1)


def cube_indirect(N, rhos, eval_u, eval_v, side=4.0, flux=10000.0):
    """{ρ: inter-reflected illuminance (lx) at floor points (eval_u, eval_v)} with N × N patches."""
    e = np.arange(N + 1) * side / N
    I, J = (a.ravel() for a in np.meshgrid(np.arange(N), np.arange(N), indexing="ij"))
    rects = np.stack([e[I], e[I + 1], e[J], e[J + 1]], 1)
    cx, cy = (e[I] + e[I + 1]) / 2, (e[J] + e[J + 1]) / 2
    a, b = np.minimum(I, N - 1 - I), np.minimum(J, N - 1 - J)
    _, orbit = np.unique(np.minimum(a, b) * N + np.maximum(a, b), return_inverse=True)
    n_orbit = orbit.max() + 1
    rep = np.array([np.flatnonzero(orbit == o)[0] for o in range(n_orbit)])
    fold = np.zeros((len(orbit), n_orbit))
    fold[np.arange(len(orbit)), orbit] = 1.0

    def gather(px, py):
        out = np.zeros((len(px), n_orbit))
        for k in range(0, len(px), 64):
            F = sum(_floor_to_rects(px[k:k + 64], py[k:k + 64], f, side, rects)
                    for f in ("ceiling", "y0", "ys", "x0", "xs"))
            out[k:k + 64] = F @ fold
        return out

    A = gather(cx[rep], cy[rep])
    d = np.stack([side / 2 - cx[rep], side / 2 - cy[rep], np.full(n_orbit, side / 2)], 1)
    Ed = flux / (4 * math.pi) * d[:, 2] / np.linalg.norm(d, axis=1) ** 3
    G = gather(np.asarray(eval_u, float), np.asarray(eval_v, float))
    return {rho: G @ np.linalg.solve(np.eye(n_orbit) - rho * A, rho * Ed) for rho in rhos}
