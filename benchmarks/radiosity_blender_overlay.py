"""The Blender add-on's radiosity overlay on the Cornell box, rendered headlessly (Blender as a
Python module, the Workbench engine showing each overlay object's per-vertex colours), on the
false-colour range of benchmarks/radiosity_figure.py so the two can be read side by side.

    python benchmarks/radiosity_blender_overlay.py [--vmax 1320]

Builds and installs the extension in a throw-away user folder, adds the Cornell box (Add
Cornell Box), runs Calculate Illuminance with Method Radiosity, hides the scene's meshes so
that the overlay objects show, renders and writes docs/images/radiosity_blender_overlay.png
with the legend beside it.
"""
import argparse
import importlib.util
import os
import sys
import tempfile
from pathlib import Path

os.environ.setdefault("BLENDER_USER_RESOURCES", tempfile.mkdtemp(prefix="spectral-gi-blender-user-"))

REPO = Path(__file__).resolve().parents[1]
OUT = REPO / "docs" / "images" / "radiosity_blender_overlay.png"
MODULE = "bl_ext.user_default.spectral_gi"


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--vmax", type=float, default=1320.0, help="top of the false-colour range, lx")
    ap.add_argument("--res", type=int, default=384)
    a = ap.parse_args()
    import bpy  # first: it provides addon_utils
    import addon_utils  # noqa: I001
    import numpy as np

    from spectral_gi.core.lux import falsecolour as fc

    spec = importlib.util.spec_from_file_location("build_extension", REPO / "tools" / "build_extension.py")
    tool = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(tool)
    zip_path = tool.build(Path(tempfile.mkdtemp()), quiet=True)
    bpy.ops.extensions.package_install_files(filepath=str(zip_path), repo="user_default", enable_on_install=True)
    if MODULE not in sys.modules:
        addon_utils.enable(MODULE, default_set=True)
    bpy.ops.wm.read_homefile(use_empty=True)
    bpy.ops.spectral_gi.add_cornell_box()
    sc = bpy.context.scene
    sc.spectral_gi_lux_method = "RADIOSITY"
    s = sc.spectral_gi_radiosity_scale
    s.scale_auto, s.scale_fixed_min, s.scale_fixed_max, s.scale_steps = False, 0.0, a.vmax, 8
    assert bpy.ops.spectral_gi.lux_calculate() == {"FINISHED"}
    names = set(sc.spectral_gi_radiosity.objects.splitlines())
    for o in sc.objects:
        if o.type == "MESH":
            o.hide_render = o.name not in names
    sc.render.engine = "BLENDER_WORKBENCH"
    sc.display.shading.light = "FLAT"
    sc.display.shading.color_type = "VERTEX"
    sc.view_settings.view_transform = "Standard"
    sc.render.resolution_x = sc.render.resolution_y = a.res
    tmp = Path(tempfile.mkdtemp()) / "overlay.png"
    sc.render.filepath = str(tmp)
    bpy.ops.render.render(write_still=True)
    img = bpy.data.images.load(str(tmp))
    w, h = img.size
    px = np.empty(w * h * 4, np.float32)
    img.pixels.foreach_get(px)
    rgb = px.reshape(h, w, 4)[::-1, :, :3]
    fig = fc.new_figure(6.0, 4.8)
    ax = fig.add_axes((0.02, 0.04, 0.74, 0.86))
    ax.imshow(np.clip(rgb, 0, 1), interpolation="nearest")
    ax.set_axis_off()
    ax.set_title(f"Blender viewport: radiosity overlay ({sc.spectral_gi_radiosity.patches} patches)", fontsize=10)
    cax = fig.add_axes((0.82, 0.04, 0.04, 0.86))
    fc.draw_legend(fig, cax, 0.0, a.vmax, steps=8)
    fc.save_figure(fig, OUT)
    print(f"wrote {OUT}")


if __name__ == "__main__":
    main()
