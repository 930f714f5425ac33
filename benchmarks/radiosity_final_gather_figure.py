"""The Cornell box rendered by radiosity and final gather (``core.render_radiosity``) next to
the path tracer's render of the same camera, with the difference of their luminance.

    python benchmarks/radiosity_final_gather_figure.py [--res 128] [--spp 256] [--fg-spp 16] [--gather 64]

Writes docs/images/radiosity_final_gather.png and prints the mean luminance of both images.
"""
import argparse
import time
from pathlib import Path

import numpy as np

from spectral_gi import core
from spectral_gi.core.io.png import to_srgb8
from spectral_gi.core.lux import falsecolour as fc

OUT = Path(__file__).resolve().parents[1] / "docs" / "images" / "radiosity_final_gather.png"


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--res", type=int, default=128)
    ap.add_argument("--spp", type=int, default=256, help="path tracer: samples a pixel")
    ap.add_argument("--fg-spp", type=int, default=16, help="final gather: camera samples a pixel")
    ap.add_argument("--gather", type=int, default=64, help="final gather: gather rays a camera sample")
    a = ap.parse_args()
    t0 = time.perf_counter()
    pt_film, _ = core.render(core.cornell_box(width=a.res, height=a.res, spp=a.spp))
    t_pt = time.perf_counter() - t0
    t0 = time.perf_counter()
    fg_film, _, sol = core.render_radiosity(core.cornell_box(width=a.res, height=a.res, spp=a.fg_spp),
                                            gather=a.gather)
    t_fg = time.perf_counter() - t0
    pt, fg = pt_film.develop(), fg_film.develop()
    lp, lf = float(pt.luminance.mean()), float(fg.luminance.mean())
    print(f"path tracer {a.spp} spp: {t_pt:.1f} s, mean luminance {lp:.4g} cd/m²; radiosity ({sol.patches.n} "
          f"patches) and final gather {a.fg_spp} spp x {a.gather}: {t_fg:.1f} s, mean {lf:.4g} cd/m² "
          f"({100 * (lf / lp - 1):+.2f} %)")
    fig = fc.new_figure(10.5, 3.9)
    panels = ((to_srgb8(fg.rgb), f"radiosity + final gather ({a.fg_spp} spp × {a.gather} gather rays)"),
              (to_srgb8(pt.rgb), f"path tracer ({a.spp} spp)"))
    for k, (img, title) in enumerate(panels):
        ax = fig.add_axes((0.01 + 0.31 * k, 0.03, 0.3, 0.84))
        ax.imshow(img, interpolation="nearest")
        ax.set_axis_off()
        ax.set_title(title, fontsize=9)
    ax = fig.add_axes((0.64, 0.03, 0.3, 0.84))
    rel = fg.luminance / np.maximum(pt.luminance, 1e-9) - 1
    im = ax.imshow(np.clip(rel, -0.2, 0.2), cmap="RdBu_r", vmin=-0.2, vmax=0.2, interpolation="nearest")
    ax.set_axis_off()
    ax.set_title("luminance: final gather / path − 1", fontsize=9)
    fig.colorbar(im, ax=ax, fraction=0.046, pad=0.02)
    fig.suptitle(f"Cornell box: mean luminance {lf:.4g} cd/m² by final gather, {lp:.4g} cd/m² path-traced "
                 f"({100 * (lf / lp - 1):+.2f} %)", fontsize=10)
    fc.save_figure(fig, OUT)
    print(f"wrote {OUT}")


if __name__ == "__main__":
    main()
